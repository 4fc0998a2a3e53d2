#include "core/monitor_settings.hpp"

namespace mpm {

const std::vector<FieldRow<MonitorSettings>>& MonitorSettings::fields() {
  using S = MonitorSettings;
  static const std::vector<FieldRow<S>> rows = [] {
    std::vector<FieldRow<S>> r = {
        {"ar_order", [](S& s) { return &s.ar_order; }, {.min = 0, .max = 200, .whole = true}, "residual lags na"},
        {"input_order", [](S& s) { return &s.input_order; }, {.min = 1, .max = 200, .whole = true},
         "input lags nb (cover the longest dead time)"},
        {"forgetting", [](S& s) { return &s.forgetting; }, {.min = 0.9, .max = 1.0, .min_open = true},
         "RLS forgetting factor: memory of about 1/(1-forgetting) samples"},
        {"false_alarm", [](S& s) { return &s.false_alarm; }, {.min = 0.0, .max = 0.5, .min_open = true, .max_open = true},
         "level alpha of the end-of-record test, per channel and test"},
        {"outlier_limit", [](S& s) { return &s.outlier_limit; }, {.min = 3.0, .max = 1e6, .also = 0.0},
         "skip a residual jump beyond this many robust std devs (0 = never)"},
        {"warmup", [](S& s) { return &s.warmup; }, {.min = 0, .max = 1e9, .whole = true},
         "samples before any test (0 = 10 x regressors)"},
        {"gamma_lambda", [](S& s) { return &s.gamma_lambda; }, {.min = 0.0, .max = 1e9, .min_open = true},
         "the paper's lambda: gamma < lambda^2 locates"},
        {"input_pole", [](S& s) { return &s.input_pole; }, {.min = 0.0, .max = 0.99, .max_open = true},
         "Laguerre pole of the input basis (0 = plain lags)"},
    };
    for (auto& row : lift(DetectorSettings::fields(), &S::detector,
                          {"false_alarms_per_year", "sample_time", "crossing_constant", "detector_thresholds"}))
      r.push_back(std::move(row));
    return r;
  }();
  return rows;
}

std::vector<FieldError> MonitorSettings::errors() const {
  std::vector<FieldError> e = range_errors(fields(), *this);  // the detector's rows: below
  for (FieldError& f : detector.errors()) e.push_back(std::move(f));
  return e;
}

}  // namespace mpm
