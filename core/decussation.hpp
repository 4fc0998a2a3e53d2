// OVERVIEW
// "Decussation" location of model-plant mismatch (Li et al.), the method the
// Granger-causality paper compares itself against (Chen, Xie & Su, Processes
// 2021, Sec. 2.3 and Tables 4-6). It is an offline, batch baseline: it
// allocates freely and is not meant for the per-sample path.
//
// The paper only sketches the method, so this is a well-posed reading of it:
//
// Input signals. `u` (samples x inputs) and the IMC model residual
//   d~ = y - G_M u   (samples x outputs),
// e.g. what ResidualGenerator produces. The nominal model G_M is used only to
// form d~; absolute units are fine (every regression has an intercept and
// every variance/correlation removes the mean).
//
// 1. Innovations by orthogonal projection. The paper projects y onto the
//    orthogonal complement of the past data Z(k) = [Y(k-1..); U(k-1..)]:
//      a_bar(k) = d~(k) - proj(d~(k) | 1, d~(k-1..k-p), u(k-1..k-p)),
//    one least-squares fit over the whole batch, all outputs at once. We use
//    past residuals instead of past outputs: d~ - y = -G_M u is a causal
//    function of past inputs (strictly proper G_M), so both spans give the
//    same innovation as p grows, and d~ is what MQI compares against. With a
//    monic, minimum-phase N the innovation of d~ is the white noise a itself,
//    whether or not the model is mismatched and in open or closed loop. The
//    residual is rescaled by sqrt(rows / (rows - rank)) so its variance is
//    unbiased.
// 2. Whitened residual  a~_j = N_j^-1 d~_j  (N_j scaled to be monic,
//    num[0] = 1, since the projection's innovation already carries num[0]).
//    With no mismatch a~_j = a_j; with one, a~_j = N_j^-1 Delta G_j u + a_j.
// 3. MQI_j = var(a_bar_j) / var(a~_j): the smallest one-step-ahead variance
//    the data allow (the innovation) over the variance the residual's own
//    whitening leaves. N_j^-1 Delta G_j u(k) is a function of data up to
//    k-1 only (Delta G strictly proper), so it is uncorrelated with a_j(k)
//    even in closed loop, and MQI_j = var(a)/(var(a) + var(N^-1 Delta G u))
//    <= 1: ~1 with row j of G right, below 1 with a mismatch in row j.
//    MQI_j < mqi_threshold flags OUTPUT j (row j of G).
//    Why not var(N a_bar)/var(d~) (ideal over actual residual, the form of
//    "model residual assessment"): N's low-frequency gain multiplies the
//    O(1/sqrt(n)) error of the fitted AR part, which gave a +-10 % spread
//    around 1 with no mismatch on 4000 Wood-Berry samples, and its cross
//    term with Delta G u can be negative in closed loop. The ratio of white
//    signals is tight (the fit's residual and a~ differ by O(p/n)).
// 4. CAID(u_i, ds_j): correlation between input i and the part of the
//    residual the estimated disturbance d_bar_j = N_j a_bar_j does not
//    explain, ds_j = d~_j - d_bar_j (~ Delta G_j u under mismatch). The
//    paper writes r(u, d_bar); correlating u with d_bar itself would
//    measure how the controller reacts to the disturbance (it is zero in
//    open loop whatever the mismatch), so we correlate with what is left
//    after removing it. Because Delta G is dynamic (dead time), the
//    correlation of u_i(k - tau) with ds_j(k) is taken for
//    tau = 0..caid_max_lag and the one of largest magnitude is reported,
//    with its sign and lag. |CAID| >= caid_threshold flags INPUT i
//    (column i of G) for output j.
// 5. Decussation: channel (output j, input i) is located when row j is
//    flagged by MQI and column i by CAID for that output.
//
// The paper's tables index CAID by input (CAID(u1, ds), CAID(u2, ds)) and
// MQI by output (MQI(1), MQI(2)), and read "MQI(1) with CAID(u2, ds)" as G12:
// hence MQI names the row and CAID the column here. Its reported values
// (e.g. CAID (0.7071, 0.4416) with no mismatch) come from its own MPC runs
// and are not reproduced by tests.
//
// Known weaknesses, kept on purpose since this is the baseline the paper
// beats: with no mismatch ds_j is tiny but still a filtered combination of
// past inputs (estimation error), so CAID alone is meaningless (it can be
// 0.5 on a correct model) and is only read through an MQI-flagged row; in
// closed loop the inputs are correlated through the controller, so CAID can
// point at the wrong column; and a mismatch the loop barely excites (little
// input variance through Delta G) leaves MQI near 1. Outputs whose N is
// unknown cannot be assessed: pass only outputs with a known disturbance
// model. A constant residual (zero variance) gives MQI = NaN, never flagged.
//
// Missing data: a row with a NaN/inf anywhere in u or d~ is dropped and the
// series is cut there; lags never reach across a cut. Each contiguous run
// contributes regression rows after its first p samples, and MQI/CAID
// samples after the N and N^-1 filters, started from rest in each run, have
// settled (their impulse-response tail beyond that point holds < 1e-4 of the
// energy) and after caid_max_lag samples.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/transfer_function.hpp"

namespace mpm {

struct DecussationSettings {
  int past_order = 10;          // p: lags of d~ and u in the projection, >= 1
  int caid_max_lag = 20;        // largest lag tau of u_i(k - tau) in CAID, >= 0
  double mqi_threshold = 0.95;  // MQI_j below this flags output j, in (0, 1]
  double caid_threshold = 0.3;  // |CAID| at or above this flags an input, in (0, 1)

  // Throws std::invalid_argument naming the field and its allowed range.
  void validate() const;
};

struct DecussationResult {
  Eigen::VectorXd mqi;         // per output
  Eigen::MatrixXd caid;        // outputs x inputs: signed peak correlation
  Eigen::MatrixXi caid_lag;    // outputs x inputs: lag tau of that peak
  Eigen::VectorXd innovation_variance;  // var(a_bar_j) (MQI's numerator)
  std::vector<bool> output_flagged;     // MQI_j < mqi_threshold
  // Located channels as (output, input), zero-based, row-major order.
  std::vector<std::pair<std::size_t, std::size_t>> located;
  bool mismatch = false;       // any output flagged
  std::size_t regression_rows = 0;  // rows in the projection fit
  std::size_t samples_used = 0;     // samples behind MQI and CAID
};

// u: samples x inputs; residual: samples x outputs (d~ = y - G_M u);
// noise_models: N_j per output (delay 0, num[0] != 0, stable and minimum
// phase). Throws std::invalid_argument on mismatched sizes, invalid settings
// or noise models, or too few finite contiguous samples for the fit.
DecussationResult decussation(const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual,
                              const std::vector<DiscreteTf>& noise_models,
                              const DecussationSettings& settings = {});

}  // namespace mpm
