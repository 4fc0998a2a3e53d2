#include "transport/transport.hpp"

#include "transport/dds_transport.hpp"
#include "transport/lcm_transport.hpp"

namespace mpm::transport {

std::unique_ptr<Transport> create(const Settings& settings, std::string& error) {
  switch (settings.kind) {
    case Kind::kLcm:
      return make_lcm_transport(settings.lcm, error);
    case Kind::kDds:
      return make_dds_transport(settings.dds, error);
  }
  error = "unknown transport";
  return nullptr;
}

}  // namespace mpm::transport
