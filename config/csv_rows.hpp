// The CSV tokenizer shared by the whole-file reader (recording.cpp) and the
// streaming one (csv_stream.cpp), so both accept and refuse exactly the
// same text. Internal to config/.
//
// Dialects (formats.md section 4.4): the separator is ',' or ';', told from
// the header (a header with both outside quotes, or with tabs and neither,
// is refused); with ';' a value's ',' is its decimal mark. Fields may be
// quoted as RFC 4180 says ("a ""b""" is a "b"; the quotes are not part of
// a name), but a quoted field may not span lines. The column `t` also takes
// ISO-8601 times, converted to seconds since the Unix epoch. A UTF-8 BOM and
// CRLF line ends are the callers' (they strip them); UTF-16 and CR-only
// line ends are refused by name.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "config/limits.hpp"

namespace mpm::config::detail {

// What the header says about the rows below it.
struct CsvLayout {
  std::vector<std::string> names;
  char separator = ',';
  std::size_t time_column = static_cast<std::size_t>(-1);  // the column named t, if any
};

// The header's column names and dialect; throws ConfigError (line 1) for
// more than limits.max_csv_columns columns, an empty or a duplicate name, or
// a dialect that is not read.
CsvLayout parse_csv_header(std::string_view line, const std::string& source, const Limits& limits);

// Appends one data line's values (NaN for an empty field or nan); throws
// ConfigError naming the line and column for a wrong field count or a bad value.
void parse_csv_row(std::string_view line, std::size_t line_number, const CsvLayout& layout,
                   const std::string& source, std::vector<double>& values);

// True for a line of nothing but blanks: tolerated at the end of a file.
bool is_blank_line(std::string_view line);

}  // namespace mpm::config::detail
