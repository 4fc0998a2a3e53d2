#include "config/iso_time.hpp"

#include <cstdint>

namespace mpm::config::detail {
namespace {

class Cursor {
 public:
  explicit Cursor(std::string_view t) : t_(t) {}
  bool done() const { return i_ == t_.size(); }
  bool take(char c) {
    if (i_ < t_.size() && t_[i_] == c) return ++i_, true;
    return false;
  }
  bool take_any(std::string_view set) {
    if (i_ < t_.size() && set.find(t_[i_]) != std::string_view::npos) return ++i_, true;
    return false;
  }
  // Exactly n digits.
  bool digits(int n, int& out) {
    out = 0;
    for (int k = 0; k < n; ++k, ++i_) {
      if (i_ >= t_.size() || t_[i_] < '0' || t_[i_] > '9') return false;
      out = out * 10 + (t_[i_] - '0');
    }
    return true;
  }
  // One or more digits as a fraction 0.d1d2...
  bool fraction(double& out) {
    out = 0.0;
    double scale = 0.1;
    const std::size_t start = i_;
    for (; i_ < t_.size() && t_[i_] >= '0' && t_[i_] <= '9'; ++i_, scale /= 10) out += (t_[i_] - '0') * scale;
    return i_ > start;
  }

 private:
  std::string_view t_;
  std::size_t i_ = 0;
};

bool leap(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

int days_in_month(int y, int m) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && leap(y) ? 29 : kDays[m - 1];
}

// Days from 1970-01-01 to y-m-d in the proleptic Gregorian calendar
// (H. Hinnant's days_from_civil).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

}  // namespace

bool looks_like_date(std::string_view text) noexcept {
  return text.size() >= 10 && text[4] == '-' && text[0] >= '0' && text[0] <= '9';
}

std::optional<double> parse_iso8601(std::string_view text) noexcept {
  Cursor c(text);
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  double frac = 0.0;
  if (!c.digits(4, y) || !c.take('-') || !c.digits(2, mo) || !c.take('-') || !c.digits(2, d)) return std::nullopt;
  if (!c.take_any("Tt ") || !c.digits(2, h) || !c.take(':') || !c.digits(2, mi)) return std::nullopt;
  if (c.take(':')) {
    if (!c.digits(2, s)) return std::nullopt;
    if (c.take_any(".,") && !c.fraction(frac)) return std::nullopt;
  }
  int offset_minutes = 0;
  if (!c.take_any("Zz")) {
    const bool plus = c.take('+');
    if (plus || c.take('-')) {
      int oh = 0, om = 0;
      if (!c.digits(2, oh)) return std::nullopt;
      if (!c.done()) {
        c.take(':');
        if (!c.digits(2, om)) return std::nullopt;
      }
      if (oh > 23 || om > 59) return std::nullopt;
      offset_minutes = (plus ? 1 : -1) * (oh * 60 + om);
    }
  }
  if (!c.done()) return std::nullopt;
  if (mo < 1 || mo > 12 || d < 1 || d > days_in_month(y, mo) || h > 23 || mi > 59 || s > 59) return std::nullopt;
  const std::int64_t seconds = days_from_civil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d)) * 86400 +
                               h * 3600 + mi * 60 + s - offset_minutes * 60;
  return static_cast<double>(seconds) + frac;
}

}  // namespace mpm::config::detail
