// The pieces of the CSV reader shared by the whole-file reader
// (recording.cpp) and the streaming one (csv_stream.cpp), so both accept
// and refuse exactly the same text. Internal to config/.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "config/limits.hpp"

namespace mpm::config::detail {

// The header's column names; throws ConfigError (line 1) for more than
// limits.max_csv_columns columns, an empty or a duplicate name.
std::vector<std::string> parse_csv_header(std::string_view line, const std::string& source,
                                          const Limits& limits);

// Appends one data line's values (NaN for an empty field or nan); throws
// ConfigError naming the line and column for a wrong field count or a bad value.
void parse_csv_row(std::string_view line, std::size_t line_number, const std::vector<std::string>& names,
                   const std::string& source, std::vector<double>& values);

// True for a line of nothing but blanks: tolerated at the end of a file.
bool is_blank_line(std::string_view line);

}  // namespace mpm::config::detail
