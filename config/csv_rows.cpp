// The CSV tokenizer and the header and row parsers (csv_rows.hpp). Rows are
// the hot path of million-row recordings: fields are string_views into the
// line, an unquoted field ends at the next separator (memchr), and a value
// is converted by std::from_chars; nothing is allocated per row.
#include "config/csv_rows.hpp"

#include <cmath>
#include <limits>
#include <map>

#include "config/iso_time.hpp"
#include "config/number_text.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config::detail {
namespace {

constexpr std::size_t kEnd = std::string_view::npos;

std::string where(const std::string& source, std::size_t line) {
  return source + ":" + std::to_string(line) + ": ";
}

// For a message: control characters as '?', long text cut.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 80)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return text.size() > 80 ? out + "..." : out;
}

struct Field {
  std::string_view text;  // inside the quotes when quoted; "" pairs still doubled when escaped
  bool quoted = false;
  bool escaped = false;
};

enum class FieldProblem { kNone, kUnterminatedQuote, kTextAfterQuote };

const char* describe(FieldProblem p) {
  return p == FieldProblem::kUnterminatedQuote
             ? "a quoted field has no closing quote (a quoted field cannot span lines)"
             : "text after a quoted field's closing quote (a quote inside a quoted field is written \"\")";
}

bool blank(char c) { return c == ' ' || c == '\t'; }

// The field starting at `pos`; `pos` moves past its separator, or to kEnd
// after the last field of the line.
FieldProblem next_field(std::string_view line, std::size_t& pos, char sep, Field& out) {
  // The common case first: an unquoted field up to the next separator.
  const std::size_t end = line.find(sep, pos);
  const std::string_view field = trim(line.substr(pos, end == kEnd ? kEnd : end - pos));
  if (field.empty() || field.front() != '"') {
    out = {field, false, false};
    pos = end == kEnd ? kEnd : end + 1;
    return FieldProblem::kNone;
  }
  // Quoted: the separator found above may be inside the quotes.
  const std::size_t i = static_cast<std::size_t>(field.data() - line.data());
  std::size_t j = i + 1;
  bool escaped = false;
  for (;; j += 2, escaped = true) {
    j = line.find('"', j);
    if (j == kEnd) return FieldProblem::kUnterminatedQuote;
    if (j + 1 >= line.size() || line[j + 1] != '"') break;
  }
  out = {line.substr(i + 1, j - i - 1), true, escaped};
  std::size_t k = j + 1;
  while (k < line.size() && blank(line[k])) ++k;
  if (k == line.size()) {
    pos = kEnd;
  } else if (line[k] == sep) {
    pos = k + 1;
  } else {
    return FieldProblem::kTextAfterQuote;
  }
  return FieldProblem::kNone;
}

// Fields of a line as the tokenizer splits it (up to a bad quote).
std::size_t count_fields(std::string_view line, char sep) {
  std::size_t n = 0;
  Field f;
  for (std::size_t pos = 0; pos != kEnd;) {
    ++n;
    if (next_field(line, pos, sep, f) != FieldProblem::kNone) break;
  }
  return n;
}

std::string unescape(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '"') ++i;  // "" -> "
  }
  return out;
}

// ',' or ';', from what the header has outside quotes.
char detect_separator(std::string_view line, const std::string& source) {
  std::size_t commas = 0, semicolons = 0, tabs = 0;
  bool quoted = false;
  for (const char c : line) {
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    commas += c == ',';
    semicolons += c == ';';
    tabs += c == '\t';
  }
  if (commas > 0 && semicolons > 0)
    throw ConfigError(where(source, 1) + "header: both ',' and ';' outside quotes, cannot tell the separator "
                                         "(quote the names that contain one)");
  if (commas == 0 && semicolons == 0 && tabs > 0)
    throw ConfigError(where(source, 1) + "header: tab-separated columns are not read; separate them with ',' or ';'");
  return semicolons > 0 ? ';' : ',';
}

[[noreturn, gnu::cold, gnu::noinline]] void bad_value(std::string_view text, const CsvLayout& layout, std::size_t col,
                                                     const std::string& source, std::size_t line) {
  const bool time = col == layout.time_column;
  throw ConfigError(where(source, line) + "column '" + printable(layout.names[col]) + "': expected " +
                    (time ? "a time in seconds or an ISO-8601 time such as 2026-11-25T08:00:00.5Z"
                          : "a finite number (or an empty field or nan for a missing sample)") +
                    ", got '" + printable(text) + "'");
}

// Another spelling than a plain number: a decimal comma under ';', an
// ISO-8601 time in t. Off the hot path.
[[gnu::noinline]] std::optional<double> parse_other(std::string_view text, const CsvLayout& layout, std::size_t col) {
  std::optional<double> value;
  if (layout.separator == ';' && text.size() < 64 && text.find(',') != kEnd) {
    char decimal[64];  // with ';' between fields, ',' is the decimal mark
    for (std::size_t k = 0; k < text.size(); ++k) decimal[k] = text[k] == ',' ? '.' : text[k];
    value = parse_double({decimal, text.size()});
  }
  if (!value && col == layout.time_column && looks_like_date(text)) value = parse_iso8601(text);
  return value;
}

double parse_value(const Field& f, const CsvLayout& layout, std::size_t col, const std::string& source,
                   std::size_t line) {
  const std::string_view text = f.quoted ? trim(f.text) : f.text;
  if (text.empty() || is_nan_word(text)) return std::numeric_limits<double>::quiet_NaN();
  if (!f.escaped) {
    std::optional<double> value = parse_double(text);
    if (!value) value = parse_other(text, layout, col);
    if (value && std::isfinite(*value)) return *value;
  }
  bad_value(text, layout, col, source, line);
}

}  // namespace

CsvLayout parse_csv_header(std::string_view line, const std::string& source, const Limits& limits) {
  if (line.substr(0, 2) == "\xFF\xFE" || line.substr(0, 2) == "\xFE\xFF")
    throw ConfigError(where(source, 1) + "UTF-16 text is not read: save the file as UTF-8 (or ASCII)");
  if (line.find('\r') != kEnd)
    throw ConfigError(where(source, 1) + "a carriage return inside a line: lines must end in LF or CRLF, "
                                         "not CR alone (old Mac line ends)");
  CsvLayout layout;
  layout.separator = detect_separator(line, source);
  // Counted before anything is stored: a header of a million columns is an
  // error here, not a million names and a rows x columns buffer.
  if (const std::size_t n = count_fields(line, layout.separator); n > limits.max_csv_columns)
    throw ConfigError(where(source, 1) + "header: expected 1.." + std::to_string(limits.max_csv_columns) +
                      " columns, got " + std::to_string(n) + " (the limit is Limits::max_csv_columns)");
  std::map<std::string, std::size_t, std::less<>> column_of;
  Field f;
  for (std::size_t pos = 0, col = 1; pos != kEnd; ++col) {
    if (const FieldProblem p = next_field(line, pos, layout.separator, f); p != FieldProblem::kNone)
      throw ConfigError(where(source, 1) + "header, column " + std::to_string(col) + ": " + describe(p));
    std::string name = f.escaped ? unescape(f.text) : std::string(f.text);
    if (name.empty())
      throw ConfigError(where(source, 1) + "column " + std::to_string(col) + " of the header has no name");
    const auto [it, fresh] = column_of.emplace(name, col);
    if (!fresh)
      throw ConfigError(where(source, 1) + "duplicate column name '" + printable(name) + "' (columns " +
                        std::to_string(it->second) + " and " + std::to_string(col) + ")");
    if (name == "t") layout.time_column = layout.names.size();
    layout.names.push_back(std::move(name));
  }
  return layout;
}

void parse_csv_row(std::string_view line, std::size_t line_number, const CsvLayout& layout,
                   const std::string& source, std::vector<double>& values) {
  const std::size_t n = layout.names.size();
  std::size_t pos = 0;
  Field f;
  for (std::size_t col = 0; col < n; ++col) {
    if (const FieldProblem p = next_field(line, pos, layout.separator, f); p != FieldProblem::kNone)
      throw ConfigError(where(source, line_number) + "column '" + printable(layout.names[col]) + "': " + describe(p));
    // The count is checked before the value, as the line's shape is the
    // more basic error.
    if ((pos == kEnd) != (col + 1 == n))
      throw ConfigError(where(source, line_number) + "expected " + std::to_string(n) +
                        " fields (as in the header), got " + std::to_string(count_fields(line, layout.separator)));
    values.push_back(parse_value(f, layout, col, source, line_number));
  }
}

bool is_blank_line(std::string_view line) { return line.find_first_not_of(" \t\r") == kEnd; }

}  // namespace mpm::config::detail
