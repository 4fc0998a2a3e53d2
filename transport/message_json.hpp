// Messages as single-line JSON objects (what `mpm listen` prints, one per
// line, for jq and log shippers). Non-finite numbers become null.
#pragma once

#include <string>

#include "transport/messages.hpp"

namespace mpm::msg {

std::string to_json(const Alarm& alarm);
std::string to_json(const Status& status);
std::string to_json(const Sample& sample);
std::string to_json(const Diagnosis& diagnosis);

}  // namespace mpm::msg
