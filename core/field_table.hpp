// One row per setting of a settings struct: its key, where it lives, the
// values it may take and one line of help. The struct's own member
// initialisers are the defaults. Everything that lists the settings walks
// the rows instead of naming the fields again: validate() here, the YAML
// reader and the example config's test (config/), the command-line flags
// (daemon/) and the docs. A new setting is one row plus its use.
//
// Plain data and setup-time code only (no I/O; std::function and strings are
// built once, when the table is first asked for).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace mpm {

// What is wrong with one setting: `field` is its key, so a caller points at
// the key (a file's line, a flag) without reading the message.
struct FieldError {
  std::string field;
  std::string message;  // "forgetting must be in (0.9, 1], got 1.5"
};

// The numbers a setting may be: [min, max] with either end open, whole
// numbers only, and one more allowed value outside it (`also`: 0 = "off",
// or the number a word such as "auto" stands for).
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  bool max_open = false;
  bool whole = false;
  double also = std::numeric_limits<double>::quiet_NaN();  // NaN = none

  bool contains(double v) const {
    if (v == also) return true;
    if (std::isnan(v) || (whole && v != std::floor(v))) return false;
    return (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
  }
  // "in (0.9, 1]", "0 or in [3, 1e+06]", "a whole number in [1, 200]", ">= 0";
  // `word` in place of `also` when the file writes it as a word ("auto").
  std::string describe(const char* word = nullptr) const {
    std::ostringstream t;
    t.precision(12);  // 1048576, not 1.04858e+06
    if (word) {
      t << '"' << word << "\" or ";
    } else if (!std::isnan(also)) {
      t << also << " or ";
    }
    if (whole) t << "a whole number ";
    if (std::isinf(max) && !std::isinf(min)) {
      t << (min_open ? "> " : ">= ") << min;
    } else {
      t << "in " << (min_open ? '(' : '[') << min << ", " << max << (max_open ? ')' : ']');
    }
    return t.str();
  }
};

// std::size_t settings (the loaders' caps) are std::uint64_t* rows.
static_assert(std::is_same_v<std::size_t, std::uint64_t>, "a size_t setting needs its own alternative");

template <class S>
struct FieldRow {
  using Ref = std::variant<int*, double*, std::int64_t*, std::uint64_t*, bool*, std::string*,
                           std::vector<double>*>;
  const char* key;             // file key; the flag is "--" + key with '-' for '_'
  std::function<Ref(S&)> ref;  // where the value lives in S
  Range range;                 // numbers only; the default Range allows any
  const char* help;            // one line, for the docs and --help
  // A word the file or flag may give instead of a number ("auto"), and what
  // it does (sets the number to its "automatic" value, or a flag beside it).
  const char* word = nullptr;
  std::function<void(S&)> on_word = {};
  // For a bool: the words of false and true (regressors: model_filtered |
  // plain_lags); nullptr = true/false.
  const char* false_word = nullptr;
  const char* true_word = nullptr;
  // A row lifted from an inner struct (lift()): the inner struct's errors()
  // checks its range, so range_errors() of the outer table skips it.
  bool checked_inside = false;

  Ref get(const S& s) const { return ref(const_cast<S&>(s)); }  // read only
};

// The value of a number field as a double (NaN for strings, bools and lists).
inline double number_of(const std::variant<int*, double*, std::int64_t*, std::uint64_t*, bool*,
                                           std::string*, std::vector<double>*>& ref) {
  return std::visit(
      [](auto* p) -> double {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
          return static_cast<double>(*p);
        } else {
          return std::numeric_limits<double>::quiet_NaN();
        }
      },
      ref);
}

// One error per number outside its row's range (in table order).
template <class S>
std::vector<FieldError> range_errors(const std::vector<FieldRow<S>>& rows, const S& s) {
  std::vector<FieldError> errors;
  for (const FieldRow<S>& row : rows) {
    if (row.checked_inside) continue;
    const double v = number_of(row.get(s));
    if (std::isnan(v) && !std::holds_alternative<double*>(row.get(s))) continue;  // not a number field
    if (row.range.contains(v)) continue;
    std::ostringstream m;
    m.precision(12);
    m << row.key << " must be " << row.range.describe(row.word) << ", got " << v;
    errors.push_back({row.key, m.str()});
  }
  return errors;
}

// The rows of a part of Outer (Outer::*member), keeping only `keys` (all
// when empty), so an outer table lists an inner struct's settings without
// repeating their ranges.
template <class Outer, class Inner>
std::vector<FieldRow<Outer>> lift(const std::vector<FieldRow<Inner>>& rows, Inner Outer::*member,
                                  const std::vector<std::string>& keys = {}) {
  std::vector<FieldRow<Outer>> out;
  for (const FieldRow<Inner>& row : rows) {
    bool wanted = keys.empty();
    for (const std::string& k : keys) wanted = wanted || k == row.key;
    if (!wanted) continue;
    FieldRow<Outer> o;
    o.key = row.key;
    o.ref = [inner = row.ref, member](Outer& s) { return inner(s.*member); };
    o.range = row.range;
    o.help = row.help;
    o.word = row.word;
    if (row.on_word) o.on_word = [inner = row.on_word, member](Outer& s) { inner(s.*member); };
    o.false_word = row.false_word;
    o.true_word = row.true_word;
    o.checked_inside = true;
    out.push_back(std::move(o));
  }
  return out;
}

// "a; b; c": the errors as one message (the old validate() string).
inline std::string joined(const std::vector<FieldError>& errors) {
  std::string s;
  for (const FieldError& e : errors) s += (s.empty() ? "" : "; ") + e.message;
  return s;
}

}  // namespace mpm
