// CSV recordings (formats.md section 2): parse, load, write.
//
// Recordings reach millions of rows, so the reader takes the whole text at
// once, walks it with string_views (no per-line or per-field allocation) and
// converts with std::from_chars; values go into one row-major buffer that is
// copied into the matrix at the end.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>

#include "config/csv_rows.hpp"
#include "config/file_text.hpp"
#include "config/number_text.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config {
namespace {

using detail::trim;

// Hands out the lines of a text one at a time, without '\n' or a final '\r'.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : rest_(text) {}
  bool done() const { return rest_.empty(); }
  std::size_t number() const { return number_; }  // 1-based, of the last line returned
  std::string_view next() {
    const auto end = rest_.find('\n');
    std::string_view line = rest_.substr(0, end);
    rest_ = end == std::string_view::npos ? std::string_view{} : rest_.substr(end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return line;
  }
  // True when nothing but line breaks and blanks remains (a trailing newline
  // or a few empty lines at the end are tolerated).
  bool only_blank_left() const {
    return rest_.find_first_not_of(" \t\r\n") == std::string_view::npos;
  }

 private:
  std::string_view rest_;
  std::size_t number_ = 0;
};

}  // namespace


namespace {

void append_value(std::string& out, double x, const std::string& path, std::size_t row,
                  const std::string& column) {
  if (std::isnan(x)) return;  // missing sample: empty field
  if (std::isinf(x))
    throw ConfigError(path + ": row " + std::to_string(row) + ", column '" + column +
                      "': cannot write an infinite value (only finite numbers or NaN)");
  char text[32];
  // Shortest representation that reads back to the same bits.
  const auto result = std::to_chars(text, text + sizeof text, x);
  out.append(text, result.ptr);
}

}  // namespace

std::optional<std::size_t> Recording::find(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return std::nullopt;
  return static_cast<std::size_t>(it - names.begin());
}

Recording parse_recording(const std::string& csv_text, const std::string& source_name,
                          const Limits& limits) {
  std::string_view text = csv_text;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
  LineCursor lines(text);
  if (lines.only_blank_left())
    throw ConfigError(source_name + ":1: empty file, expected a header line with column names");
  Recording rec;
  rec.source = source_name;
  const detail::CsvLayout layout = detail::parse_csv_header(lines.next(), source_name, limits);
  rec.names = layout.names;
  const std::size_t cols = rec.names.size();
  std::vector<double> values;
  // Every value takes at least one byte of the text (its comma or line
  // break), so the text's size bounds the buffer whatever the line count.
  const auto lines_left = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n') + 1);
  values.reserve(std::min(lines_left * cols, text.size() + cols));
  while (!lines.only_blank_left()) {
    const std::string_view line = lines.next();
    // A blank line before more data is a row of empty fields, whatever
    // blanks it holds (as CsvRowReader reads it: found by fuzz_csv).
    detail::parse_csv_row(detail::is_blank_line(line) ? std::string_view{} : line, lines.number(), layout,
                          source_name, values);
  }
  const auto rows = static_cast<Eigen::Index>(values.size() / cols);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  rec.data = Eigen::Map<const RowMajor>(values.data(), rows, static_cast<Eigen::Index>(cols));
  return rec;
}

Recording load_recording(const std::string& path, const Limits& limits) {
  return parse_recording(detail::read_file(path, limits.max_csv_bytes), path, limits);
}

void write_recording(const std::string& path, const Recording& rec) {
  if (static_cast<std::size_t>(rec.data.cols()) != rec.names.size())
    throw ConfigError(path + ": recording has " + std::to_string(rec.names.size()) + " names but " +
                      std::to_string(rec.data.cols()) + " data columns");
  std::string out;
  for (std::size_t c = 0; c < rec.names.size(); ++c) {
    const std::string& name = rec.names[c];
    if (name.empty() || name.find_first_of(",\"\r\n") != std::string::npos || trim(name) != name)
      throw ConfigError(path + ": column name '" + name + "' cannot be written in a CSV header");
    out += (c ? "," : "") + name;
  }
  out += '\n';
  out.reserve(out.size() + static_cast<std::size_t>(rec.data.size()) * 20);
  for (Eigen::Index r = 0; r < rec.data.rows(); ++r) {
    for (Eigen::Index c = 0; c < rec.data.cols(); ++c) {
      if (c) out += ',';
      append_value(out, rec.data(r, c), path, static_cast<std::size_t>(r),
                   rec.names[static_cast<std::size_t>(c)]);
    }
    out += '\n';
  }
  detail::write_file(path, out);
}

}  // namespace mpm::config
