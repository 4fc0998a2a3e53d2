// The `--max-...` flags of the commands that read plant files and
// recordings: one per cap of config::Limits::fields() (--max-inputs,
// --max-delay-samples, --max-csv-columns, ...), so a bigger plant than the
// defaults allow is a flag away, and a wrong value is a usage error naming
// the flag and the range.
#pragma once

#include <set>
#include <string>

#include "config/limits.hpp"
#include "daemon/args.hpp"

namespace mpm {

inline std::string limit_flag(const FieldRow<config::Limits>& row) {
  std::string flag = row.key;
  for (char& c : flag) c = c == '_' ? '-' : c;
  return flag;
}

// `valued` plus every limit flag, for Args.
inline std::set<std::string> with_limit_flags(std::set<std::string> valued) {
  for (const FieldRow<config::Limits>& row : config::Limits::fields()) valued.insert(limit_flag(row));
  return valued;
}

// The defaults with every limit flag given applied. Throws UsageError.
inline config::Limits limits_from(const Args& args) {
  config::Limits limits;
  for (const FieldRow<config::Limits>& row : config::Limits::fields()) {
    const std::string flag = limit_flag(row);
    if (!args.get(flag)) continue;
    if (const std::string problem = config::set_limit(limits, row.key, args.number(flag, 0.0)); !problem.empty())
      throw UsageError("--" + flag + ": " + problem);
  }
  return limits;
}

// For usage texts (a literal, so it joins the commands' literals).
#define MPM_LIMIT_FLAGS_USAGE                                                                        \
  "  --max-inputs N, --max-outputs N, --max-poly-length N, --max-delay-samples N,\n"               \
  "  --max-states N, --max-yaml-bytes N, --max-csv-columns N, --max-csv-bytes N\n"                  \
  "                     the loaders' caps on the plant file and the recording (defaults 100,\n"   \
  "                     100, 200, 1000, 50, 64 MiB, 10000, 16 GiB)\n"

}  // namespace mpm
