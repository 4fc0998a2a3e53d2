#include "config/settings_doc.hpp"

#include <cmath>
#include <sstream>
#include <type_traits>
#include <variant>

#include "config/daemon_config.hpp"

namespace mpm::config {
namespace {

// A row's default as the file would write it.
template <class S>
std::string default_text(const FieldRow<S>& row, const S& defaults) {
  std::ostringstream t;
  t.precision(12);
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          t << '`' << (*p ? row.true_word : row.false_word) << '`';
        } else if constexpr (std::is_same_v<T, std::string>) {
          t << (p->empty() ? "none" : *p);
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          t << "`[]`";
        } else {
          const double v = static_cast<double>(*p);
          if (row.word && v == row.range.also) {
            t << '`' << row.word << '`';
          } else {
            t << v;
          }
        }
      },
      row.get(defaults));
  return t.str();
}

template <class S>
std::string allowed_text(const FieldRow<S>& row) {
  if (row.false_word) return std::string("`") + row.false_word + "` or `" + row.true_word + "`";
  if (std::isinf(row.range.min) && std::isinf(row.range.max)) return "";
  return row.range.describe(row.word);
}

template <class S>
void rows(std::ostringstream& out, const std::vector<FieldRow<S>>& table, const S& defaults, const char* prefix) {
  for (const FieldRow<S>& row : table)
    out << "| `" << prefix << row.key << "` | " << default_text(row, defaults) << " | " << allowed_text(row) << " | "
        << row.help << " |\n";
}

}  // namespace

std::string settings_table_markdown() {
  const DaemonConfig defaults;
  std::ostringstream out;
  out << "| key | default | allowed | meaning |\n|---|---|---|---|\n";
  rows<ServiceSettings>(out, ServiceSettings::monitor_fields(), defaults, "monitor.");
  rows<ServiceSettings>(out, ServiceSettings::fields(), defaults, "");
  rows<DaemonConfig>(out, DaemonConfig::fields(), defaults, "");
  rows<Limits>(out, Limits::fields(), defaults.limits, "limits.");
  return out.str();
}

}  // namespace mpm::config
