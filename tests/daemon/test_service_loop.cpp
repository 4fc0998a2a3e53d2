// mpmd's wiring without a network: receiver thread, bounded queue, main loop
// and monitor over the in-process fake transport. Alarms and status come out
// on the bus; a full queue drops, counts and logs; a stop ends the loop.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "child_process.hpp"
#include "daemon/mpmd/receiver.hpp"
#include "daemon/mpmd/sample_queue.hpp"
#include "daemon/mpmd/service_loop.hpp"
#include "observer.hpp"
#include "service_fixture.hpp"
#include "transport/fake_transport.hpp"
#include "wood_berry_stream.hpp"

namespace mpm {
namespace {

TEST(SampleQueue, RefusesWhenFullAndKeepsOrder) {
  SampleQueue q(3);
  msg::Sample s;
  bool was_empty = false;
  for (int k = 1; k <= 3; ++k) {
    s.seq = k;
    ASSERT_TRUE(q.push(s, was_empty));
    EXPECT_EQ(was_empty, k == 1);
  }
  s.seq = 4;
  EXPECT_FALSE(q.push(s, was_empty));
  EXPECT_EQ(q.size(), 3u);
  for (int k = 1; k <= 3; ++k) {
    ASSERT_NE(q.front(), nullptr);
    EXPECT_EQ(q.front()->seq, k);
    q.pop();
  }
  EXPECT_EQ(q.front(), nullptr);
}

// The daemon's parts, as main() assembles them, on a fake bus.
struct FakeDaemon {
  explicit FakeDaemon(std::shared_ptr<transport::FakeBus> bus, std::size_t queue_capacity)
      : transport(transport::make_fake_transport(bus)), queue(queue_capacity), receiver(*transport, queue) {
    loaded = test::wood_berry_config(0.05);
    std::string error;
    service = make_service(loaded, publish_to(transport), error);
    EXPECT_TRUE(service) << error;
  }
  void run() {
    loop = std::make_unique<ServiceLoop>("unused.yaml", loaded, std::move(service), queue, receiver, *transport,
                                         notifier);
    thread = std::thread([this] { exit_code = loop->run(stop, reload); });
  }
  ~FakeDaemon() {
    stop = true;
    if (thread.joinable()) thread.join();
    receiver.stop();
  }

  std::unique_ptr<transport::Transport> transport;
  SampleQueue queue;
  Receiver receiver;
  Notifier notifier;
  LoadedConfig loaded;
  std::unique_ptr<MonitorService> service;
  std::unique_ptr<ServiceLoop> loop;
  std::atomic<bool> stop{false}, reload{false};
  std::thread thread;
  int exit_code = -1;
};

TEST(ServiceLoop, AlarmsAndStatusFlowOverTheFakeBus) {
  auto bus = transport::make_fake_bus();
  FakeDaemon daemon(bus, 64);
  std::string error;
  ASSERT_TRUE(daemon.receiver.start(error)) << error;
  daemon.run();

  auto operator_side = transport::make_fake_transport(bus);
  test::Observer obs(*operator_side);
  ASSERT_TRUE(obs.wait_status("wb", [](const msg::Status&) { return true; })) << "a first status at start";
  test::WoodBerryStream stream(5);
  msg::Sample s;
  s.controller_id = "wb";
  for (int k = 1; k <= 2500 && obs.alarms().empty(); ++k) {
    if (k == 800) stream.set_g21_gain(1.5);
    stream.next(s);
    s.seq = k;
    operator_side->publish(s);
    if (k % 50 == 0) {
      ASSERT_TRUE(obs.wait_status("wb", [k](const msg::Status& st) { return st.samples_seen >= k; }));
    }
  }
  ASSERT_TRUE(obs.wait_alarms([](const auto& a) { return !a.empty(); }));
  EXPECT_EQ(obs.alarms().front().output, "y2");
  EXPECT_EQ(obs.alarms().front().input, "u1");
  EXPECT_TRUE(obs.alarms().front().raised);
  EXPECT_TRUE(obs.wait_status("wb", [](const msg::Status& st) { return st.alarms_raised == 1 && st.dropped == 0; }));

  daemon.stop = true;
  daemon.thread.join();
  EXPECT_EQ(daemon.exit_code, 0);
}

TEST(ServiceLoop, AFullQueueDropsCountsAndLogsOnce) {
  test::LogCapture logs;
  auto bus = transport::make_fake_bus();
  FakeDaemon daemon(bus, 4);
  std::string error;
  ASSERT_TRUE(daemon.receiver.start(error)) << error;
  // No consumer yet: the receiver fills the queue, then drops.
  auto controller = transport::make_fake_transport(bus);
  test::WoodBerryStream stream(6);
  msg::Sample s;
  s.controller_id = "wb";
  for (int k = 1; k <= 100; ++k) {
    stream.next(s);
    s.seq = k;
    controller->publish(s);
  }
  ASSERT_TRUE(test::eventually([&] { return daemon.receiver.dropped() == 96; })) << daemon.receiver.dropped();

  daemon.run();
  test::Observer obs(*controller);
  ASSERT_TRUE(obs.wait_status("wb", [](const msg::Status& st) { return st.samples_seen == 4 && st.dropped == 96; }));
  EXPECT_EQ(obs.status("wb")->gaps, 0) << "the queue kept the first four in order";
  daemon.stop = true;
  daemon.thread.join();
  EXPECT_EQ(logs.count("receive queue full"), 1);
}

}  // namespace
}  // namespace mpm
