// Minimal `--name value` / `--flag` option parsing for the mpm subcommands:
// every option is declared, unknown ones are usage errors. A valued option
// given more than once keeps every value (all()); get() sees the last.
#pragma once

#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace mpm {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  // valued: options that take a value; flags: options that do not.
  Args(int argc, char** argv, std::set<std::string> valued, std::set<std::string> flags) {
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "'");
      a = a.substr(2);
      std::string value;
      bool has_value = false;
      if (auto eq = a.find('='); eq != std::string::npos) {
        value = a.substr(eq + 1);
        a = a.substr(0, eq);
        has_value = true;
      }
      if (flags.count(a)) {
        if (has_value) throw UsageError("--" + a + " takes no value");
        flags_.insert(a);
      } else if (valued.count(a)) {
        if (!has_value) {
          if (i + 1 >= argc) throw UsageError("--" + a + " needs a value");
          value = argv[++i];
        }
        values_[a].push_back(value);
      } else {
        throw UsageError("unknown option --" + a);
      }
    }
  }
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  std::optional<std::string> get(const std::string& name) const {
    auto it = values_.find(name);
    if (it == values_.end()) return std::nullopt;
    return it->second.back();
  }
  // Every value of a repeatable option, in command-line order.
  std::vector<std::string> all(const std::string& name) const {
    auto it = values_.find(name);
    return it == values_.end() ? std::vector<std::string>{} : it->second;
  }
  std::string required(const std::string& name) const {
    auto v = get(name);
    if (!v) throw UsageError("--" + name + " is required");
    return *v;
  }
  double number(const std::string& name, double fallback) const {
    auto v = get(name);
    if (!v) return fallback;
    char* end = nullptr;
    const double x = std::strtod(v->c_str(), &end);
    if (end == v->c_str() || *end != '\0') throw UsageError("--" + name + ": expected a number, got '" + *v + "'");
    return x;
  }
  int integer(const std::string& name, int fallback) const {
    const double x = number(name, fallback);
    if (x != static_cast<int>(x)) throw UsageError("--" + name + ": expected an integer");
    return static_cast<int>(x);
  }

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::set<std::string> flags_;
};

}  // namespace mpm
