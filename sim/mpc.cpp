#include "sim/mpc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mpm::sim {
namespace {

using Index = Eigen::Index;

Index idx(std::size_t i) { return static_cast<Index>(i); }

void check_size(const std::vector<double>& v, std::size_t n, const char* name) {
  if (!v.empty() && v.size() != n)
    throw std::invalid_argument(std::string("MPC: ") + name + " needs " + std::to_string(n) + " values, got " +
                                std::to_string(v.size()));
}

double value_or(const std::vector<double>& v, std::size_t i, double fallback) {
  return v.empty() ? fallback : v[i];
}

}  // namespace

void MpcSettings::validate(std::size_t n_inputs, std::size_t n_outputs) const {
  if (prediction_horizon < 1) throw std::invalid_argument("MPC: prediction_horizon must be >= 1");
  if (control_horizon < 1 || control_horizon > prediction_horizon)
    throw std::invalid_argument("MPC: control_horizon must be in 1 .. prediction_horizon");
  check_size(output_weights, n_outputs, "output_weights");
  check_size(move_weights, n_inputs, "move_weights");
  check_size(input_lower, n_inputs, "input_lower");
  check_size(input_upper, n_inputs, "input_upper");
  for (double q : output_weights)
    if (!(q >= 0.0) || !std::isfinite(q)) throw std::invalid_argument("MPC: output_weights must be >= 0");
  for (double r : move_weights)
    if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("MPC: move_weights must be > 0");
  for (std::size_t l = 0; l < n_inputs; ++l) {
    const double lo = value_or(input_lower, l, -INFINITY), hi = value_or(input_upper, l, INFINITY);
    if (std::isnan(lo) || std::isnan(hi) || !(lo < hi))
      throw std::invalid_argument("MPC: input_lower must be below input_upper (input " + std::to_string(l + 1) + ")");
  }
  if (!(settle_tolerance > 0.0)) throw std::invalid_argument("MPC: settle_tolerance must be > 0");
  if (max_model_length < prediction_horizon + 2)
    throw std::invalid_argument("MPC: max_model_length must exceed the prediction horizon");
}

DmcController::DmcController(const PlantModel& model, const MpcSettings& s)
    : n_in_(model.n_inputs()), n_out_(model.n_outputs()), horizon_(s.prediction_horizon), moves_(s.control_horizon) {
  s.validate(n_in_, n_out_);
  if (n_in_ == 0 || n_out_ == 0) throw std::invalid_argument("MPC: the model needs inputs and outputs");
  steps_ = StepResponses(model, horizon_ + 2, s.settle_tolerance, s.max_model_length);
  build_gains(s);
  prediction_ = Eigen::MatrixXd::Zero(idx(steps_.length()), idx(n_out_));
  u_prev_ = Eigen::VectorXd::Zero(idx(n_in_));
  du_ = Eigen::VectorXd::Zero(idx(n_in_));
  bias_ = Eigen::VectorXd::Zero(idx(n_out_));
  error_ = Eigen::VectorXd::Zero(idx(horizon_ * n_out_));
  v_ = Eigen::VectorXd::Zero(idx(moves_ * n_in_));
  g_ = Eigen::VectorXd::Zero(idx(moves_ * n_in_));
}

// Decision variables v = (u(k), ..., u(k+M-1)); moves dU = D v - c with
// c = (u(k-1), 0, ...). Predictions Y = F + A dU over i = 1..P.
void DmcController::build_gains(const MpcSettings& s) {
  const Index n = idx(moves_ * n_in_), p = idx(horizon_ * n_out_), ni = idx(n_in_);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, n);
  for (std::size_t i = 1; i <= horizon_; ++i)
    for (std::size_t m = 0; m < moves_ && m <= i; ++m)
      for (std::size_t j = 0; j < n_out_; ++j)
        for (std::size_t l = 0; l < n_in_; ++l)
          a(idx((i - 1) * n_out_ + j), idx(m * n_in_ + l)) = steps_.at(j, l, i - m);
  Eigen::MatrixXd d = Eigen::MatrixXd::Identity(n, n);
  for (Index r = ni; r < n; ++r) d(r, r - ni) = -1.0;
  Eigen::VectorXd q(p), r(n);
  for (Index row = 0; row < p; ++row) q(row) = value_or(s.output_weights, static_cast<std::size_t>(row) % n_out_, 1.0);
  for (Index col = 0; col < n; ++col) r(col) = value_or(s.move_weights, static_cast<std::size_t>(col) % n_in_, 1.0);

  const Eigen::MatrixXd b = a * d;
  hessian_ = b.transpose() * q.asDiagonal() * b + d.transpose() * r.asDiagonal() * d;
  hessian_ = 0.5 * (hessian_ + hessian_.transpose());
  const Eigen::LLT<Eigen::MatrixXd> llt(hessian_);
  if (llt.info() != Eigen::Success) throw std::invalid_argument("MPC: the QP Hessian is not positive definite");
  gain_error_ = llt.solve(b.transpose() * q.asDiagonal());
  // H v = B'Q e + D'R c and e = r - F + A0 u(k-1): fold both u(k-1) terms.
  Eigen::MatrixXd r_first = Eigen::MatrixXd::Zero(n, ni);
  r_first.topRows(ni) = r.head(ni).asDiagonal();
  gain_input_ = llt.solve(r_first) + gain_error_ * a.leftCols(ni);

  lower_.resize(n);
  upper_.resize(n);
  for (Index k = 0; k < n; ++k) {
    const std::size_t l = static_cast<std::size_t>(k) % n_in_;
    lower_(k) = value_or(s.input_lower, l, -std::numeric_limits<double>::infinity());
    upper_(k) = value_or(s.input_upper, l, std::numeric_limits<double>::infinity());
  }
  qp_ = BoxQp(hessian_);
}

void DmcController::step(const double* y, const double* r, double* u) noexcept {
  for (std::size_t j = 0; j < n_out_; ++j) bias_(idx(j)) = y[j] - prediction_(0, idx(j));
  for (std::size_t i = 1; i <= horizon_; ++i)
    for (std::size_t j = 0; j < n_out_; ++j)
      error_(idx((i - 1) * n_out_ + j)) = r[j] - prediction_(idx(i), idx(j)) - bias_(idx(j));
  v_.noalias() = gain_error_ * error_;
  v_.noalias() += gain_input_ * u_prev_;
  const bool inside = ((v_.array() >= lower_.array()) && (v_.array() <= upper_.array())).all();
  if (!inside) {
    ++constrained_;
    g_.noalias() = hessian_ * v_;  // v_ is the unconstrained optimum: H v = -g
    g_ = -g_;
    if (qp_.solve(g_, lower_, upper_, v_).gradient_iterations > 0) ++fallbacks_;
  }
  for (std::size_t l = 0; l < n_in_; ++l) {
    u[l] = v_(idx(l));
    du_(idx(l)) = u[l] - u_prev_(idx(l));
    u_prev_(idx(l)) = u[l];
  }
  shift_prediction(du_.data());
}

// prediction(k+1+i) = prediction(k+1+i | before) + S(i+1) du(k). Beyond the
// model length the free response is flat (every channel into the output has
// settled) or, with an integrating channel, a straight line.
void DmcController::shift_prediction(const double* du) noexcept {
  const std::size_t length = steps_.length();
  for (std::size_t j = 0; j < n_out_; ++j) {
    const Index jj = idx(j);
    const double last = prediction_(idx(length - 1), jj), before = prediction_(idx(length - 2), jj);
    for (std::size_t i = 0; i + 1 < length; ++i) {
      double value = prediction_(idx(i + 1), jj);
      for (std::size_t l = 0; l < n_in_; ++l) value += steps_.at(j, l, i + 1) * du[l];
      prediction_(idx(i), jj) = value;
    }
    double value = steps_.ramps(j) ? 2.0 * last - before : last;
    for (std::size_t l = 0; l < n_in_; ++l) value += steps_.at(j, l, length) * du[l];
    prediction_(idx(length - 1), jj) = value;
  }
}

void DmcController::reset() noexcept {
  prediction_.setZero();
  u_prev_.setZero();
  constrained_ = fallbacks_ = 0;
}

}  // namespace mpm::sim
