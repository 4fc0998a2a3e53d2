// Cyclone DDS adapter (internal: use transport::create).
#pragma once

#include <memory>
#include <string>

#include "transport/transport.hpp"

namespace mpm::transport {

std::unique_ptr<Transport> make_dds_transport(const DdsSettings& settings, std::string& error);

}  // namespace mpm::transport
