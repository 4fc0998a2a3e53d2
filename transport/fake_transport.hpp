// In-process transport for unit tests, in the spirit of LCM's memq://: every
// transport attached to one FakeBus receives what any of them publishes
// (including itself, like multicast loopback), in publication order.
#pragma once

#include <memory>

#include "transport/transport.hpp"

namespace mpm::transport {

class FakeBus;  // shared state; opaque

std::shared_ptr<FakeBus> make_fake_bus();
std::unique_ptr<Transport> make_fake_transport(std::shared_ptr<FakeBus> bus);

}  // namespace mpm::transport
