// Command-line flags from a settings table (core/field_table.hpp): one flag
// per row, "--" + key with '-' for '_' (monitor.forgetting is --forgetting,
// limits.max_delay_samples is --max-delay-samples), checked against the
// row's range, with a usage line made from its help. So `mpm monitor` takes
// every `monitor:` key of mpmd.yaml under the same name and range, and a new
// row is a new flag without another line here.
#pragma once

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "config/setting_text.hpp"
#include "core/field_table.hpp"
#include "daemon/args.hpp"

namespace mpm {

template <class S>
std::string flag_of(const FieldRow<S>& row) {
  std::string flag = row.key;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

// The rows named `keys`, in table order (a command that takes some settings).
template <class S>
std::vector<FieldRow<S>> only(const std::vector<FieldRow<S>>& rows, const std::set<std::string>& keys) {
  std::vector<FieldRow<S>> out;
  for (const FieldRow<S>& row : rows)
    if (keys.count(row.key)) out.push_back(row);
  return out;
}

// `valued` plus one flag per row.
template <class S>
std::set<std::string> with_flags(const std::vector<FieldRow<S>>& rows, std::set<std::string> valued) {
  for (const FieldRow<S>& row : rows) valued.insert(flag_of(row));
  return valued;
}

// Applies every row's flag that was given to `s`, read as the file's value
// would be (config/setting_text.hpp). Throws UsageError naming the flag.
template <class S>
void apply_flags(const Args& args, const std::vector<FieldRow<S>>& rows, S& s) {
  for (const FieldRow<S>& row : rows) {
    const std::string flag = flag_of(row);
    if (const auto text = args.get(flag))
      if (const std::string problem = config::set_from_text(row, s, *text); !problem.empty())
        throw UsageError("--" + flag + ": " + problem);
  }
}

// One usage line per row: "  --forgetting V  RLS forgetting factor ... (in (0.9, 1])", with
// "; default 0.999" before the ")" when asked.
template <class S>
std::string flags_usage(const std::vector<FieldRow<S>>& rows, bool with_defaults = false) {
  const S defaults{};
  std::string out;
  for (const FieldRow<S>& row : rows) {
    out += "  --" + flag_of(row) + " V  " + row.help;
    if (row.false_word) {
      out += std::string(" (") + row.false_word + " or " + row.true_word + ")";
    } else if (!std::isinf(row.range.min) || !std::isinf(row.range.max)) {
      out += " (" + row.range.describe(row.word);
      // The default is the struct's member initialiser, never written twice
      // (not for a command whose defaults differ from the struct's, as
      // `mpm monitor`'s forgetting 1 over the whole record).
      if (const double d = number_of(row.get(defaults)); with_defaults && !std::isnan(d)) {
        char text[32];
        std::snprintf(text, sizeof text, "%g", d);
        out += std::string("; default ") + text;
      }
      out += ")";
    }
    out += '\n';
  }
  return out;
}

}  // namespace mpm
