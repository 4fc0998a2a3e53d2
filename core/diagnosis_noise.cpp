// The disturbance-model hypothesis: a changed noise model N of an output
// whose N the plant file gives. A candidate of every round, and tried once
// more after the search where no finding explains the output (diagnose()),
// there at its own family-wise level over the forms and outputs.
#include <cmath>
#include <optional>

#include "core/chi_square.hpp"
#include "core/diagnosis_table.hpp"

namespace mpm::diagnosis {

void fit_disturbance_model(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output;
  const Index n_fit = cx.seg.fit_samples();
  const OutputState& o = cx.out[j];
  // Corrections C = num / den of the whitened residual N^-1 d (the new
  // disturbance model is N / C): AR(1..3), and ARMA(1,1). A first-order N
  // whose pole moved leaves N^-1 d = (1 - p q^-1) / (1 - p' q^-1) a, a pole
  // and zero that nearly cancel: low-order AR fits take it up poorly, the
  // ARMA(1,1) exactly (den pole on a grid, num by least squares).
  std::vector<DiscreteTf> corrections;
  for (int k = 1; k <= 3; ++k) corrections.push_back(DiscreteTf{fit_ar(o.wd, cx.seg.fit, k), {1.0}, 0});
  const auto arma = [&](double b) {
    const Vec v = simulate(DiscreteTf{{1.0}, {1.0, -b}, 0}, o.wd);
    return DiscreteTf{fit_ar(v, cx.seg.fit, 1), {1.0, -b}, 0};
  };
  std::vector<double> poles;
  for (int k = -6; k <= 14; ++k) poles.push_back(k < 0 ? 0.15 * k : 1.0 - std::pow(0.7, k + 1));
  // The ARMA(1,1) residual is (1 - a q^-1) v with v = wd / (1 - b q^-1):
  // the search forms it from v, one filter pass per point.
  const double b = minimise_on_grid(poles, [&](double v) {
    const Vec filtered = simulate(DiscreteTf{{1.0}, {1.0, -v}, 0}, o.wd);
    const double a = -fit_ar(filtered, cx.seg.fit, 1)[1];
    Vec e(filtered.size());
    if (e.size()) e(0) = filtered(0);
    for (Index k = 1; k < e.size(); ++k) e(k) = filtered(k) - a * filtered(k - 1);
    return least_squares(e, {}, cx.seg, Part::fit).fit_var;
  });
  corrections.push_back(arma(b));
  // The evidence every candidate is held to (passes(): the fit-part and
  // held-out tests together or pooled, or the fit part alone where the
  // held-out part cannot speak), at the family of these forms over the
  // outputs; in the rounds the round's family applies on top.
  const double forms_family = static_cast<double>(corrections.size() * cx.n_out());
  std::optional<Candidate> best;
  DiscreteTf best_correction;
  for (const DiscreteTf& correction : corrections) {
    const int params = static_cast<int>(correction.den.size() > 1 ? 2 : correction.num.size() - 1);
    OutputFit of;
    of.output = j;
    of.correction = Vec::Zero(o.d.size());
    of.fit = least_squares(simulate(correction, o.wd), {}, cx.seg);
    std::vector<OutputFit> fits;
    fits.push_back(std::move(of));
    Candidate c = make_candidate(cx, h, {{j, std::nullopt}}, std::move(fits), params);
    // The ARMA(1,1) pole is searched; without a change it cancels the zero.
    c.unidentified = correction.den.size() > 1 ? 1 : 0;
    if (!passes(c, cx.settings, forms_family)) continue;
    if (!best || c.bic(std::log(static_cast<double>(n_fit))) > best->bic(std::log(static_cast<double>(n_fit)))) {
      best = std::move(c);
      best_correction = correction;
    }
  }
  if (!best) return;
  const DiscreteTf& nn = *cx.problem.noise[j];
  best->finding.nominal = nn;
  DiscreteTf fitted = nn;
  fitted.num = poly_mul(nn.num, best_correction.den);
  fitted.den = poly_mul(nn.den, best_correction.num);
  best->finding.fitted = fitted;
  best->finding.parameters["variance"] = best->fits[0].fit.fit_var;
  best->facts["variance_before"] = o.fit_var;
  best->facts["arma"] = best_correction.den.size() > 1 ? 1.0 : 0.0;
  best->whitener_change = best_correction;
  out.push_back(std::move(*best));
}

}  // namespace mpm::diagnosis
