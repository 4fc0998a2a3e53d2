// The nominal model G_M as a bank of channel filters, and the IMC residual
// d~ = y - G_M u that the monitor watches.
#pragma once

#include <cstddef>
#include <vector>

#include "core/plant_model.hpp"
#include "core/transfer_function.hpp"

namespace mpm {

// Steps every channel of a PlantModel on deviation inputs. Storage is sized in
// the constructor; step() is real-time safe.
class MimoModel {
 public:
  MimoModel() = default;
  explicit MimoModel(const PlantModel& plant);

  std::size_t n_inputs() const noexcept { return n_inputs_; }
  std::size_t n_outputs() const noexcept { return n_outputs_; }

  // u: n_inputs deviation inputs at time k; y: n_outputs model outputs at k.
  void step(const double* u, double* y) noexcept;
  // Back to rest at zero deviation.
  void reset() noexcept;
  // Calls v(member) for every member that changes after setup (checkpoint).
  template <class V>
  void visit_state(V&& v) {
    v(channels_);
  }

 private:
  struct Channel {
    std::size_t output;
    std::size_t input;
    DiscreteFilter filter;
    template <class V>
    void visit_state(V&& v) {
      v(filter);
    }
  };
  std::size_t n_inputs_ = 0;
  std::size_t n_outputs_ = 0;
  std::vector<Channel> channels_;
};

// Computes the IMC residual from absolute-unit samples: deviation inputs
// u - u0 go through G_M; the residual is y - G_M(u - u0) (the outputs' offset
// stays in it; the monitor's regression has an intercept for it).
class ResidualGenerator {
 public:
  ResidualGenerator() = default;
  ResidualGenerator(const PlantModel& plant, std::vector<double> input_operating_point);

  // u, y: absolute values at time k; residual: n_outputs values written.
  // A NaN in u makes the affected outputs' residuals NaN at k; the model
  // holds the last good input value for that input (zero-order hold).
  void step(const double* u, const double* y, double* residual) noexcept;
  // Sets u0 (n_inputs values) before the first step, when it is found in the
  // data (monitor_front_end.hpp). Real-time safe: sizes are kept.
  void set_origin(const double* u0) noexcept;
  // Calls v(member) for every member that changes after setup (checkpoint).
  template <class V>
  void visit_state(V&& v) {
    v(u0_); v(du_); v(y_model_); v(last_good_u_); v(model_);
  }

 private:
  MimoModel model_;
  std::vector<double> u0_;
  std::vector<double> du_;
  std::vector<double> y_model_;
  std::vector<double> last_good_u_;
};

}  // namespace mpm

namespace mpm {

// Samples after which every channel's response to past inputs has decayed to
// `fraction` of its initial size (slowest pole), plus the longest delay: how
// long the residual of a model started from rest carries a start-up
// transient. Integrating or unstable channels never settle: `cap` is returned.
std::size_t settling_samples(const PlantModel& plant, double fraction, std::size_t cap);

}  // namespace mpm

namespace mpm {

// A Laguerre pole for the monitor's input basis matched to the plant: the
// slowest stable real pole magnitude among the model's channels, capped at
// `cap` (0 when the model has only static or integrating channels).
double dominant_pole(const PlantModel& plant, double cap = 0.98);

}  // namespace mpm
