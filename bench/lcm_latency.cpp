#include "bench/lcm_latency.hpp"

#ifdef MPM_BENCH_HAVE_LCM
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>
#endif

namespace mpm::bench {

#ifndef MPM_BENCH_HAVE_LCM

std::optional<Latency> measure_lcm_latency(std::size_t, std::string& why) {
  why = "built without LCM (lcm pkg-config package not found)";
  return std::nullopt;
}

#else

namespace {

using Clock = std::chrono::steady_clock;
// Own port: other processes on the default 7667 do not disturb the figure.
constexpr const char* kUrl = "udpm://239.255.76.67:7671?ttl=0";
// About the size of one encoded 50x50 sample message's header and a few values.
constexpr std::size_t kPayload = 256;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

struct Receiver {
  std::atomic<std::uint64_t> last_sequence{0};
  std::vector<double> latencies_us;  // written by the receiver thread only
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const std::int64_t arrived = now_ns();
    if (rbuf->data_size < 16) return;
    std::int64_t sent = 0;
    std::uint64_t sequence = 0;
    std::memcpy(&sent, rbuf->data, 8);
    std::memcpy(&sequence, static_cast<const char*>(rbuf->data) + 8, 8);
    latencies_us.push_back(static_cast<double>(arrived - sent) * 1e-3);
    last_sequence.store(sequence, std::memory_order_release);
  }
};

double percentile(std::vector<double> v, double q) {
  const auto idx = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(idx), v.end());
  return v[idx];
}

}  // namespace

std::optional<Latency> measure_lcm_latency(std::size_t messages, std::string& why) {
  lcm::LCM publisher(kUrl);
  lcm::LCM subscriber(kUrl);
  if (!publisher.good() || !subscriber.good()) {
    why = std::string("LCM init failed on ") + kUrl + " (needs a multicast route, e.g. ip route add 224.0.0.0/4 dev lo)";
    return std::nullopt;
  }
  const std::string channel = "MPM_BENCH_LATENCY_" + std::to_string(getpid());
  Receiver receiver;
  receiver.latencies_us.reserve(messages);
  subscriber.subscribe(channel, &Receiver::on_message, &receiver);
  std::atomic<bool> stop{false};
  std::thread thread([&] {
    while (!stop.load()) subscriber.handleTimeout(20);
  });

  Latency result;
  std::array<char, kPayload> payload{};
  for (std::uint64_t seq = 1; seq <= messages; ++seq) {
    const std::int64_t sent = now_ns();
    std::memcpy(payload.data(), &sent, 8);
    std::memcpy(payload.data() + 8, &seq, 8);
    publisher.publish(channel, payload.data(), static_cast<unsigned>(payload.size()));
    const auto deadline = Clock::now() + std::chrono::milliseconds(seq == 1 ? 1000 : 200);
    while (receiver.last_sequence.load(std::memory_order_acquire) < seq && Clock::now() < deadline)
      std::this_thread::yield();
    if (receiver.last_sequence.load(std::memory_order_acquire) < seq) {
      ++result.lost;
      if (seq == 1) break;  // nothing arrives: multicast loopback blocked
    }
  }
  stop = true;
  thread.join();
  result.messages = receiver.latencies_us.size();
  if (result.messages == 0) {
    why = std::string("no message came back over ") + kUrl + " within 1 s (multicast loopback blocked?)";
    return std::nullopt;
  }
  result.p50_us = percentile(receiver.latencies_us, 0.50);
  result.p99_us = percentile(receiver.latencies_us, 0.99);
  return result;
}

#endif

}  // namespace mpm::bench
