#include "transport/transport.hpp"

#include "transport/dds_transport.hpp"
#include "transport/lcm_transport.hpp"

namespace mpm::transport {

std::unique_ptr<Transport> create(const Settings& settings, std::string& error) {
  std::unique_ptr<Transport> transport;
  switch (settings.kind) {
    case Kind::kLcm:
      transport = make_lcm_transport(settings.lcm, error);
      break;
    case Kind::kDds:
      transport = make_dds_transport(settings.dds, error);
      break;
  }
  if (transport) transport->set_sample_limits(settings.sample_limits);
  return transport;
}

}  // namespace mpm::transport
