#include "daemon/report_html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "config/json_text.hpp"
#include "config/text_escape.hpp"
#include "core/monitor_front_end.hpp"
#include "core/paper_plots.hpp"
#include "core/transfer_function.hpp"
#include "daemon/offline.hpp"

namespace mpm {
namespace {

using Vec = Eigen::VectorXd;
constexpr int kMaxLag = 30;        // correlation plots: lags shown
constexpr Eigen::Index kMaxPoints = 2000;  // time plots: points per series (strided)
constexpr int kPaperArOrder = 20;   // the paper's sweep: AR(d, 1..20)
constexpr int kPaperInputLags = 2;  // and R(u_i, 0..2)
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Numbers in the page's script and tables: JSON's (null where not finite).
std::string num(double v) { return config::json_number(v, 6); }

// prefix + n (built by append: GCC 12 warns falsely, -Wrestrict, on
// "literal" + std::to_string(n)).
std::string tag(const char* prefix, std::size_t n) {
  std::string s(prefix);
  s += std::to_string(n);
  return s;
}

// HTML text and attribute values.
std::string esc(const std::string& s) {
  static const config::EscapeTable table = [] {
    config::EscapeTable t;
    t['<'] = "&lt;";
    t['>'] = "&gt;";
    t['&'] = "&amp;";
    t['"'] = "&quot;";
    return t;
  }();
  return config::escaped(s, table);
}

// A JavaScript string literal (also safe inside <script>: no "</"); control
// characters become spaces.
std::string js_string(const std::string& s) {
  static const config::EscapeTable table = [] {
    config::EscapeTable t;
    for (std::size_t c = 0; c < 0x20; ++c) t[c] = " ";
    t['"'] = "\\\"";
    t['\\'] = "\\\\";
    t['<'] = "\\u003c";
    return t;
  }();
  std::string o = "\"";  // appended to: see tag()
  o += config::escaped(s, table);
  o += '"';
  return o;
}

// G u from rest, u a deviation series.
Vec simulate(const DiscreteTf& tf, const Vec& u) {
  DiscreteFilter f(tf);
  Vec y(u.size());
  for (Eigen::Index k = 0; k < u.size(); ++k) y(k) = f.step(u(k));
  return y;
}

Vec prediction(const PlantModel& p, const Eigen::MatrixXd& du, std::size_t j) {
  Vec y = Vec::Zero(du.rows());
  for (const ChannelModel& c : p.channels)
    if (c.output == j && !c.tf.is_zero()) y += simulate(c.tf, du.col(static_cast<Eigen::Index>(c.input)));
  return y;
}

double finite_mean(const Vec& x) {
  double s = 0.0;
  std::size_t n = 0;
  for (double v : x)
    if (std::isfinite(v)) s += v, ++n;
  return n ? s / static_cast<double>(n) : 0.0;
}

// Normalised correlation of a and b (means removed, finite pairs) at lags
// 0..max_lag of b behind a when `both_sides` is false, -max..max otherwise.
std::vector<double> correlation(const Vec& a, const Vec& b, int max_lag, bool both_sides) {
  const double ma = finite_mean(a), mb = finite_mean(b);
  double saa = 0.0, sbb = 0.0;
  for (Eigen::Index k = 0; k < a.size(); ++k)
    if (std::isfinite(a(k)) && std::isfinite(b(k))) saa += (a(k) - ma) * (a(k) - ma), sbb += (b(k) - mb) * (b(k) - mb);
  std::vector<double> r;
  const double norm = std::sqrt(saa * sbb);
  for (int lag = both_sides ? -max_lag : 0; lag <= max_lag; ++lag) {
    double s = 0.0;
    for (Eigen::Index k = std::max<Eigen::Index>(0, lag); k < a.size() && k - lag < b.size(); ++k) {
      const double x = a(k), y = b(k - lag);
      if (std::isfinite(x) && std::isfinite(y)) s += (x - ma) * (y - mb);
    }
    r.push_back(norm > 0.0 ? s / norm : std::nan(""));
  }
  return r;
}

std::size_t finite_count(const Vec& x) {
  return static_cast<std::size_t>(std::count_if(x.begin(), x.end(), [](double v) { return std::isfinite(v); }));
}

// Samples until the slowest stable pole has settled (5 time constants), plus the delay.
int step_horizon(const DiscreteTf& a, const DiscreteTf& b) {
  double slow = 0.0;
  for (const DiscreteTf* t : {&a, &b})
    for (double m : root_magnitudes(t->den)) slow = std::max(slow, m);
  const double tau = slow >= 1.0 - 1e-9 ? 60.0 : slow > 0.0 ? -1.0 / std::log(slow) : 1.0;
  return std::clamp(static_cast<int>(5.0 * tau) + std::max(a.delay, b.delay) + 5, 30, 600);
}

std::vector<double> step(const DiscreteTf& tf, int n) {
  DiscreteFilter f(tf);
  std::vector<double> y;
  for (int k = 0; k < n; ++k) y.push_back(f.step(1.0));
  return y;
}

// One dygraphs plot: rows of [x, series...] and its options.
struct Plot {
  std::string id, title, xlabel;
  std::vector<std::string> labels;  // series names (x excluded)
  std::vector<std::vector<double>> rows;
  std::string options;  // extra dygraphs options (JS object body)
};

std::string plot_js(const Plot& p) {
  std::ostringstream o;
  o << "{id:" << js_string(p.id) << ",title:" << js_string(p.title) << ",xlabel:" << js_string(p.xlabel)
    << ",labels:[" << js_string(p.xlabel);
  for (const auto& l : p.labels) o << "," << js_string(l);
  o << "],opts:{" << p.options << "},rows:[";
  for (std::size_t r = 0; r < p.rows.size(); ++r) {
    o << (r ? "," : "") << "[";
    for (std::size_t c = 0; c < p.rows[r].size(); ++c) o << (c ? "," : "") << num(p.rows[r][c]);
    o << "]";
  }
  o << "]}";
  return o.str();
}

std::string read_script(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot read the dygraphs script " + path +
                                   " for the HTML report (install libjs-dygraphs, or set MPM_DYGRAPHS_JS)");
  std::stringstream s;
  s << f.rdbuf();
  std::string js = s.str();
  // Inlined in <script>: a literal "</script" inside would end the element.
  for (std::size_t at = js.find("</script"); at != std::string::npos; at = js.find("</script", at))
    js.replace(at, 2, "<\\/");
  return js;
}

struct OutputSeries {
  Vec y, nominal, corrected, before, after;  // over the analysed samples
  double fit_before = 0.0, fit_after = 0.0;    // simulation (from the inputs alone)
  double fit1_before = std::nan(""), fit1_after = std::nan("");  // one step ahead, through N
};

// One-step-ahead prediction error of the output given the residual r and the
// disturbance model N: N^-1 r (missing samples taken as the mean).
Vec innovation(const Vec& r, const NoiseModel& n) {
  DiscreteTf inverse{n.tf.den, n.tf.num, 0};
  inverse.normalise();
  const double m = finite_mean(r);
  Vec x(r.size());
  for (Eigen::Index k = 0; k < r.size(); ++k) x(k) = std::isfinite(r(k)) ? r(k) - m : 0.0;
  return simulate(inverse, x);
}

OutputSeries output_series(const ReportInputs& in, std::size_t j) {
  const auto& pb = in.problem;
  const Eigen::Index b = static_cast<Eigen::Index>(pb.begin), n = pb.du.rows() - b;
  const Vec nom_all = prediction(in.plant, pb.du, j), corr_all = prediction(in.corrected.plant, pb.du, j);
  OutputSeries s;
  const Vec res = pb.residual.col(static_cast<Eigen::Index>(j)).segment(b, n);
  s.nominal = nom_all.segment(b, n);
  s.corrected = corr_all.segment(b, n);
  s.before = res;
  s.after = res - (s.corrected - s.nominal);
  const double ob = finite_mean(s.before), oa = finite_mean(s.after);
  s.y = res + s.nominal;  // the recording, in deviation units with the output's offset
  s.fit_before = fit_percent(s.y, s.before);
  s.fit_after = fit_percent(s.y, s.after);
  if (in.plant.noise[j] && in.corrected.plant.noise[j]) {
    s.fit1_before = fit_percent(s.y, innovation(s.before, *in.plant.noise[j]));
    s.fit1_after = fit_percent(s.y, innovation(s.after, *in.corrected.plant.noise[j]));
  }
  s.y.array() -= ob;
  s.corrected.array() += oa - ob;
  s.before.array() -= ob;
  s.after.array() -= oa;
  return s;
}

std::string arrow(const ReportInputs& in, const diagnosis::Finding& f) {
  std::string o;
  for (std::size_t c = 0; c < f.channels.size(); ++c) {
    const auto& ch = f.channels[c];
    o += (c ? ", " : "") + (ch.input ? in.plant.inputs[*ch.input] + " \u2192 " : std::string()) +
         in.plant.outputs[ch.output];
  }
  return o;
}

// Outputs whose loop has a mismatch, as the JSON's loops[].mismatch: the
// monitor located it (a channel named, or the loop's joint test rejecting)
// or a finding names it.
std::vector<std::size_t> located_loops(const ReportInputs& in) {
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < in.plant.n_outputs(); ++j) {
    bool located = j < in.verdict.loop_mismatch.size() && in.verdict.loop_mismatch[j];
    for (const auto& [o, i] : in.verdict.located) located = located || o == j;
    for (const auto& f : in.result.findings)
      for (const auto& c : f.channels) located = located || c.output == j;
    if (located) out.push_back(j);
  }
  return out;
}

// The paper's location plots for each located loop (core/paper_plots.hpp).
void paper_section(const ReportInputs& in, std::vector<Plot>& plots, std::ostringstream& body) {
  const PlantModel& p = in.plant;
  body << "<section id=paper><h2>The paper's location plots, per located loop</h2>\n<p>As Chen, Xie &amp; Su "
          "(2021) plot them, from batch least squares on the residual with plain lags: the residual variance "
          "of <i>d\u0303</i> regressed on its own " << kPaperArOrder << " lags or fewer and on 0, 1 or 2 lags of one "
          "input (their \u201cR(u,nb), AR(d,1\u2013" << kPaperArOrder << ")\u201d curves: where that input does not "
          "cause the residual, its curves lie on the AR-only one); and the AR part fitted beside each input's "
          "lags against the coefficients of 1 \u2212 N\u207b\u00b9 (on the channel that carries the mismatch they "
          "match; elsewhere the AR part over-fits: \u03b3 measures the distance).</p>\n";
  const std::vector<std::size_t> loops = located_loops(in);
  if (loops.empty()) body << "<p>No loop located.</p>\n";
  const auto b = static_cast<Eigen::Index>(in.problem.begin), n = in.problem.du.rows() - b;
  const auto noise = noise_ar(p, kPaperArOrder);
  for (std::size_t j : loops) {
    const OrderSweep w = order_sweep(in.problem.residual.col(static_cast<Eigen::Index>(j)).segment(b, n),
                                     in.problem.du.middleRows(b, n), kPaperArOrder, kPaperInputLags);
    body << "<h3>" << esc(p.outputs[j]) << " (" << w.used << " samples fitted)</h3>\n";
    for (std::size_t i = 0; i < p.n_inputs(); ++i) {
      Plot v{tag("v", j) + tag("_", i), p.outputs[j] + ": residual variance against AR order, " + p.inputs[i],
             "AR order na", {}, {}, "colors:['#444','#1f77b4','#d62728'],drawPoints:true,digitsAfterDecimal:4"};
      for (int nb = 0; nb <= kPaperInputLags; ++nb) v.labels.push_back("R(" + p.inputs[i] + "," + std::to_string(nb) + ")");
      for (std::size_t na = 1; na <= std::size_t{kPaperArOrder}; ++na) {
        std::vector<double> row{double(na)};
        for (std::size_t nb = 0; nb <= std::size_t{kPaperInputLags}; ++nb) row.push_back(w.variance[i][nb][na - 1]);
        v.rows.push_back(std::move(row));
      }
      body << "<div class='plot small' id=" << v.id << "></div>\n";
      plots.push_back(std::move(v));
    }
    Plot g{tag("g", j), p.outputs[j] + ": AR coefficients beside each input's " + tag("", kPaperInputLags) +
                            " lags against 1 \u2212 N\u207b\u00b9",
           "coefficient (lag)", {}, {}, "drawPoints:true"};
    g.labels.push_back("1 \u2212 N\u207b\u00b9");
    for (std::size_t i = 0; i < p.n_inputs(); ++i)
      g.labels.push_back("beside " + p.inputs[i] + " (\u03b3 " + num(in.monitor.channel(j, i).gamma) + ")");
    g.options += ",series:{" + js_string(g.labels[0]) + ":{strokePattern:[6,3],strokeWidth:2.5,color:'#000'}}";
    for (int l = 0; l < kPaperArOrder; ++l) {
      std::vector<double> row{double(l + 1), noise[j] ? (*noise[j])[static_cast<std::size_t>(l)] : kNaN};
      for (std::size_t i = 0; i < p.n_inputs(); ++i) row.push_back(w.ar[i][static_cast<std::size_t>(l)]);
      g.rows.push_back(std::move(row));
    }
    body << "<div class=plot id=" << g.id << "></div>\n";
    plots.push_back(std::move(g));
  }
  body << "</section>\n";
}

// The live detector's statistic over the record (DetectorTrace).
void detector_section(const ReportInputs& in, std::vector<Plot>& plots, std::ostringstream& body) {
  if (!in.trace) return;
  const DetectorTrace& tr = *in.trace;
  body << "<section id=detector><h2>The live detector's statistic over the record</h2>\n<p>What mpmd and "
          "<code>mpm monitor</code> compute on these samples: per output, the sequential detector's score "
          "statistic T<sub>W</sub> over its threshold h<sub>W</sub> (the largest over its windows W; the "
          "output is raised when it crosses 1), for the test of all inputs' lags and for the focused test of "
          "each input's gain direction; the largest over every " << tr.stride() << " samples. Log scale.</p>\n";
  for (std::size_t j = 0; j < in.plant.n_outputs(); ++j) {
    Plot t{tag("t", j), in.plant.outputs[j] + ": detector statistic T_W / h_W", "t [s]",
           {"all inputs", "focused", "threshold"}, {},
           "colors:['#1f77b4','#ff7f0e','#d62728'],logscale:true,series:{'threshold':{strokePattern:[6,3]}}"};
    for (std::size_t bin = 0; bin < tr.bins(); ++bin) {
      const double a = tr.all(j, bin), f = tr.focused(j, bin);
      if (!std::isfinite(a) && !std::isfinite(f)) continue;
      t.rows.push_back({static_cast<double>(bin * tr.stride()) * in.problem.sample_time, a, f, 1.0});
    }
    if (t.rows.empty()) continue;
    body << "<div class=plot id=" << t.id << "></div>\n";
    plots.push_back(std::move(t));
  }
  body << "</section>\n";
}

}  // namespace

DetectorTrace::DetectorTrace(std::size_t outputs, std::size_t samples, std::size_t points)
    : stride_(std::max<std::size_t>(1, (samples + std::max<std::size_t>(points, 1) - 1) / std::max<std::size_t>(points, 1))),
      bins_((samples + stride_ - 1) / stride_),
      all_(outputs, std::vector<double>(bins_, kNaN)),
      focused_(outputs, std::vector<double>(bins_, kNaN)) {}

PartSampleCallback DetectorTrace::callback() {
  return [this](std::size_t k, const GrangerMonitor& m) {
    const std::size_t bin = k / stride_;
    if (bin >= bins_) return;
    for (std::size_t j = m.first_modelled_output(); j < m.end_modelled_output() && j < all_.size(); ++j) {
      // 0: no look yet (left NaN); NaN never compares, so the first look wins.
      if (const double a = detector_evidence(m.detector(), j); a > 0.0 && !(a <= all_[j][bin])) all_[j][bin] = a;
      if (const double f = detector_evidence(m.focused_detector(), j); f > 0.0 && !(f <= focused_[j][bin]))
        focused_[j][bin] = f;
    }
  };
}

std::string dygraphs_path() {
  if (const char* e = std::getenv("MPM_DYGRAPHS_JS"); e && *e) return e;
  return "/usr/share/javascript/dygraphs/dygraph.min.js";
}

double fit_percent(const Vec& y, const Vec& e) {
  const double my = finite_mean(y), me = finite_mean(e);
  double se = 0.0, sy = 0.0;
  std::size_t n = 0;
  for (Eigen::Index k = 0; k < y.size(); ++k)
    if (std::isfinite(y(k)) && std::isfinite(e(k))) se += (e(k) - me) * (e(k) - me), sy += (y(k) - my) * (y(k) - my), ++n;
  if (n == 0 || sy <= 0.0) return std::nan("");
  return 100.0 * (1.0 - std::sqrt(se / sy));
}

std::string report_html(const ReportInputs& in) {
  const std::string dygraphs = read_script(dygraphs_path());
  // Its style sheet (legend layout) sits beside it; the page works without.
  std::string css;
  if (std::string c = dygraphs_path(); c.size() > 3 && c.compare(c.size() - 3, 3, ".js") == 0) {
    std::ifstream f(c.replace(c.size() - 3, 3, ".css"));
    std::stringstream s;
    s << f.rdbuf();
    css = s.str();
  }
  const PlantModel& p = in.plant;
  const double ts = in.problem.sample_time;
  std::vector<Plot> plots;
  std::ostringstream body;

  // Summary and findings.
  body << "<h1>mpm diagnosis: " << esc(p.name) << "</h1>\n<p class=meta>plant <code>" << esc(in.plant_path)
       << "</code>, recording <code>" << esc(in.data_path) << "</code>, " << in.problem.du.rows()
       << " samples (the first " << in.problem.begin << " skipped as start-up transient), sample time " << num(ts)
       << " s; false-alarm level " << num(in.settings.alpha) << " per look (a record without mismatch gets a finding "
       << "with probability at most " << num(healthy_finding_bound(in.settings.alpha))
       << "); hypotheses judged on the held-out blocks of phase " << in.settings.holdout_phase
       << ".</p>\n<section id=findings><h2>Findings</h2>\n";
  if (in.result.findings.empty()) body << "<p>No mismatch found.</p>\n";
  else {
    body << "<table><tr><th>#</th><th>channels</th><th>physics</th><th>what was found</th>"
            "<th>held-out variance before \u2192 after</th><th>written to the plant file</th></tr>\n";
    for (std::size_t k = 0; k < in.result.findings.size(); ++k) {
      const auto& f = in.result.findings[k];
      const Written written = k < in.corrected.written.size() ? in.corrected.written[k] : Written::kNotExpressible;
      body << "<tr><td>" << k + 1 << "</td><td>" << esc(arrow(in, f)) << "</td><td><b>" << esc(f.physics) << "</b>";
      for (std::size_t a = 0; a < f.alternatives.size(); ++a) body << (a ? ", " : " (or ") << esc(f.alternatives[a]);
      body << (f.alternatives.empty() ? "" : ")") << "</td><td>" << esc(f.summary) << "</td><td>"
           << num(f.fit.holdout_variance_before) << " \u2192 "
           << num(f.fit.holdout_variance_after) << "</td><td>"
           << (written == Written::kApplied ? "yes"
               : written == Written::kImplausible ? "no (implausible)" : "no (not expressible)")
           << "</td></tr>\n";
    }
    body << "</table>\n";
  }
  for (const auto& note : in.result.notes) body << "<p class=note>" << esc(note) << "</p>\n";
  body << "</section>\n";

  // Fit % per output.
  std::vector<OutputSeries> series;
  for (std::size_t j = 0; j < p.n_outputs(); ++j) series.push_back(output_series(in, j));
  body << "<section id=fit><h2>Fit % (NRMSE, as MATLAB compare) before and after</h2>\n"
          "<p>100 (1 \u2212 |y \u2212 \u0177| / |y \u2212 mean y|) over the analysed samples, offsets removed: "
          "<b>simulation</b>, the model's prediction from the recorded inputs alone (under feedback with "
          "coloured disturbances it can be negative: the disturbances are most of y); <b>one step ahead</b>, "
          "the prediction through the disturbance model N (where the plant file gives it). The corrected "
          "model applies only the corrections the plant file can express.</p>\n<table><tr><th>output</th>"
          "<th>simulation, nominal</th><th>simulation, corrected</th><th>one step, nominal</th>"
          "<th>one step, corrected</th></tr>\n";
  for (std::size_t j = 0; j < p.n_outputs(); ++j)
    body << "<tr><td>" << esc(p.outputs[j]) << "</td><td class=fitb>" << num(series[j].fit_before)
         << "</td><td class=fita>" << num(series[j].fit_after) << "</td><td class=fit1b>"
         << num(series[j].fit1_before) << "</td><td class=fit1a>" << num(series[j].fit1_after) << "</td></tr>\n";
  body << "</table></section>\n";

  // Time plots, residual autocorrelations and cross-correlations.
  body << "<section id=time><h2>Recording against the nominal and the corrected model</h2>\n";
  for (std::size_t j = 0; j < p.n_outputs(); ++j) {
    const OutputSeries& s = series[j];
    const Eigen::Index n = s.y.size(), stride = std::max<Eigen::Index>(1, (n + kMaxPoints - 1) / kMaxPoints);
    Plot y{tag("y", j), p.outputs[j] + ": recording vs models", "t [s]",
           {"recording", "nominal model", "corrected model"}, {}, "colors:['#444','#d62728','#2ca02c']"};
    Plot r{tag("r", j), p.outputs[j] + ": residual before and after", "t [s]",
           {"before (nominal)", "after (corrected)"}, {}, "colors:['#d62728','#2ca02c']"};
    for (Eigen::Index k = 0; k < n; k += stride) {
      const double t = static_cast<double>(k + static_cast<Eigen::Index>(in.problem.begin)) * ts;
      y.rows.push_back({t, s.y(k), s.nominal(k), s.corrected(k)});
      r.rows.push_back({t, s.before(k), s.after(k)});
    }
    body << "<div class=plot id=" << y.id << "></div><div class=plot id=" << r.id << "></div>\n";
    plots.push_back(std::move(y));
    plots.push_back(std::move(r));
  }
  body << "</section>\n<section id=residuals><h2>Residual autocorrelation (95 % bounds of white noise)</h2>\n";
  for (std::size_t j = 0; j < p.n_outputs(); ++j) {
    const OutputSeries& s = series[j];
    const auto rb = correlation(s.before, s.before, kMaxLag, false), ra = correlation(s.after, s.after, kMaxLag, false);
    const double bound = 1.96 / std::sqrt(static_cast<double>(std::max<std::size_t>(1, finite_count(s.before))));
    Plot a{tag("a", j), p.outputs[j] + ": residual autocorrelation", "lag [samples]",
           {"before", "after", "+bound", "-bound"}, {},
           "colors:['#d62728','#2ca02c','#888','#888'],drawPoints:true,series:{'+bound':{strokePattern:[4,4],"
           "drawPoints:false},'-bound':{strokePattern:[4,4],drawPoints:false}}"};
    for (std::size_t l = 0; l <= std::size_t{kMaxLag}; ++l) a.rows.push_back({double(l), rb[l], ra[l], bound, -bound});
    body << "<div class=plot id=" << a.id << "></div>\n";
    plots.push_back(std::move(a));
  }
  body << "</section>\n<section id=xcorr><h2>Cross-correlation of the residual with each input (95 % bounds)</h2>\n";
  for (std::size_t j = 0; j < p.n_outputs(); ++j)
    for (std::size_t i = 0; i < p.n_inputs(); ++i) {
      const OutputSeries& s = series[j];
      const Vec u = in.problem.du.col(static_cast<Eigen::Index>(i)).segment(
          static_cast<Eigen::Index>(in.problem.begin), s.before.size());
      const auto xb = correlation(s.before, u, kMaxLag, true), xa = correlation(s.after, u, kMaxLag, true);
      const double bound = 1.96 / std::sqrt(static_cast<double>(std::max<std::size_t>(1, finite_count(s.before))));
      Plot x{tag("x", j) + tag("_", i),
             p.outputs[j] + " residual vs " + p.inputs[i] + " (positive lag: input leads)", "lag [samples]",
             {"before", "after", "+bound", "-bound"}, {},
             "colors:['#d62728','#2ca02c','#888','#888'],series:{'+bound':{strokePattern:[4,4]},"
             "'-bound':{strokePattern:[4,4]}}"};
      for (std::size_t l = 0; l <= 2 * std::size_t{kMaxLag}; ++l)  // lags -kMaxLag..kMaxLag
        x.rows.push_back({double(l) - kMaxLag, xb[l], xa[l], bound, -bound});
      body << "<div class='plot small' id=" << x.id << "></div>\n";
      plots.push_back(std::move(x));
    }
  body << "</section>\n<section id=steps><h2>Step responses: nominal and fitted, per finding</h2>\n";
  for (std::size_t k = 0; k < in.result.findings.size(); ++k) {
    const auto& f = in.result.findings[k];
    if (!f.fitted || f.channels.empty() || !f.channels[0].input) continue;
    const DiscreteTf nominal = f.nominal ? *f.nominal : DiscreteTf{};
    const int h = step_horizon(nominal, *f.fitted);
    const auto sn = step(nominal, h), sf = step(*f.fitted, h);
    Plot s{tag("s", k), tag("finding ", k + 1) + " (" + f.physics + "): " + arrow(in, f),
           "t [s]", {"nominal", "fitted"}, {}, "colors:['#d62728','#2ca02c'],stepPlot:true"};
    for (std::size_t t = 0; t < static_cast<std::size_t>(h); ++t) s.rows.push_back({double(t) * ts, sn[t], sf[t]});
    body << "<div class='plot small' id=" << s.id << "></div>\n";
    plots.push_back(std::move(s));
  }
  body << "</section>\n";

  paper_section(in, plots, body);
  detector_section(in, plots, body);

  // Granger table.
  body << "<section id=granger><h2>Granger causality per channel (whole record)</h2>\n<table><tr><th>output</th>"
          "<th>input</th><th>F (pairwise)</th><th>F (conditional)</th><th>p</th><th>\u03b3</th><th>located</th>"
          "</tr>\n";
  for (std::size_t j = 0; j < p.n_outputs(); ++j)
    for (std::size_t i = 0; i < p.n_inputs(); ++i) {
      const ChannelStats& c = in.monitor.channel(j, i);
      const bool located = std::find(in.verdict.located.begin(), in.verdict.located.end(), std::make_pair(j, i)) !=
                           in.verdict.located.end();
      body << "<tr" << (located ? " class=located" : "") << "><td>" << esc(p.outputs[j]) << "</td><td>"
           << esc(p.inputs[i]) << "</td><td>" << num(c.f_pairwise) << "</td><td>" << num(c.f_conditional)
           << "</td><td>" << num(in.monitor.p_value(c.lr_conditional)) << "</td><td>" << num(c.gamma) << "</td><td>"
           << (located ? "yes" : "") << (in.monitor.loop(j).diverging ? " (loop diverging)" : "") << "</td></tr>\n";
    }
  body << "</table></section>\n";

  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>\n<title>mpm diagnosis: " << esc(p.name)
       << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:1em auto;color:#222}"
          "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:3px 8px;"
          "text-align:left}tr.located{background:#fde}.plot{width:1050px;height:260px;margin:1em 0}"
          ".plot.small{width:520px;height:220px;display:inline-block;margin:.5em 4px}.meta,.note{color:#555}"
          "</style>\n<style>" << css << "</style>\n<script>\n"
       << dygraphs << "\n</script>\n</head><body>\n"
       << body.str() << "<p id=status>plots not drawn (JavaScript disabled?)</p>\n<script>\nconst plots=[";
  for (std::size_t k = 0; k < plots.size(); ++k) html << (k ? ",\n" : "") << plot_js(plots[k]);
  html << "];\nlet drawn=0;\nfor(const p of plots){const o=Object.assign({title:p.title,xlabel:p.xlabel,labels:"
          "p.labels,legend:'always',labelsSeparateLines:false,strokeWidth:1.3},p.opts);"
          "new Dygraph(document.getElementById(p.id),p.rows,o);drawn++;}\n"
          "const st=document.getElementById('status');st.textContent='drawn '+drawn+' of '+plots.length+' plots';\n"
          "st.dataset.layout=JSON.stringify({height:document.documentElement.scrollHeight,plots:plots.map(p=>{"
          "const r=document.getElementById(p.id).getBoundingClientRect();return [p.id,r.left,r.top+scrollY,r.width,"
          "r.height];})});\n"
          "</script>\n</body></html>\n";
  return html.str();
}

}  // namespace mpm
