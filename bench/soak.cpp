#include "bench/soak.hpp"

#include <malloc.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <type_traits>

#include <Eigen/Dense>

#include "config/plant_loader.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/mpmd/monitor_service.hpp"
#include "sim/builtin_plants.hpp"
#include "tests/support/batch_qr.hpp"

namespace mpm::bench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kM = 2;  // inputs
constexpr std::size_t kN = 2;  // outputs
// The mismatch of a mismatched stretch, and where it is.
constexpr double kMismatchGain = 1.3;
constexpr std::size_t kTrueOutput = 1, kTrueInput = 0;  // u1 -> y2
// Rows older than this weight (lambda^age) are left out of the batch fit.
constexpr double kOldestWeight = 1e-30;

// The Wood-Berry column as config/wood-berry.yaml states it (b q^-d / (1 - a
// q^-1) per channel, AR(1) noise per output, operating point), written out
// here so the data do not come from the code under test.
struct Channel {
  double b, a;
  int delay;
};
constexpr Channel kChannels[kN][kM] = {{{0.744, 0.9419, 2}, {-0.8789, 0.9535, 4}},
                                       {{0.5786, 0.9123, 8}, {-1.302, 0.9329, 4}}};
constexpr double kNoisePole[kN] = {0.8, 0.9};
constexpr double kU0[kM] = {15.0, 12.0};
constexpr double kY0[kN] = {90.0, 5.0};
constexpr double kInputStd = 5.0;

// Plant and model driven by the same inputs; every value x `scale`.
class SoakPlant {
 public:
  explicit SoakPlant(std::uint64_t seed) : rng_(seed) {}

  void step(double scale, bool frozen, double g21, double* u, double* y, double* sim_y) {
    head_ = (head_ + 1) % kHistory;
    for (std::size_t i = 0; i < kM; ++i) {
      if (!frozen) du_[i] = scale * kInputStd * white_(rng_);
      hist_[i][head_] = du_[i];
      u[i] = scale * kU0[i] + du_[i];
    }
    for (std::size_t j = 0; j < kN; ++j) {
      noise_[j] = kNoisePole[j] * noise_[j] + scale * white_(rng_);
      double plant = 0.0, model = 0.0;
      for (std::size_t i = 0; i < kM; ++i) {
        const Channel& c = kChannels[j][i];
        const double past = hist_[i][(head_ + kHistory - static_cast<std::size_t>(c.delay)) % kHistory];
        const double gain = (j == kTrueOutput && i == kTrueInput) ? g21 : 1.0;
        x_[j][i] = c.a * x_[j][i] + gain * c.b * past;
        xm_[j][i] = c.a * xm_[j][i] + c.b * past;
        plant += x_[j][i];
        model += xm_[j][i];
      }
      y[j] = scale * kY0[j] + plant + noise_[j];
      sim_y[j] = scale * kY0[j] + model;
    }
  }
  std::mt19937_64& rng() { return rng_; }

 private:
  static constexpr std::size_t kHistory = 16;
  std::mt19937_64 rng_;
  std::normal_distribution<double> white_{0.0, 1.0};
  std::array<double, kM> du_{};
  std::array<std::array<double, kHistory>, kM> hist_{};
  std::size_t head_ = 0;
  std::array<std::array<double, kM>, kN> x_{}, xm_{};
  std::array<double, kN> noise_{};
};

PlantModel wood_berry() {
  const auto text = sim::builtin_plant_text("wood-berry.yaml");
  if (!text) throw std::runtime_error("built-in wood-berry.yaml missing");
  return config::parse_plant(std::string(*text), "wood-berry.yaml (built in)");
}

// Short memories, so that a stretch of 25 000 samples holds many of them and
// an alarm raised in a mismatched stretch clears within the next one; the
// stated false-alarm rate is the default (1 per year of 1 s samples).
ServiceSettings soak_settings() {
  ServiceSettings s;
  s.controller_id = "soak";
  s.monitor.ar_order = 5;
  s.monitor.input_order = 10;  // covers G21's 8-sample delay
  s.monitor.forgetting = 0.995;
  s.monitor.detector.windows = 2;
  s.settle_samples = 100;
  s.log_interval = 3600;
  s.diagnosis_window = 0;  // the monitor's own memory and time, without the diagnosis
  return s;
}

// The monitor's regressor registers and per-output use counts, read through
// its checkpoint visitor (the order of GrangerMonitor::visit_state).
struct MonitorProbe {
  const Eigen::MatrixXd* residual_lags = nullptr;  // na x outputs
  const Eigen::MatrixXd* input_lags = nullptr;     // nb x (outputs * inputs)
  const std::vector<std::uint64_t>* output_used = nullptr;

  explicit MonitorProbe(const GrangerMonitor& monitor) {
    int index = 0;
    // visit_state is not const (a checkpoint reads into it too); this
    // visitor only takes addresses.
    const_cast<GrangerMonitor&>(monitor).visit_state([&](auto& member) {
      using T = std::decay_t<decltype(member)>;
      if constexpr (std::is_same_v<T, Eigen::MatrixXd>) {
        if (index == 0) residual_lags = &member;
        if (index == 1) input_lags = &member;
      }
      if constexpr (std::is_same_v<T, std::vector<std::uint64_t>>) {
        if (index == 18) output_used = &member;
      }
      ++index;
    });
    if (!residual_lags || !input_lags || !output_used)
      throw std::runtime_error("soak: GrangerMonitor::visit_state changed its order; update bench/soak.cpp's probe");
  }
};

// The rows one output's factor absorbed, newest last, in a ring of the
// rows whose weight is above kOldestWeight; the batch fit of them.
class BatchOracle {
 public:
  BatchOracle(std::size_t na, std::size_t nb, double lambda)
      : na_(na), nb_(nb), p_(1 + na + kM * nb), lambda_(lambda),
        capacity_(static_cast<std::size_t>(std::ceil(std::log(kOldestWeight) / std::log(lambda)))),
        rows_(static_cast<Eigen::Index>(capacity_), static_cast<Eigen::Index>(p_ + 1)),
        weighted_(static_cast<Eigen::Index>(capacity_), static_cast<Eigen::Index>(p_ + 1)) {}

  void clear() noexcept { count_ = 0; }
  // The row output j's factor absorbs: [1, its residual lags, its inputs'
  // regressors, the residual] from the registers before the update.
  void push(const Eigen::MatrixXd& res_lags, const Eigen::MatrixXd& in_lags, std::size_t j, double residual) {
    auto row = rows_.row(static_cast<Eigen::Index>(next_));
    row[0] = 1.0;
    for (std::size_t l = 0; l < na_; ++l) row[static_cast<Eigen::Index>(1 + l)] = res_lags(static_cast<Eigen::Index>(l), static_cast<Eigen::Index>(j));
    for (std::size_t i = 0; i < kM; ++i)
      for (std::size_t l = 0; l < nb_; ++l)
        row[static_cast<Eigen::Index>(1 + na_ + i * nb_ + l)] =
            in_lags(static_cast<Eigen::Index>(l), static_cast<Eigen::Index>(j * kM + i));
    row[static_cast<Eigen::Index>(p_)] = residual;
    next_ = (next_ + 1) % capacity_;
    if (count_ < capacity_) ++count_;
  }
  std::size_t count() const noexcept { return count_; }

  // Largest deviation of the monitor's output j from the batch fit.
  double deviation(const GrangerMonitor& monitor, std::size_t j, double sum_w) {
    const auto n = static_cast<Eigen::Index>(count_);
    double w = 1.0;
    for (Eigen::Index a = 0; a < n; ++a) {  // a = age, newest first
      const std::size_t slot = (next_ + capacity_ - 1 - static_cast<std::size_t>(a)) % capacity_;
      weighted_.row(a) = std::sqrt(w) * rows_.row(static_cast<Eigen::Index>(slot));
      w *= lambda_;
    }
    test::BatchQr qr(static_cast<int>(p_));
    qr.add_block(weighted_.topRows(n));
    const int p = static_cast<int>(p_), prefix = static_cast<int>(1 + na_), nb = static_cast<int>(nb_);
    std::vector<int> all, ar;
    for (int c = 0; c < p; ++c) all.push_back(c);
    for (int c = 0; c < prefix; ++c) ar.push_back(c);
    const double rss_full = qr.rss(all), rss_ar = qr.rss(ar);
    const LoopStats& loop = monitor.loop(j);
    const auto relative = [](double value, double ref) { return std::abs(value - ref) / std::abs(ref); };
    double worst = std::max(relative(loop.sigma_full * sum_w, rss_full),
                            relative(loop.sigma1 / loop.sigma_full, rss_ar / rss_full));
    for (std::size_t i = 0; i < kM; ++i) {
      const int first = prefix + static_cast<int>(i) * nb;
      std::vector<int> pair = ar;
      for (int c = first; c < first + nb; ++c) pair.push_back(c);
      const double f_cond = std::log(qr.rss(test::range_except(p, first, nb)) / rss_full);
      const double f_pair = std::log(rss_ar / qr.rss(pair));
      const ChannelStats& c = monitor.channel(j, i);
      worst = std::max({worst, std::abs(c.f_conditional - f_cond), std::abs(c.f_pairwise - f_pair)});
    }
    return std::isfinite(worst) ? worst : std::numeric_limits<double>::infinity();
  }

 private:
  std::size_t na_, nb_, p_;
  double lambda_;
  std::size_t capacity_;
  Eigen::MatrixXd rows_;      // ring
  Eigen::MatrixXd weighted_;  // scratch: sqrt(lambda^age) x rows, newest first
  std::size_t next_ = 0, count_ = 0;
};

// Alarm edges into the current stretch, and the channels raised now.
struct AlarmLedger {
  SoakStretch* stretch = nullptr;
  bool disturbed = false;  // in the stretch's disturbance window now
  std::array<bool, kN * kM> raised{};
  void on_alarm(const msg::Alarm& a) {
    const auto c = static_cast<std::size_t>(a.output_index) * kM + static_cast<std::size_t>(a.input_index);
    raised[c] = a.raised;
    if (!a.raised || !stretch) return;
    const bool truth = static_cast<std::size_t>(a.output_index) == kTrueOutput &&
                       static_cast<std::size_t>(a.input_index) == kTrueInput;
    if (truth && stretch->mismatched) ++stretch->raises_true;
    else if (disturbed) ++stretch->raises_disturbed;
    else {
      if (stretch->raises_other++ == 0) {
        stretch->first_clean_raise = a.sample_sequence - 1 - static_cast<std::int64_t>(stretch->first_sample);
        stretch->first_clean_output = a.output_index;
        stretch->first_clean_input = a.input_index;
      }
    }
  }
  bool any() const noexcept {
    for (bool r : raised)
      if (r) return true;
    return false;
  }
};

int count_nonfinite(const MonitorService& service) {
  int bad = 0;
  const GrangerMonitor& m = service.monitor();
  for (std::size_t j = 0; j < kN; ++j) {
    const LoopStats& l = m.loop(j);
    for (double v : {l.sigma1, l.sigma_full, l.residual_variance, l.lr_joint}) bad += std::isfinite(v) ? 0 : 1;
    for (std::size_t i = 0; i < kM; ++i) {
      const ChannelStats& c = m.channel(j, i);
      for (double v : {c.f_pairwise, c.f_conditional, c.lr_pairwise, c.lr_conditional, c.score_conditional})
        bad += std::isfinite(v) ? 0 : 1;
    }
  }
  return bad;
}

// Every number of a status message but gamma (NaN by design where unknown).
int count_nonfinite(const msg::Status& s) {
  int bad = 0;
  for (double v : {s.effective_samples, s.raise_threshold, s.clear_threshold}) bad += std::isfinite(v) ? 0 : 1;
  for (const auto& c : s.channels)
    for (double v : {c.f_pairwise, c.f_conditional, c.lr, c.p_value}) bad += std::isfinite(v) ? 0 : 1;
  for (const auto& l : s.loops)
    for (double v : {l.residual_variance, l.sigma1, l.sigma_full}) bad += std::isfinite(v) ? 0 : 1;
  return bad;
}

constexpr SoakKind kCycle[] = {SoakKind::kMatched, SoakKind::kMismatched, SoakKind::kGaps, SoakKind::kNan,
                               SoakKind::kOutliers, SoakKind::kFrozen, SoakKind::kHuge, SoakKind::kTiny};

// Restores the log sink on every way out.
struct CountingLog {
  explicit CountingLog(std::uint64_t& lines) {
    log::set_sink([&lines](log::Level, std::string_view) { ++lines; });
  }
  ~CountingLog() { log::set_sink({}); }
  CountingLog(const CountingLog&) = delete;
  CountingLog& operator=(const CountingLog&) = delete;
};

}  // namespace

const char* soak_kind_name(SoakKind kind) noexcept {
  switch (kind) {
    case SoakKind::kMatched: return "matched";
    case SoakKind::kMismatched: return "mismatched";
    case SoakKind::kGaps: return "gaps";
    case SoakKind::kNan: return "nan";
    case SoakKind::kOutliers: return "outliers";
    case SoakKind::kFrozen: return "frozen";
    case SoakKind::kHuge: return "huge";
    case SoakKind::kTiny: return "tiny";
  }
  return "?";
}

std::uint64_t SoakFaults::events() const noexcept {
  return gap_events + nan_bursts + outliers + stretches;
}

// Resident memory of what is still allocated: freed heap handed back first
// (malloc_trim), since glibc keeps freed blocks of a rare large temporary
// (the batch fit's check, a first alarm) in the heap, which reads as ~3 MB of
// growth after the first mismatched stretch in one build and not another
// (measured: 3.3 MB, 192 kB with MALLOC_TRIM_THRESHOLD_=0).
double resident_kb() {
  malloc_trim(0);
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0.0;
  unsigned long size = 0, resident = 0;
  const int got = std::fscanf(f, "%lu %lu", &size, &resident);
  std::fclose(f);
  if (got != 2) return 0.0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1024.0;
}

SoakReport run_soak(const SoakOptions& o) {
  SoakReport report;
  CountingLog counting(report.log_lines);
  const auto t0 = std::chrono::steady_clock::now();
  const PlantModel plant = wood_berry();
  const ServiceSettings settings = soak_settings();
  AlarmLedger ledger;
  MonitorService service(plant, settings, [&ledger](const msg::Alarm& a) { ledger.on_alarm(a); });
  const GrangerMonitor& monitor = service.monitor();
  const MonitorProbe probe(monitor);
  const std::size_t na = static_cast<std::size_t>(settings.monitor.ar_order);
  const std::size_t nb = static_cast<std::size_t>(settings.monitor.input_order);
  const double lambda = settings.monitor.forgetting;
  std::vector<BatchOracle> oracle(kN, BatchOracle(na, nb, lambda));
  Eigen::MatrixXd res_lags = *probe.residual_lags, in_lags = *probe.input_lags;  // before each update

  SoakPlant gen(o.seed);
  std::uniform_int_distribution<int> pick(0, 1 << 20);
  msg::Sample s;
  s.controller_id = settings.controller_id;
  s.session_id = 7;
  s.u.resize(kM);
  s.y.resize(kN);
  s.sim_y.resize(kN);
  msg::Status status;
  double sum_w = 0.0;
  std::uint64_t gap_left = 0, nan_left = 0;
  std::size_t nan_target = 0;
  const std::uint64_t stretches = (o.samples + o.stretch - 1) / o.stretch;
  report.stretches.reserve(static_cast<std::size_t>(stretches));
  const auto start = Throttle::Clock::time_point{};

  for (std::uint64_t k = 0; k < stretches; ++k) {
    SoakStretch& st = report.stretches.emplace_back();
    st.kind = kCycle[k % (sizeof kCycle / sizeof kCycle[0])];
    st.first_sample = k * o.stretch;
    st.samples = std::min(o.stretch, o.samples - st.first_sample);
    st.mismatched = st.kind == SoakKind::kMismatched;
    if (st.kind == SoakKind::kMismatched || st.kind == SoakKind::kFrozen || st.kind == SoakKind::kHuge ||
        st.kind == SoakKind::kTiny)
      ++report.faults.stretches;
    ledger.stretch = &st;
    const std::uint64_t from = st.samples / 10, to = st.samples / 2;  // the disturbance
    for (std::uint64_t t = 0; t < st.samples; ++t) {
      const bool disturbed = t >= from && t < to;
      const double scale = !disturbed ? 1.0 : st.kind == SoakKind::kHuge ? 1e8 : st.kind == SoakKind::kTiny ? 1e-8 : 1.0;
      const bool frozen = disturbed && st.kind == SoakKind::kFrozen;
      ledger.disturbed = disturbed && st.kind != SoakKind::kMatched && st.kind != SoakKind::kMismatched;
      gen.step(scale, frozen, st.mismatched ? kMismatchGain : 1.0, s.u.data(), s.y.data(), s.sim_y.data());
      s.seq = static_cast<std::int64_t>(st.first_sample + t + 1);
      const auto now = start + std::chrono::seconds(s.seq);
      SoakFaults& f = report.faults;
      f.frozen += frozen ? 1 : 0;
      f.huge += disturbed && st.kind == SoakKind::kHuge ? 1 : 0;
      f.tiny += disturbed && st.kind == SoakKind::kTiny ? 1 : 0;
      f.mismatched += st.mismatched ? 1 : 0;
      ++report.samples;
      // Gaps: never delivered.
      if (disturbed && st.kind == SoakKind::kGaps && gap_left == 0 && (t - from) % 400 == 0) {
        gap_left = 1 + static_cast<std::uint64_t>(pick(gen.rng()) % 30);
        ++f.gap_events;
      }
      if (gap_left > 0) {
        --gap_left;
        ++f.missing;
        continue;
      }
      if (disturbed && st.kind == SoakKind::kNan && nan_left == 0 && (t - from) % 500 == 0) {
        nan_left = 1 + static_cast<std::uint64_t>(pick(gen.rng()) % 20);
        nan_target = static_cast<std::size_t>(pick(gen.rng()) % 4);
        ++f.nan_bursts;
      }
      if (nan_left > 0) {
        --nan_left;
        ++f.nan_samples;
        (nan_target < kM ? s.u[nan_target] : s.y[nan_target - kM]) = kNaN;
      }
      if (disturbed && st.kind == SoakKind::kOutliers && (t - from) % 250 == 125) {
        const int what = pick(gen.rng());
        const double sign = what & 1 ? 1.0 : -1.0;
        const std::size_t which = static_cast<std::size_t>(what >> 1) % 2;
        switch ((what >> 2) % 3) {
          case 0: s.y[which] += sign * 1e6; break;
          case 1: s.y[which] += sign * 1e100; ++f.outliers_1e100; break;
          default: s.u[which] += sign * 1e6; break;
        }
        ++f.outliers;
      }
      res_lags = *probe.residual_lags;
      in_lags = *probe.input_lags;
      const std::uint64_t used_before = monitor.counters().used;
      service.on_sample(s, now);
      ++report.delivered;
      if (monitor.counters().used != used_before) {
        sum_w = lambda * sum_w + 1.0;
        for (std::size_t j = 0; j < kN; ++j) {
          if ((*probe.output_used)[j] == 0) oracle[j].clear();  // the output restarted: a new window
          else oracle[j].push(res_lags, in_lags, j, s.y[j] - s.sim_y[j]);
        }
      }
      report.nonfinite += static_cast<std::uint64_t>(count_nonfinite(service));
      if (s.seq % 1000 == 0) {
        service.check_health(now);
        service.fill_status(status, s.seq, s.seq);
        report.nonfinite += static_cast<std::uint64_t>(count_nonfinite(status));
        ++report.statuses;
      }
    }
    // The end of the stretch: the statistics against the batch fit.
    for (std::size_t j = 0; j < kN; ++j) {
      if (oracle[j].count() < 10 * (1 + na + kM * nb)) continue;
      st.deviation = std::max(st.deviation, oracle[j].deviation(monitor, j, sum_w));
      ++report.checks;
    }
    report.max_deviation = std::max(report.max_deviation, st.deviation);
    st.raised_at_end = ledger.any();
    for (std::size_t j = 0; j < kN; ++j) st.diverging_at_end = st.diverging_at_end || monitor.loop(j).diverging;
    st.rss_kb = resident_kb();
    if (k == 0) report.rss_first_kb = st.rss_kb;
    report.rss_max_growth_kb = std::max(report.rss_max_growth_kb, st.rss_kb - report.rss_first_kb);
    if (o.progress) o.progress(st.first_sample + st.samples, o.samples);
  }
  ledger.stretch = nullptr;
  report.used = monitor.counters().used;
  report.service_gaps = service.counters().gaps;
  report.service_missing = service.counters().missing;
  report.service_nan = service.counters().nan_samples;
  report.monitor_outliers = monitor.counters().outliers;
  report.monitor_resets = monitor.counters().resets;
  report.monitor_raises = monitor.counters().raises;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace mpm::bench
