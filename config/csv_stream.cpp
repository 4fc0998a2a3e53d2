#include "config/csv_stream.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string_view>

#include <sys/stat.h>

#include "config/csv_rows.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config {
namespace {

constexpr std::size_t kChunk = 1 << 20;  // bytes read at a time

}  // namespace

CsvRowReader::CsvRowReader(const std::string& path, const Limits& limits)
    : source_(path), file_(std::fopen(path.c_str(), "rb")) {
  if (!file_) throw ConfigError(path + ": cannot open file: " + std::strerror(errno));
  struct stat info {};
  if (::fstat(::fileno(file_.get()), &info) != 0 || !S_ISREG(info.st_mode))
    throw ConfigError(path + ": not a regular file (a device, FIFO or directory is not read)");
  // A value takes a few dozen characters: a much longer line cannot be a
  // row of max_csv_columns columns (the one acceptance load_recording lacks).
  max_line_ = std::max<std::size_t>(1 << 20, 64 * (limits.max_csv_columns + 1));
  std::string_view header;
  if (!next_line(header))
    throw ConfigError(path + ":1: empty file, expected a header line with column names");
  if (header.substr(0, 3) == "\xEF\xBB\xBF") header.remove_prefix(3);  // UTF-8 byte order mark
  if (detail::is_blank_line(header)) {
    // As load_recording: a blank header before more lines is parsed as the
    // header it is (a lone CR inside it is that error; found by fuzz_csv).
    const std::string blank_header(header);
    std::string_view more;
    while (next_line(more))
      if (!detail::is_blank_line(more)) {
        detail::parse_csv_header(blank_header, path, limits);  // throws: CR, or no name
        detail::parse_csv_header({}, path, limits);             // throws: no name
      }
    throw ConfigError(path + ":1: empty file, expected a header line with column names");
  }
  layout_ = detail::parse_csv_header(header, path, limits);
}

bool CsvRowReader::fill() {
  if (eof_) return false;
  if (begin_ > 0) {  // keep the unfinished line, drop what was handed out
    buffer_.erase(0, begin_);
    begin_ = 0;
  }
  const std::size_t old = buffer_.size();
  buffer_.resize(old + kChunk);
  const std::size_t got = std::fread(buffer_.data() + old, 1, kChunk, file_.get());
  buffer_.resize(old + got);
  if (got < kChunk) {
    if (std::ferror(file_.get()))
      throw ConfigError(source_ + ": cannot read file: " + std::strerror(errno));
    eof_ = true;
  }
  return got > 0;
}

bool CsvRowReader::next_line(std::string_view& line) {
  for (;;) {
    const std::size_t end = buffer_.find('\n', begin_);
    if (end != std::string::npos || (eof_ && begin_ < buffer_.size())) {
      const std::size_t stop = end == std::string::npos ? buffer_.size() : end;
      line = std::string_view(buffer_).substr(begin_, stop - begin_);
      begin_ = end == std::string::npos ? buffer_.size() : end + 1;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      ++line_;
      return true;
    }
    if (buffer_.size() - begin_ > max_line_)
      throw ConfigError(source_ + ":" + std::to_string(line_ + 1) + ": line longer than " +
                        std::to_string(max_line_) + " bytes");
    if (!fill()) return false;
  }
}

bool CsvRowReader::next(std::vector<double>& row) {
  row.clear();
  if (has_pending_) {
    if (held_blank_ > 0) {  // blank lines before more data are rows, as in load_recording
      --held_blank_;
      detail::parse_csv_row({}, held_first_line_++, layout_, source_, row);
      return true;
    }
    has_pending_ = false;
    detail::parse_csv_row(pending_, pending_line_, layout_, source_, row);
    return true;
  }
  std::string_view line;
  while (next_line(line)) {
    if (detail::is_blank_line(line)) {  // fine at the end of the file
      if (held_blank_++ == 0) held_first_line_ = line_;
      continue;
    }
    if (held_blank_ > 0) {
      pending_.assign(line);  // reused: no allocation once it has grown
      pending_line_ = line_;
      has_pending_ = true;
      return next(row);
    }
    detail::parse_csv_row(line, line_, layout_, source_, row);
    return true;
  }
  return false;
}

}  // namespace mpm::config
