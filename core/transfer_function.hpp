// Single-input single-output linear channels: coefficients, zero-order-hold
// discretisation, and a stateful filter that steps one sample at a time.
//
// Conventions follow formats.md: discrete polynomials are in q^-1 with
// ascending powers (MATLAB filter()), continuous ones in s with the highest
// power first (MATLAB tf()).
#pragma once

#include <cstddef>
#include <vector>

namespace mpm {

// y(k) = q^-delay * num(q^-1)/den(q^-1) * u(k), den[0] == 1 after normalise().
struct DiscreteTf {
  std::vector<double> num{0.0};
  std::vector<double> den{1.0};
  int delay = 0;

  // Divides num and den by den[0]; trims trailing zeros. Throws
  // std::invalid_argument if den is empty or den[0] == 0.
  void normalise();
  bool is_zero() const;             // every num coefficient is 0
  double dc_gain() const;           // num(1)/den(1); +-inf for an integrator
  bool is_stable() const;           // all poles strictly inside the unit circle
  bool has_integrator() const;      // a pole at z = 1 (within 1e-9)
};

// G(s) e^{-dead_time s}; num/den highest power of s first.
struct ContinuousTf {
  std::vector<double> num{0.0};
  std::vector<double> den{1.0};
  double dead_time = 0.0;  // seconds, >= 0
};

// Exact zero-order-hold equivalent of a proper continuous channel at sample
// time ts, dead time included (its fractional part becomes an extra zero
// through the modified z-transform). Throws std::invalid_argument for an
// improper or empty transfer function, a negative dead time or ts <= 0.
DiscreteTf discretize_zoh(const ContinuousTf& g, double ts);

// Roots of a polynomial given in ascending powers of q^-1 as z-plane roots,
// i.e. roots of c0 z^n + c1 z^{n-1} + ... + cn.
std::vector<double> root_magnitudes(const std::vector<double>& ascending);

// Stateful direct-form filter for a DiscreteTf. All storage is sized in the
// constructor; step() is real-time safe (no allocation, no exceptions).
class DiscreteFilter {
 public:
  DiscreteFilter() = default;
  explicit DiscreteFilter(const DiscreteTf& tf);

  // Feeds u(k), returns y(k).
  double step(double u) noexcept;
  // Puts the filter at rest at the given constant input level (steady state
  // for a stable filter; zero output history for an integrating one).
  void reset(double u_rest = 0.0) noexcept;
  const DiscreteTf& tf() const noexcept { return tf_; }
  // Calls v(member) for every member that changes after setup (checkpoint).
  template <class V>
  void visit_state(V&& v) {
    v(u_hist_); v(y_hist_); v(u_head_); v(y_head_);
  }

 private:
  DiscreteTf tf_;
  std::vector<double> u_hist_;  // ring: u(k), u(k-1), ... u(k-delay-nb+1)
  std::vector<double> y_hist_;  // ring: y(k-1) ... y(k-na)
  std::size_t u_head_ = 0;
  std::size_t y_head_ = 0;
};

}  // namespace mpm
