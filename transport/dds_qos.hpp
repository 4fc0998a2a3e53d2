// The QoS of each topic, chosen for what the data is for:
//
// * samples: RELIABLE, VOLATILE, KEEP_LAST(depth). A sample is only useful
//   live; keep-last means a slow or absent monitor never blocks the
//   controller's writer, and a reader that falls behind loses the oldest
//   samples, which the daemon sees and counts as a sequence gap.
// * alarms: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST(1) per instance. An
//   instance is one (controller, output, input) channel, so an operator tool
//   that joins late receives the current state of every channel that has
//   raised: the alarms raised now.
// * status: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST(1) per controller: a tool
//   that joins sees every monitor's latest status at once; older ones are
//   superseded anyway.
//
// Reader and writer of a topic use the same policies, so they always match
// (a best-effort writer would never match a reliable reader).
#pragma once

#include <dds/dds.h>

namespace mpm::transport::dds_qos {

dds_qos_t* sample(int depth);
dds_qos_t* alarm_writer();
dds_qos_t* alarm_reader();
dds_qos_t* status_writer();
dds_qos_t* status_reader();

}  // namespace mpm::transport::dds_qos
