// The diagnosis behind a raise: the ring buffer costs the per-sample path no
// allocation, a raise yields one diagnosis naming the planted physics, and
// requests made while the worker is busy are coalesced into one pending
// request, counted, never queued without bound.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "daemon/mpmd/diagnosis_worker.hpp"
#include "daemon/mpmd/monitor_service.hpp"
#include "service_fixture.hpp"
#include "support/alloc_counter.hpp"
#include "wood_berry_stream.hpp"

namespace mpm {
namespace {

ServiceSettings with_diagnosis() {
  ServiceSettings s = test::fast_service();
  s.diagnosis_window = 3000;
  s.scan_interval = 0;  // the diagnosis of a raise only (the scan: test_diagnosis_scan.cpp)
  return s;
}

const msg::Sample& next(test::WoodBerryStream& stream, msg::Sample& s) {
  stream.next(s);
  s.controller_id = "wb";
  s.session_id = 1;
  ++s.seq;
  return s;
}

// Polls until `n` diagnoses arrived or 60 s passed.
std::vector<msg::Diagnosis> collect(MonitorService& service, std::size_t n) {
  std::vector<msg::Diagnosis> out;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (out.size() < n && std::chrono::steady_clock::now() < deadline) {
    service.poll_diagnoses([&](const msg::Diagnosis& d) { out.push_back(d); });
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return out;
}

TEST(DiagnosisWorker, RecordingSamplesDoesNotAllocate) {
  MonitorService service(test::wood_berry_plant(), with_diagnosis(), {});
  test::WoodBerryStream stream(4);
  msg::Sample s;
  for (int k = 0; k < 3500; ++k) service.on_sample(next(stream, s), {});  // the ring wraps
  test::AllocationScope scope;
  for (int k = 0; k < 1000; ++k) service.on_sample(next(stream, s), {});
  EXPECT_EQ(scope.count(), 0);
}

TEST(DiagnosisWorker, ARaiseYieldsTheDiagnosisOfItsChannel) {
  std::vector<msg::Alarm> alarms;
  MonitorService service(test::wood_berry_plant(), with_diagnosis(), [&](const msg::Alarm& a) { alarms.push_back(a); });
  test::WoodBerryStream stream(6);
  stream.set_g21_gain(2.0);
  msg::Sample s;
  for (int k = 0; k < 3000 && alarms.empty(); ++k) service.on_sample(next(stream, s), {});
  ASSERT_FALSE(alarms.empty());
  ASSERT_EQ(alarms[0].output, "y2");
  const auto found = collect(service, 1);
  ASSERT_EQ(found.size(), 1u);
  const msg::Diagnosis& d = found[0];
  EXPECT_EQ(d.sample_sequence, alarms[0].sample_sequence);
  EXPECT_EQ(d.physics, "gain") << d.text;
  ASSERT_FALSE(d.parameter_names.empty());
  EXPECT_EQ(d.parameter_names[0], "gain_ratio");
  EXPECT_NEAR(d.parameter_values[0], 2.0, 0.3) << d.text;
  EXPECT_GT(d.holdout_improvement, 0.0);
  EXPECT_EQ(service.diagnosis()->completed(), 1u);
}

TEST(DiagnosisWorker, RequestsWhileBusyAreCoalesced) {
  const PlantModel plant = test::wood_berry_plant();
  DiagnosisWorker worker(plant, 2000);
  test::WoodBerryStream stream(8);
  for (int k = 0; k < 2000; ++k) {
    double u[2], y[2];
    stream.next(u, y);
    const double r[2] = {y[0] - 90.0, y[1] - 5.0};
    worker.record(u, r);
  }
  // One handed over; two more while it runs: the second replaces the first.
  EXPECT_TRUE(worker.request({1, 0, 0, 1, "wb"}));
  EXPECT_TRUE(worker.request({0, 1, 0, 2, "wb"}));
  EXPECT_FALSE(worker.request({0, 0, 0, 3, "wb"}));
  EXPECT_EQ(worker.coalesced(), 2u);
  std::vector<msg::Diagnosis> done;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (done.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    msg::Diagnosis d;
    if (worker.take(d)) done.push_back(d);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[0].sample_sequence, 1);
  EXPECT_EQ(done[1].sample_sequence, 3);  // the latest pending request, not the replaced one
  EXPECT_EQ(done[1].window, 2000);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  msg::Diagnosis none;
  EXPECT_FALSE(worker.take(none));
  EXPECT_EQ(worker.completed(), 2u);
}

}  // namespace
}  // namespace mpm
