#include "core/monitor_settings.hpp"

#include <sstream>

namespace mpm {

std::string MonitorSettings::validate() const {
  std::ostringstream e;
  if (ar_order < 0 || ar_order > 200) e << "ar_order must be in [0, 200], got " << ar_order << "; ";
  if (input_order < 1 || input_order > 200) e << "input_order must be in [1, 200], got " << input_order << "; ";
  if (!(forgetting > 0.9 && forgetting <= 1.0)) e << "forgetting must be in (0.9, 1], got " << forgetting << "; ";
  if (!(false_alarm > 0.0 && false_alarm < 0.5)) e << "false_alarm must be in (0, 0.5), got " << false_alarm << "; ";
  if (!(outlier_limit == 0.0 || (outlier_limit >= 3.0 && outlier_limit <= 1e6)))
    e << "outlier_limit must be 0 (off) or in [3, 1e6], got " << outlier_limit << "; ";
  e << detector.validate();
  if (warmup < 0) e << "warmup must be >= 0, got " << warmup << "; ";
  if (!(input_pole >= 0.0 && input_pole < 0.99)) e << "input_pole must be in [0, 0.99), got " << input_pole << "; ";
  if (!(gamma_lambda > 0.0)) e << "gamma_lambda must be > 0, got " << gamma_lambda << "; ";
  std::string s = e.str();
  if (s.size() >= 2) s.resize(s.size() - 2);
  return s;
}

}  // namespace mpm
