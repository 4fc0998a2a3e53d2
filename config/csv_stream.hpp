// A recording read row by row, for tools whose memory must not grow with
// the record (`mpm monitor` over 10^7 samples). One buffer, reused: a chunk
// of the file plus the line being completed; rows are parsed in place with
// the same functions as load_recording (csv_rows.hpp), so the two accept
// the same files, give the same values and the same located errors.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "config/csv_rows.hpp"
#include "config/limits.hpp"
#include "config/row_source.hpp"

namespace mpm::config {

class CsvRowReader final : public RowSource {
 public:
  // Opens `path` (a regular file only) and reads its header. Throws
  // ConfigError naming the file (and line) as load_recording does.
  explicit CsvRowReader(const std::string& path, const Limits& limits = {});

  const std::vector<std::string>& names() const override { return layout_.names; }
  const std::string& source() const override { return source_; }

  // The next data row's values (one per column, NaN = missing) into `row`,
  // resized to names().size(); false at the end of the file. Throws
  // ConfigError for a bad row. Blank lines at the end are ignored.
  bool next(std::vector<double>& row) override;

 private:
  bool next_line(std::string_view& line);
  bool fill();

  struct Closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  std::string source_;
  std::unique_ptr<std::FILE, Closer> file_;
  detail::CsvLayout layout_;  // names and dialect, from the header
  std::string buffer_;        // [begin_, buffer_.size()) not yet handed out
  std::size_t begin_ = 0;
  bool eof_ = false;
  std::size_t line_ = 0;      // 1-based number of the last line handed out
  std::size_t max_line_ = 0;  // longest line accepted, from the column cap
  // Blank lines are held back: ignored at the end of the file, rows (or a
  // field-count error) when data follows them, as in load_recording.
  std::size_t held_blank_ = 0;
  std::size_t held_first_line_ = 0;
  std::string pending_;       // the data line that followed them
  std::size_t pending_line_ = 0;
  bool has_pending_ = false;
};

}  // namespace mpm::config
