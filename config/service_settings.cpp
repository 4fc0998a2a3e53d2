#include "config/service_settings.hpp"

#include <cstdio>
#include <type_traits>

namespace mpm::config {

using S = ServiceSettings;

const std::vector<FieldRow<S>>& ServiceSettings::monitor_fields() {
  static const std::vector<FieldRow<S>> rows = [] {
    std::vector<FieldRow<S>> r = lift(MonitorSettings::fields(), &S::monitor);
    for (FieldRow<S>& row : r) {
      if (std::string(row.key) != "input_pole") continue;
      row.word = "auto";  // the plant's dominant pole, found at setup
      row.on_word = [](S& s) { s.input_pole_auto = true; };
      row.help = "Laguerre pole of the input basis (0 = plain lags; auto = the plant's dominant pole)";
    }
    const std::vector<FieldRow<S>> front_end = {
        {"regressors", [](S& s) { return &s.plain_lags; }, {},
         "model_filtered (input lags filtered through the nominal channel) or plain_lags (the paper's)",
         nullptr, {}, "model_filtered", "plain_lags"},
        {"settle_samples", [](S& s) { return &s.settle_samples; }, {.min = 0, .max = 1e9, .whole = true, .also = -1},
         "samples skipped while the model's start-up transient decays (auto = the plant's settling time)",
         "auto", [](S& s) { s.settle_samples = -1; }},
    };
    r.insert(r.end(), front_end.begin(), front_end.end());
    return r;
  }();
  return rows;
}

const std::vector<FieldRow<S>>& ServiceSettings::fields() {
  static const std::vector<FieldRow<S>> rows = {
      {"log_interval", [](S& s) { return &s.log_interval; }, {.min = 0.0},
       "seconds between repeats of one kind of log line (each kind of data problem, and reloads, logged at once, then at most once per interval with the count in between)"},
      {"max_sequence_jump", [](S& s) { return &s.max_sequence_jump; }, {.min = 1, .max = 1e15, .whole = true},
       "the largest sequence gap (or step back) taken as plausible; a larger jump is counted (`restarts`), logged and resynchronised on, like a publisher restart"},
      {"stale_after", [](S& s) { return &s.stale_after; }, {.min = 0.0, .max = 1e9, .also = -1},
       "seconds without a usable sample: status not ready (0 = never, auto = the longer of 60 s and 10 samples)",
       "auto", [](S& s) { s.stale_after = -1; }},
      {"diagnosis_window", [](S& s) { return &s.diagnosis_window; }, {.min = 200, .max = 1e6, .whole = true, .also = 0},
       "recent samples diagnosed (physics) on a background thread when a channel is raised; 0 = no diagnosis"},
      {"scan_interval", [](S& s) { return &s.scan_interval; }, {.min = 50, .max = 1e7, .whole = true, .also = 0},
       "usable samples between looks of the diagnosis scan over the last diagnosis_window samples (it has half the stated false-alarm rate, the sequential detector the other half); 0 = no scan"},
  };
  return rows;
}

std::vector<FieldError> ServiceSettings::errors() const {
  std::vector<FieldError> e = monitor.errors();
  for (auto* rows : {&monitor_fields(), &fields()})
    for (FieldError& f : range_errors(*rows, *this)) e.push_back(std::move(f));
  return e;
}

template <class T>
void append_value(const T& v, std::string& out) {
  if constexpr (std::is_same_v<T, std::string>) {
    out += v;
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    for (double x : v) append_value(x, out);
  } else {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", static_cast<double>(v));  // exact for every double
    out += text;
  }
  out += ' ';
}

template <class Settings>
void append_values(const std::vector<FieldRow<Settings>>& rows, const Settings& s, std::string& out) {
  for (const FieldRow<Settings>& row : rows) {
    out += row.key;
    out += '=';
    std::visit([&](auto* p) { append_value(*p, out); }, row.get(s));
  }
}
template void append_values(const std::vector<FieldRow<S>>&, const S&, std::string&);

}  // namespace mpm::config
