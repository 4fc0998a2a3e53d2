#include "config/number_text.hpp"

#include <cctype>
#include <charconv>
#include <system_error>

namespace mpm::config::detail {

std::string_view trim(std::string_view text) noexcept {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

std::optional<double> parse_double(std::string_view text) noexcept {
  // from_chars rejects a leading '+' but users (and YAML) may write one.
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && (text.front() == '+' || text.front() == '-')) return std::nullopt;
  }
  if (text.empty()) return std::nullopt;
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  // result_out_of_range: a literal like 1e999; report it as not a number
  // rather than silently turning it into inf or 0.
  if (ec != std::errc{} || ptr != end) return std::nullopt;
  return value;
}

bool is_nan_word(std::string_view text) noexcept {
  if (!text.empty() && (text.front() == '+' || text.front() == '-')) text.remove_prefix(1);
  if (text.size() != 3) return false;
  const auto lower = [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  };
  return lower(text[0]) == 'n' && lower(text[1]) == 'a' && lower(text[2]) == 'n';
}

}  // namespace mpm::config::detail
