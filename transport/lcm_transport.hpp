// LCM adapter (internal: use transport::create).
#pragma once

#include <memory>
#include <string>

#include "transport/transport.hpp"

namespace mpm::transport {

std::unique_ptr<Transport> make_lcm_transport(const LcmSettings& settings, std::string& error);

}  // namespace mpm::transport
