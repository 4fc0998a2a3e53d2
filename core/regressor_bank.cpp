#include "core/regressor_bank.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm {

RegressorBank::RegressorBank(std::size_t n_inputs, std::size_t n_outputs, std::size_t na, std::size_t nb,
                             double input_pole, const std::vector<std::optional<DiscreteTf>>& channel_models,
                             std::size_t first_output, std::size_t end_output)
    : n_inputs_(n_inputs),
      n_outputs_(n_outputs),
      na_(na),
      nb_(nb),
      first_output_(first_output),
      end_output_(end_output),
      pole_(input_pole) {
  input_lags_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(n_outputs * n_inputs));
  channel_filters_.resize(n_outputs * n_inputs);
  if (!channel_models.empty() && channel_models.size() != n_outputs * n_inputs)
    throw std::invalid_argument("channel models: need n_outputs * n_inputs entries");
  int filter_settle = 0;  // samples for the model filters to settle
  for (std::size_t c = 0; c < channel_models.size(); ++c) {
    if (!channel_models[c] || channel_models[c]->is_zero()) continue;
    DiscreteTf tf = *channel_models[c];
    tf.normalise();
    std::size_t lead = 0;  // leading zero coefficients are delay
    while (lead + 1 < tf.num.size() && tf.num[lead] == 0.0) ++lead;
    tf.num.erase(tf.num.begin(), tf.num.begin() + static_cast<long>(lead));
    tf.delay += static_cast<int>(lead);
    if (tf.delay > 0) --tf.delay;  // stepping with u(k) gives G u at k+1
    if (!tf.is_stable()) continue;  // an integrating model channel would drift: plain lags
    channel_filters_[c].emplace(tf);
    // The filter starts at rest after a (re)start: wait for its memory too.
    double slowest = 0.0;
    for (double mag : root_magnitudes(tf.den)) slowest = std::max(slowest, mag);
    int settle = tf.delay + static_cast<int>(tf.num.size());
    if (slowest > 0.0) settle += static_cast<int>(std::ceil(std::log(0.01) / std::log(slowest)));
    filter_settle = std::max(filter_settle, std::min(settle, 2000));
  }
  // After a start or a gap, the residual lags need na samples; the Laguerre
  // states need nb samples and then until the pre-gap memory (zeroed) has
  // decayed to 1 %; model filters likewise.
  lags_needed_ = static_cast<int>(std::max(na_, nb_)) + filter_settle;
  if (input_pole > 0.0)
    lags_needed_ = std::max(lags_needed_, static_cast<int>(nb_) + static_cast<int>(std::ceil(std::log(0.01) / std::log(input_pole))));
  lags_first_ = lags_wait_ = lags_needed_;
  residual_lags_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(na_), static_cast<Eigen::Index>(n_outputs));
  input_ref_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs));
}

void RegressorBank::gap() noexcept {
  lags_filled_ = 0;
  lags_wait_ = lags_needed_;
  input_lags_.setZero();
  for (auto& f : channel_filters_)
    if (f) f->reset(0.0);
}

void RegressorBank::start_at(const double* u) noexcept {
  if (lags_filled_ != 0) return;
  for (std::size_t i = 0; i < n_inputs_; ++i) input_ref_[static_cast<Eigen::Index>(i)] = u[i];
}

void RegressorBank::push(const double* u, const double* residual) noexcept {
  // Newest first: shift each output's column down by one, time k on top.
  if (na_ > 0)
    for (std::size_t j = 0; j < n_outputs_; ++j) {
      double* lags = residual_lags_.col(static_cast<Eigen::Index>(j)).data();
      std::copy_backward(lags, lags + na_ - 1, lags + na_);
      lags[0] = residual[j];
    }
  // Laguerre network, one column per input: x_1 <- a x_1 + sqrt(1-a^2) u(k),
  // x_r <- a x_r + x_{r-1}(old) - a x_{r-1}(new). With a = 0: a shift register.
  const double a = pole_;
  const double gain = std::sqrt(1.0 - a * a);
  for (std::size_t c = first_output_ * n_inputs_; c < end_output_ * n_inputs_; ++c) {
    const std::size_t i = c % n_inputs_;
    double source = u[i] - input_ref_[static_cast<Eigen::Index>(i)];
    if (channel_filters_[c]) source = channel_filters_[c]->step(source);
    double* x = input_lags_.col(static_cast<Eigen::Index>(c)).data();
    if (a == 0.0) {  // plain lags (the default): a shift register
      std::copy_backward(x, x + nb_ - 1, x + nb_);
      x[0] = source;
      continue;
    }
    double prev_old = x[0];
    x[0] = a * x[0] + gain * source;
    for (std::size_t r = 1; r < nb_; ++r) {
      const double old = x[r];
      x[r] = a * x[r] + prev_old - a * x[r - 1];
      prev_old = old;
    }
  }
  if (lags_filled_ < 1 << 30) ++lags_filled_;
}

void RegressorBank::reset() noexcept {
  residual_lags_.setZero();
  input_lags_.setZero();
  for (auto& f : channel_filters_)
    if (f) f->reset(0.0);
  lags_filled_ = 0;
  lags_wait_ = lags_first_;
}

void RegressorBank::reset_output(std::size_t j) noexcept { residual_lags_.col(static_cast<Eigen::Index>(j)).setZero(); }

void RegressorBank::adopt_output(const RegressorBank& part, std::size_t j) {
  residual_lags_.col(static_cast<Eigen::Index>(j)) = part.residual_lags_.col(static_cast<Eigen::Index>(j));
  for (std::size_t i = 0; i < n_inputs_; ++i) {
    const std::size_t c = j * n_inputs_ + i;
    input_lags_.col(static_cast<Eigen::Index>(c)) = part.input_lags_.col(static_cast<Eigen::Index>(c));
    channel_filters_[c] = part.channel_filters_[c];
  }
}

void RegressorBank::adopt_shared(const RegressorBank& part) {
  lags_filled_ = part.lags_filled_;
  lags_wait_ = part.lags_wait_;
  input_ref_ = part.input_ref_;
}

}  // namespace mpm
