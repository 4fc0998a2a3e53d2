// Text of JSON scalars, shared by the writers that build JSON (`mpm
// diagnose`'s report, `mpm bench`'s figures) and the plant writer's flow
// lists ("[a, b]" is the same in YAML). Written once so that escaping and
// non-finite numbers are handled alike everywhere.
#pragma once

#include <string>
#include <vector>

namespace mpm::config {

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(const std::string& s);
// A number with `digits` significant digits (%g); null when not finite
// (JSON has no NaN or infinity).
std::string json_number(double v, int digits);
// "[a, b, ...]" of json_number(v_i, digits).
std::string json_number_list(const std::vector<double>& v, int digits);

}  // namespace mpm::config
