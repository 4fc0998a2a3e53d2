// The transport contract, checked on every implementation: the fake bus, LCM
// over UDP multicast and Cyclone DDS on loopback, each between two transport
// objects of this process. Then what is particular to each: LCM's decode
// errors and configurable channels, DDS's late-joining alarm readers.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <sstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <ostream>
#include <vector>

#include "same_message.hpp"
#include "sample_messages.hpp"
#include "transport/fake_transport.hpp"
#include "transport/lcm_codec.hpp"
#include "transport/transport.hpp"

namespace mpm::transport {
namespace {

const std::string kLoopbackXml = MPM_SOURCE_DIR "/deploy/dds/cyclonedds-loopback.xml";

// Distinct LCM ports / DDS domains per test, so parallel runs on one host
// never hear each other.
Settings unique_settings(Kind kind) {
  static int counter = 0;
  const int slot = static_cast<int>((::getpid() * 3 + counter++) % 200);
  Settings s;
  s.kind = kind;
  s.lcm.url = "udpm://239.255.76.68:" + std::to_string(30000 + slot * 3) + "?ttl=0";
  s.dds.domain = 1 + slot;
  s.dds.config = kLoopbackXml;
  return s;
}

enum class Impl { kFake, kLcm, kDds };
void PrintTo(Impl i, std::ostream* os) { *os << (i == Impl::kFake ? "fake" : i == Impl::kLcm ? "lcm" : "dds"); }

// Handles messages on `t` until `done()` or the timeout.
bool pump(Transport& t, const std::function<bool()>& done, std::chrono::seconds timeout = std::chrono::seconds(20)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    if (t.handle(std::chrono::milliseconds(20)) < 0) return false;
  }
  return true;
}

// For messages that must reach one transport only: `receiver` pumped until
// `arrived()`, then `bystander` given 200 ms to receive what it must not.
bool pump_then_listen(Transport& receiver, const std::function<bool()>& arrived, Transport& bystander) {
  if (!pump(receiver, arrived)) return false;
  bystander.handle(std::chrono::milliseconds(200));
  return true;
}

class TransportContract : public ::testing::TestWithParam<Impl> {
 protected:
  void SetUp() override {
    const Settings settings = unique_settings(GetParam() == Impl::kDds ? Kind::kDds : Kind::kLcm);
    if (GetParam() == Impl::kFake) {
      auto bus = make_fake_bus();
      publisher_ = make_fake_transport(bus);
      subscriber_ = make_fake_transport(bus);
    } else {
      std::string error;
      publisher_ = create(settings, error);
      ASSERT_TRUE(publisher_) << error;
      subscriber_ = create(settings, error);
      ASSERT_TRUE(subscriber_) << error;
    }
  }
  std::unique_ptr<Transport> publisher_;
  std::unique_ptr<Transport> subscriber_;
};

TEST_P(TransportContract, SamplesArriveInOrderWithEveryField) {
  std::vector<msg::Sample> got;
  ASSERT_TRUE(subscriber_->subscribe_samples([&](const msg::Sample& s) { got.push_back(s); }));
  ASSERT_TRUE(publisher_->wait_for_sample_readers(1, std::chrono::seconds(20)));
  msg::Sample s = test::full_sample();
  for (int k = 1; k <= 20; ++k) {
    s.seq = k;
    s.u[0] = k;
    ASSERT_TRUE(publisher_->publish(s));
  }
  ASSERT_TRUE(pump(*subscriber_, [&] { return got.size() >= 20; })) << got.size();
  ASSERT_EQ(got.size(), 20u);
  for (int k = 1; k <= 20; ++k) {
    EXPECT_EQ(got[static_cast<std::size_t>(k - 1)].seq, k);
    EXPECT_EQ(got[static_cast<std::size_t>(k - 1)].u[0], k);
  }
  test::expect_same_message(got.back(), s);
  EXPECT_EQ(subscriber_->receive_errors(), 0u);
}

TEST_P(TransportContract, AlarmsAndStatusArrive) {
  std::vector<msg::Alarm> alarms;
  std::vector<msg::Status> status;
  ASSERT_TRUE(subscriber_->subscribe_alarms([&](const msg::Alarm& a) { alarms.push_back(a); }));
  ASSERT_TRUE(subscriber_->subscribe_status([&](const msg::Status& s) { status.push_back(s); }));
  ASSERT_TRUE(publisher_->advertise(Transport::Topic::kAlarm));
  msg::Alarm a = test::full_alarm();
  ASSERT_TRUE(publisher_->publish(a));
  a.input = "u2";
  a.input_index = 1;
  a.raised = false;
  ASSERT_TRUE(publisher_->publish(a));
  ASSERT_TRUE(publisher_->publish(test::full_status()));
  ASSERT_TRUE(pump(*subscriber_, [&] { return alarms.size() >= 2 && !status.empty(); }));
  test::expect_same_message(alarms[0], test::full_alarm());
  test::expect_same_message(alarms[1], a);
  test::expect_same_message(status[0], test::full_status());
}

TEST_P(TransportContract, OnlySubscribedKindsAreDelivered) {
  int samples = 0, alarms = 0;
  ASSERT_TRUE(subscriber_->subscribe_alarms([&](const msg::Alarm&) { ++alarms; }));
  // The publisher also listens to samples: it must not get its own alarms.
  ASSERT_TRUE(publisher_->subscribe_samples([&](const msg::Sample&) { ++samples; }));
  ASSERT_TRUE(publisher_->publish(test::full_alarm()));
  ASSERT_TRUE(pump_then_listen(*subscriber_, [&] { return alarms == 1; }, *publisher_));
  EXPECT_EQ(samples, 0);
}

TEST_P(TransportContract, HandleTimesOutWithoutTraffic) {
  ASSERT_TRUE(subscriber_->subscribe_samples([](const msg::Sample&) {}));
  EXPECT_EQ(subscriber_->handle(std::chrono::milliseconds(50)), 0);
}

INSTANTIATE_TEST_SUITE_P(All, TransportContract, ::testing::Values(Impl::kFake, Impl::kLcm, Impl::kDds),
                         [](const auto& test) {
                           return std::string(test.param == Impl::kFake  ? "Fake"
                                              : test.param == Impl::kLcm ? "Lcm"
                                                                         : "Dds");
                         });

TEST(LcmTransport, UndecodableMessagesAreCountedAndSkipped) {
  const Settings settings = unique_settings(Kind::kLcm);
  std::string error;
  auto t = create(settings, error);
  ASSERT_TRUE(t) << error;
  std::vector<msg::Sample> got;
  ASSERT_TRUE(t->subscribe_samples([&](const msg::Sample& s) { got.push_back(s); }));
  lcm::LCM raw(settings.lcm.url);
  ASSERT_TRUE(raw.good());
  const char garbage[] = "not an LCM message";
  raw.publish(settings.lcm.sample_channel, garbage, sizeof garbage);
  mpm_lcm::alarm_t wrong_type;  // right encoding, wrong type hash
  lcm_codec::to_wire(test::full_alarm(), wrong_type);
  raw.publish(settings.lcm.sample_channel, &wrong_type);
  ASSERT_TRUE(t->publish(test::full_sample()));
  ASSERT_TRUE(pump(*t, [&] { return !got.empty() && t->receive_errors() == 2; }));
  EXPECT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].controller_id, "column-7");
}

TEST(LcmTransport, ChannelNamesSeparateTraffic) {
  Settings a = unique_settings(Kind::kLcm);
  Settings b = a;
  b.lcm.sample_channel = "PLANT2_SAMPLE";
  std::string error;
  auto ta = create(a, error);
  auto tb = create(b, error);
  ASSERT_TRUE(ta && tb) << error;
  int on_a = 0, on_b = 0;
  ASSERT_TRUE(ta->subscribe_samples([&](const msg::Sample&) { ++on_a; }));
  ASSERT_TRUE(tb->subscribe_samples([&](const msg::Sample&) { ++on_b; }));
  ASSERT_TRUE(tb->publish(test::full_sample()));
  ASSERT_TRUE(pump_then_listen(*tb, [&] { return on_b == 1; }, *ta));
  EXPECT_EQ(on_a, 0) << "a sample on PLANT2_SAMPLE reached the MPM_SAMPLE subscriber";
}

TEST(LcmTransport, MemqWorksInOneProcess) {
  Settings s;
  s.lcm.url = "memq://";
  std::string error;
  auto t = create(s, error);
  ASSERT_TRUE(t) << error;
  int got = 0;
  ASSERT_TRUE(t->subscribe_alarms([&](const msg::Alarm& a) { got += a.raised ? 1 : 0; }));
  ASSERT_TRUE(t->publish(test::full_alarm()));
  ASSERT_TRUE(pump(*t, [&] { return got == 1; }));
}

TEST(LcmTransport, BadUrlIsAClearError) {
  Settings s;
  s.lcm.url = "nonsense://nowhere";
  std::string error;
  EXPECT_EQ(create(s, error), nullptr);
  EXPECT_NE(error.find("nonsense://nowhere"), std::string::npos) << error;
}

// DDS alarms are transient-local and keyed by (controller, output, input): an
// operator tool that starts after the alarms were raised still receives the
// current state of every channel.
TEST(DdsTransport, LateJoiningReaderGetsTheCurrentAlarmOfEachChannel) {
  const Settings settings = unique_settings(Kind::kDds);
  std::string error;
  auto daemon = create(settings, error);
  ASSERT_TRUE(daemon) << error;
  msg::Alarm a = test::full_alarm();
  ASSERT_TRUE(daemon->publish(a));  // y2 <- u1 raised
  a.input = "u2";
  a.input_index = 1;
  ASSERT_TRUE(daemon->publish(a));  // y2 <- u2 raised ...
  a.raised = false;
  ASSERT_TRUE(daemon->publish(a));  // ... and cleared again
  a.controller_id = "column-8";
  a.raised = true;
  ASSERT_TRUE(daemon->publish(a));  // another controller's alarm
  msg::Status st = test::full_status();
  ASSERT_TRUE(daemon->publish(st));
  st.samples_seen = 11;
  ASSERT_TRUE(daemon->publish(st));

  auto late = create(settings, error);  // the operator joins now
  ASSERT_TRUE(late) << error;
  std::map<std::string, msg::Alarm> current;  // by controller/input
  std::vector<msg::Status> status;
  ASSERT_TRUE(late->subscribe_alarms([&](const msg::Alarm& x) { current[x.controller_id + "/" + x.input] = x; }));
  ASSERT_TRUE(late->subscribe_status([&](const msg::Status& s) { status.push_back(s); }));
  ASSERT_TRUE(pump(*late, [&] { return current.size() == 3 && !status.empty(); }));
  EXPECT_TRUE(current["column-7/u1"].raised);
  EXPECT_FALSE(current["column-7/u2"].raised) << "the latest state of the channel, not its history";
  EXPECT_TRUE(current["column-8/u2"].raised);
  late->handle(std::chrono::milliseconds(200));
  ASSERT_EQ(status.size(), 1u) << "status: the latest per controller";
  EXPECT_EQ(status[0].samples_seen, 11);
}

TEST(DdsTransport, SampleWriterSeesItsReaders) {
  const Settings settings = unique_settings(Kind::kDds);
  std::string error;
  auto publisher = create(settings, error);
  ASSERT_TRUE(publisher) << error;
  EXPECT_FALSE(publisher->wait_for_sample_readers(1, std::chrono::milliseconds(200)));
  auto reader = create(settings, error);
  ASSERT_TRUE(reader->subscribe_samples([](const msg::Sample&) {}));
  EXPECT_TRUE(publisher->wait_for_sample_readers(1, std::chrono::seconds(20)));
}

// Both example configurations are ones Cyclone accepts (the plant-network
// one with its example interface name replaced by this host's loopback).
TEST(DdsTransport, ExampleConfigurationsAreAccepted) {
  std::ifstream in(MPM_SOURCE_DIR "/deploy/dds/cyclonedds-plant-network.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const auto at = xml.find("name=\"eth1\"");
  ASSERT_NE(at, std::string::npos);
  xml.replace(at, 11, "name=\"lo\"");
  xml = xml.substr(xml.find("<CycloneDDS"));  // inline XML: no <?xml?> prolog
  for (const std::string& config : {kLoopbackXml, xml}) {
    Settings s = unique_settings(Kind::kDds);
    s.dds.config = config;
    std::string error;
    EXPECT_NE(create(s, error), nullptr) << error;
  }
}

TEST(DdsTransport, BadConfigurationIsAClearError) {
  Settings s = unique_settings(Kind::kDds);
  s.dds.config = "<CycloneDDS><Domain><General><NoSuchElement/></General></Domain></CycloneDDS>";
  std::string error;
  EXPECT_EQ(create(s, error), nullptr);
  EXPECT_NE(error.find("DDS"), std::string::npos) << error;
}

}  // namespace
}  // namespace mpm::transport
