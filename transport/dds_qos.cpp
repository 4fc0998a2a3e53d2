#include "transport/dds_qos.hpp"

namespace mpm::transport::dds_qos {

namespace {

dds_qos_t* make(dds_durability_kind_t durability, int depth) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(qos, durability);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  return qos;
}

// A reader keeps a few per instance so a raise followed quickly by a clear
// both reach the application.
constexpr int kReaderDepth = 16;

}  // namespace

dds_qos_t* sample(int depth) { return make(DDS_DURABILITY_VOLATILE, depth); }
dds_qos_t* alarm_writer() { return make(DDS_DURABILITY_TRANSIENT_LOCAL, 1); }
dds_qos_t* alarm_reader() { return make(DDS_DURABILITY_TRANSIENT_LOCAL, kReaderDepth); }
dds_qos_t* status_writer() { return make(DDS_DURABILITY_TRANSIENT_LOCAL, 1); }
dds_qos_t* status_reader() { return make(DDS_DURABILITY_TRANSIENT_LOCAL, kReaderDepth); }

}  // namespace mpm::transport::dds_qos
