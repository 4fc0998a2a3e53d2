// OVERVIEW: the front end every monitor of a plant shares, live (mpmd) and
// offline (`mpm monitor`, `mpm paper`, `mpm diagnose`, `mpm calibrate`, the
// bench). Written once here so that the commands cannot disagree on the same
// samples:
//   1. building a monitor from a plant (MonitorBlueprint): the noise models
//      for gamma, the reference variances, the model-filtered regressors and
//      the plant's sample time;
//   2. the residual front end (ResidualFrontEnd): u0 (InputOrigin: the plant
//      file's operating point, else the first complete input sample,
//      formats.md), y - sim_y where the controller sends its prediction,
//      inputs held over gaps (ResidualGenerator), and the settle time after
//      the nominal model starts from rest (settle_length);
//   3. the locating rule: which channel an end-of-record verdict names
//      (record_verdict), and what each raise or clear of a channel reports
//      (AlarmEdges, alarm_facts), the same numbers in mpmd's alarm messages
//      and in `mpm monitor --events`.
// Setup allocates; ResidualFrontEnd::step, AlarmEdges::scan and alarm_facts
// allocate nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "core/plant_model.hpp"

namespace mpm {

// ---- 1. A monitor of a plant ----------------------------------------------

// Noise-model AR coefficients (1 - N^-1) per output, for the gamma index.
std::vector<std::optional<std::vector<double>>> noise_ar(const PlantModel& plant, int order);
// Variance of each output's residual with a matched model (N's output
// variance), 0 where the plant file gives no noise model or no variance.
std::vector<double> reference_variances(const PlantModel& plant);
// The nominal channels G_ji, output major, for the monitor's model-filtered
// regressors (nullopt where the model has no channel).
std::vector<std::optional<DiscreteTf>> channel_models(const PlantModel& plant);
// The settings with what the plant file knows filled in: the detector's
// sample time (0 in the settings = the plant's).
MonitorSettings for_plant(MonitorSettings settings, const PlantModel& plant);

// The forgetting factor of a whole-record replay (`mpm monitor`, `mpm
// diagnose`, `mpm paper`): every sample weighs the same, so the statistics
// after the last sample are the end-of-record test. Live (mpmd, `mpm
// calibrate`) the default is MonitorSettings::forgetting; `mpm monitor
// --forgetting` with mpmd's value replays what mpmd sees.
inline constexpr double kRecordForgetting = 1.0;

// Everything a GrangerMonitor of `plant` takes besides the outputs it
// models, computed once (setup), so that building one, or one part per
// thread, is cheap. Model-filtered regressors unless `plain_lags`.
class MonitorBlueprint {
 public:
  MonitorBlueprint(const PlantModel& plant, const MonitorSettings& settings, bool plain_lags = false);
  // Throws std::invalid_argument when the settings are invalid for the plant.
  // `front_end_settle`: the samples the residual front end skips at the start
  // (settle_length()); none, and the monitor's first start waits for its lags
  // only (GrangerMonitor::start_settled()).
  GrangerMonitor build(OutputRange outputs = {}, std::size_t front_end_settle = kSettleUnknown) const;
  static constexpr std::size_t kSettleUnknown = static_cast<std::size_t>(-1);
  const MonitorSettings& settings() const noexcept { return settings_; }

 private:
  std::size_t inputs_ = 0, outputs_ = 0;
  MonitorSettings settings_;
  std::vector<std::optional<std::vector<double>>> noise_;
  std::vector<double> reference_;
  std::vector<std::optional<DiscreteTf>> channels_;
};

// ---- 2. The residual front end --------------------------------------------

// formats.md: u0 = operating_point.inputs, else the first complete input
// sample seen (all inputs finite); zeros while none has come.
class InputOrigin {
 public:
  explicit InputOrigin(const PlantModel& plant);
  // Offers an input sample (n_inputs values): the first complete one becomes
  // u0 when the plant gives none. Returns known(). Real-time safe.
  bool offer(const double* u) noexcept;
  bool known() const noexcept { return known_; }
  const std::vector<double>& u0() const noexcept { return u0_; }
  // Checkpoint: u0 was restored with the residual model that holds it.
  void restored() noexcept { known_ = true; }

 private:
  std::vector<double> u0_;
  bool known_ = false;
};

// u0 of a whole record (samples x inputs, absolute units, NaN = missing).
std::vector<double> input_origin(const PlantModel& plant, const Eigen::MatrixXd& u);
// The deviation inputs the residual generator sees: u - u0, each input
// holding its last good value over missing samples (u0 before the first).
Eigen::MatrixXd held_deviations(const Eigen::MatrixXd& u, const std::vector<double>& u0);

// The settle time of the nominal model's start-up transient, in samples:
// `requested` when >= 0 (the user's word); else none when every output's
// residual comes from the controller's own prediction (sim_ columns), which
// already accounts for the past; else the plant's 1 % settling time, capped
// at `cap` (integrating channels never settle).
std::size_t settle_length(const PlantModel& plant, int requested, std::size_t cap, bool all_simulated = false);
// The cap live: the service cannot see the record's length.
inline constexpr std::size_t kLiveSettleCap = 2000;
// The cap offline: at most a tenth of the record.
inline constexpr std::size_t record_settle_cap(std::size_t samples) noexcept { return samples / 10; }

// One sample in, its residual out: y - sim_y for the outputs whose
// prediction the controller sends, y - G_M (u - u0) for the others (NaN
// where values are missing), and where the sample stands.
class ResidualFrontEnd {
 public:
  enum class Stage : std::uint8_t {
    kNoOrigin,  // no u0 yet (no operating point, no complete input sample): nothing computed
    kSettling,  // residual computed, but the model's start-up transient is still in it
    kReady,     // residual is evidence
  };
  // u0 by InputOrigin's rule, as the samples come (live).
  ResidualFrontEnd(const PlantModel& plant, std::size_t settle);
  // u0 known beforehand (offline: input_origin over the whole record).
  // `use_sim[j]`: output j's residual is y - sim_y when a sim_y is given
  // (empty = every output).
  ResidualFrontEnd(const PlantModel& plant, const std::vector<double>& u0, std::size_t settle,
                   std::vector<bool> use_sim = {});

  // Real-time safe. u: n_inputs, y: n_outputs, sim_y: n_outputs or null,
  // residual: n_outputs written unless kNoOrigin.
  Stage step(const double* u, const double* y, const double* sim_y, double* residual) noexcept;
  // The settle time starts again (after a long gap the model held the last
  // input while the plant saw the real ones: that error decays like a
  // start-up transient).
  void resettle() noexcept { settling_ = settle_; }
  int settle() const noexcept { return settle_; }
  bool has_origin() const noexcept { return origin_.known(); }

  // Checkpoint (mpmd): whether u0 is known, then the residual model (its u0
  // included); the settle count separately, where the service's layout has it.
  template <class V>
  void visit_model(V&& v) {
    bool known = origin_.known();
    v(known);
    if (known) {
      v(generator_);
      origin_.restored();
    } else {  // a fresh model: u0 comes with the next complete sample
      generator_ = at_rest_;
      origin_ = initial_origin_;
    }
  }
  template <class V>
  void visit_settling(V&& v) {
    v(settling_);
  }

 private:
  InputOrigin origin_, initial_origin_;
  ResidualGenerator generator_, at_rest_;
  std::vector<bool> use_sim_;
  int settle_ = 0;
  int settling_ = 0;
};

// ---- 3. The locating rule -------------------------------------------------

// The verdict on a whole record, from the statistics after its last sample
// (with forgetting 1 they summarise the whole record; the alarm state is for
// live use): a channel is located when its own conditional test rejects at
// the monitor's alpha; in a loop where none does but the joint test of all
// inputs rejects, the paper's two indices name the channel: among those
// whose AR part matches N^-1 (gamma < lambda^2), the one with the largest
// pairwise F. Diverging loops locate nothing.
//
// `family` shares the level over that many tests: 1 tests each channel and
// loop at the monitor's false_alarm (the paper's per-channel rule, as `mpm
// monitor` reports a record); record_test_count() holds the whole record's
// verdict at false_alarm (what `mpm diagnose` reports beside its
// family-wise structured tests). Per test, a 3x3 record's 12 tests give a
// healthy record a mismatch about 1 time in 100.
struct RecordVerdict {
  std::vector<std::pair<std::size_t, std::size_t>> located;  // (output, input), row major
  std::vector<bool> loop_mismatch;                           // per output
  std::vector<bool> by_gamma;                                // per channel, output major
  bool diverging = false;
};
RecordVerdict record_verdict(const GrangerMonitor& monitor, double family = 1.0);
// The end-of-record tests of a record: each channel's and each loop's.
double record_test_count(const GrangerMonitor& monitor) noexcept;

// What a raise or clear of one channel reports, from the monitor right
// after the sample that changed it.
struct AlarmFacts {
  bool raised = false;
  double statistic = 0.0;          // the output's detector statistic at its last raise
  double threshold = 0.0;          // its threshold
  double window = 0.0;             // its memory (samples)
  double f_conditional = 0.0;      // the channel's conditional index
  double conditional_score = 0.0;  // the channel's conditional score at the raise
  double p_value = 1.0;            // raise: of the conditional score (nb dof); clear: of the conditional LR
  double gamma = 0.0;
  bool by_gamma = false;           // named by the paper's gamma rule
};
AlarmFacts alarm_facts(const GrangerMonitor& m, std::size_t output, std::size_t input) noexcept;

// The channels' alarm flags as last published: scan() reports each change.
class AlarmEdges {
 public:
  AlarmEdges(std::size_t outputs, std::size_t inputs) : inputs_(inputs), state_(outputs * inputs, 0) {}
  // Calls on_edge(output, input, raised) for each channel of outputs
  // [first, end) whose flag changed since the last scan, output major.
  // Parts of the outputs may be scanned on different threads.
  template <class OnEdge>
  void scan(const GrangerMonitor& m, std::size_t first, std::size_t end, OnEdge&& on_edge) {
    for (std::size_t j = first; j < end; ++j) {
      for (std::size_t i = 0; i < inputs_; ++i) {
        const std::uint8_t now = m.channel_alarm(j, i) ? 1 : 0;
        std::uint8_t& was = state_[j * inputs_ + i];
        if (now == was) continue;
        was = now;
        on_edge(j, i, now != 0);
      }
    }
  }
  template <class OnEdge>
  void scan(const GrangerMonitor& m, OnEdge&& on_edge) {
    scan(m, 0, m.n_outputs(), on_edge);
  }
  bool raised(std::size_t output, std::size_t input) const noexcept { return state_[output * inputs_ + input] != 0; }
  void lower(std::size_t output, std::size_t input) noexcept { state_[output * inputs_ + input] = 0; }
  template <class V>
  void visit_state(V&& v) {  // checkpoint
    v(state_);
  }

 private:
  std::size_t inputs_ = 0;
  std::vector<std::uint8_t> state_;  // output major
};

}  // namespace mpm
