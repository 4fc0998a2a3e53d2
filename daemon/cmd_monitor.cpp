// `mpm monitor`: replays a recording through the online Granger monitor, as
// mpmd would see it live, and prints the per-channel statistics and alarms.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <cstdio>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "config/service_settings.hpp"
#include "core/chi_square.hpp"
#include "core/diagnosis_scan.hpp"
#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/data_input.hpp"
#include "daemon/limit_flags.hpp"
#include "daemon/offline.hpp"
#include "daemon/scan_look.hpp"
#include "daemon/setting_flags.hpp"
#include "daemon/stream_monitor.hpp"

namespace mpm {
namespace {

constexpr const char* kUsageHead =
    "usage: mpm monitor --plant PLANT.yaml --data RUN.csv [options]\n"
    "  Replays the recording through the online monitor and prints, per output and input,\n"
    "  the paper's pairwise index F, the conditional index (other inputs in the model),\n"
    "  its p-value, the noise-model index gamma and the alarm state. RUN is a CSV or an\n"
    "  lcm-logger file of the sample channel (told by its content; formats.md 4.4).\n"
    "options:\n"
    "  --channel NAME     the sample channel of an LCM log (default MPM_SAMPLE)\n"
    "  --plain-lags       regress on plain input lags as in the paper (= --regressors plain_lags)\n"
    "  --threads N        N > 1: load the whole record and replay parts of the outputs on N\n"
    "                     threads (default: one thread, the record read as a stream, memory\n"
    "                     independent of its length; the result does not depend on it)\n"
    "  --json             print one JSON object instead of the table\n"
    "  --events           print the live detectors' raise and clear events as JSON lines: the\n"
    "                     alarms mpmd publishes for the same samples and settings (one thread;\n"
    "                     --forgetting 0.999 is mpmd's default memory): the sequential\n"
    "                     detector's per channel, and the diagnosis scan's per output\n"
    MPM_LIMIT_FLAGS_USAGE
    "The loop verdict is the end-of-record test (the statistics after the last sample);\n"
    "'first raised' is the live detector's first raise.\n"
    "monitor settings: mpmd.yaml's `monitor:` keys, same names and ranges (default: mpmd's,\n"
    "except --forgetting 1, the whole record):\n";

// mpmd.yaml's top-level rows of the diagnosis scan, which `--events` replays.
const std::vector<FieldRow<config::ServiceSettings>>& scan_rows() {
  static const auto rows = only(config::ServiceSettings::fields(), {"diagnosis_window", "scan_interval"});
  return rows;
}

// The usage: the fixed text, then one line per monitor setting (its row).
const std::string& usage() {
  static const std::string text =
      kUsageHead + flags_usage(config::ServiceSettings::monitor_fields()) + flags_usage(scan_rows());
  return text;
}

// A JSON number, or null when not finite (JSON has no NaN or infinity).
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

struct ChannelTrace {
  long raised_at = -1;  // first sample the alarm was raised
  long cleared_at = -1; // last sample it cleared
};

void print_table(const PlantModel& plant, const GrangerMonitor& m, const std::vector<ChannelTrace>& trace,
                 std::size_t samples, std::size_t transient) {
  const RecordVerdict verdict = record_verdict(m);
  const auto& s = m.settings();
  std::printf("plant %s: %zu samples (first %zu skipped: model start-up transient)\n", plant.name.c_str(), samples,
              transient);
  std::printf("na=%d nb=%d input pole=%g forgetting=%g alpha=%g: LR threshold %.1f (chi-square, %d dof), n_eq=%.0f\n",
              s.ar_order, s.input_order, s.input_pole, s.forgetting, s.false_alarm, m.raise_threshold(), s.input_order,
              m.effective_samples());
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    const LoopStats& l = m.loop(j);
    std::printf("\noutput %s: %s   joint p %.3g, residual variance %.4g, AR-only Sigma1 %.4g, full model %.4g\n",
                plant.outputs[j].c_str(), l.diverging ? "DIVERGING (not analysed)" : verdict.loop_mismatch[j] ? "MISMATCH" : "ok",
                m.joint_p_value(l.lr_joint), l.residual_variance, l.sigma1, l.sigma_full);
    std::printf("  %-10s %12s %12s %12s %10s  %s\n", "input", "F pairwise", "F cond.", "p (cond.)", "gamma", "alarm");
    for (std::size_t i = 0; i < m.n_inputs(); ++i) {
      const ChannelStats& c = m.channel(j, i);
      const ChannelTrace& t = trace[j * m.n_inputs() + i];
      bool located = false, by_gamma = verdict.by_gamma[j * m.n_inputs() + i];
      for (const auto& [oj, oi] : verdict.located) located = located || (oj == j && oi == i);
      std::printf("  %-10s %12.4g %12.4g %12.3g %10.4g  %s", plant.inputs[i].c_str(), c.f_pairwise, c.f_conditional,
                  m.p_value(c.lr_conditional), c.gamma, by_gamma ? "located by gamma" : located ? "MISMATCH" : "-");
      if (t.raised_at >= 0) std::printf(" (first raised at sample %ld)", t.raised_at);
      std::printf("\n");
    }
  }
}

void print_json(const PlantModel& plant, const GrangerMonitor& m, const std::vector<ChannelTrace>& trace,
                std::size_t samples) {
  const RecordVerdict verdict = record_verdict(m);
  std::printf("{\"plant\": \"%s\", \"samples\": %zu, \"lr_threshold\": %s, \"loops\": [", plant.name.c_str(), samples,
              num(m.raise_threshold()).c_str());
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    const LoopStats& l = m.loop(j);
    std::printf("%s{\"output\": \"%s\", \"alarm\": %s, \"mismatch\": %s, \"diverging\": %s, "
                "\"residual_variance\": %s, \"sigma1\": %s, \"joint_p_value\": %s, \"channels\": [",
                j ? ", " : "", plant.outputs[j].c_str(), l.alarm ? "true" : "false",
                verdict.loop_mismatch[j] ? "true" : "false", l.diverging ? "true" : "false",
                num(l.residual_variance).c_str(), num(l.sigma1).c_str(), num(m.joint_p_value(l.lr_joint)).c_str());
    for (std::size_t i = 0; i < m.n_inputs(); ++i) {
      const ChannelStats& c = m.channel(j, i);
      std::printf("%s{\"input\": \"%s\", \"F\": %s, \"F_conditional\": %s, \"p_value\": %s, \"gamma\": %s, "
                  "\"alarm\": %s, \"located_by_gamma\": %s, \"raised_at\": %ld}",
                  i ? ", " : "", plant.inputs[i].c_str(), num(c.f_pairwise).c_str(), num(c.f_conditional).c_str(),
                  num(m.p_value(c.lr_conditional)).c_str(), num(c.gamma).c_str(), c.alarm ? "true" : "false",
                  c.located_by_gamma ? "true" : "false", trace[j * m.n_inputs() + i].raised_at);
    }
    std::printf("]}");
  }
  const MonitorCounters& k = m.counters();
  std::printf("], \"counters\": {\"used\": %llu, \"missing\": %llu, \"outliers\": %llu, \"resets\": %llu, "
              "\"raises\": %llu}}\n",
              static_cast<unsigned long long>(k.used), static_cast<unsigned long long>(k.missing),
              static_cast<unsigned long long>(k.outliers), static_cast<unsigned long long>(k.resets),
              static_cast<unsigned long long>(k.raises));
}

// A JSON number to full precision, or null.
std::string exact(double v) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// One JSON line per raise or clear of a channel: the edges mpmd publishes as
// alarm messages for the same samples, with the same numbers (AlarmEdges,
// alarm_facts in core/monitor_front_end.hpp).
void print_event(const PlantModel& plant, const GrangerMonitor& m, std::size_t k, std::size_t j, std::size_t i) {
  const AlarmFacts f = alarm_facts(m, j, i);
  std::printf("{\"event\": \"%s\", \"sample\": %zu, \"output\": \"%s\", \"channel\": \"%s\", \"statistic\": %s, "
              "\"threshold\": %s, \"window\": %s, \"p_value\": %s, \"F_conditional\": %s, \"gamma\": %s, "
              "\"conditional_score\": %s, \"by_gamma\": %s, \"physics\": null, \"detector\": \"sequential\"}\n",
              f.raised ? "raised" : "cleared", k, plant.outputs[j].c_str(), plant.inputs[i].c_str(),
              exact(f.statistic).c_str(), exact(f.threshold).c_str(), exact(f.window).c_str(), exact(f.p_value).c_str(),
              exact(f.f_conditional).c_str(), exact(f.gamma).c_str(), exact(f.conditional_score).c_str(),
              f.by_gamma ? "true" : "false");
}

// One JSON line per raise or clear of an output by the diagnosis scan: the
// finding's channel, physics, fitted parameters and held-out improvement (a
// raise), the look's window and level; what mpmd publishes for the same look.
void print_scan_event(const PlantModel& plant, std::size_t k, std::size_t j, bool raised, const msg::Diagnosis& d,
                      const std::optional<std::size_t>& input, double lr, std::size_t window, double alpha) {
  std::string params = "{";
  for (std::size_t n = 0; n < d.parameter_names.size(); ++n)
    params += (n ? ", " : "") + json_quoted(d.parameter_names[n]) + ": " + exact(d.parameter_values[n]);
  params += "}";
  std::printf("{\"event\": \"%s\", \"sample\": %zu, \"output\": \"%s\", \"channel\": %s, \"statistic\": %s, "
              "\"threshold\": null, \"window\": %zu, \"p_value\": %s, \"physics\": %s, \"detector\": \"scan\", "
              "\"parameters\": %s, \"holdout_improvement\": %s, \"channels\": %s, \"text\": %s}\n",
              raised ? "raised" : "cleared", k, plant.outputs[j].c_str(),
              input ? json_quoted(plant.inputs[*input]).c_str() : "null", raised ? exact(lr).c_str() : "null", window,
              exact(alpha).c_str(), raised ? json_quoted(d.physics).c_str() : "null", params.c_str(),
              raised ? exact(d.holdout_improvement).c_str() : "null", json_quoted(d.channels).c_str(),
              json_quoted(d.text).c_str());
}

// The diagnosis scan run at once at its checkpoints (mpmd runs the same
// looks on its diagnosis thread): a ring of the rows mpmd keeps, the
// schedule, and the events of each look.
class ScanReplay {
 public:
  ScanReplay(const PlantModel& plant, const ScanSettings& settings, double rate_per_sample)
      : plant_(plant),
        nominal_(channel_models(plant)),
        scan_(plant.n_outputs(), settings, rate_per_sample),
        ring_(settings.window, plant.n_inputs(), plant.n_outputs()),
        snapshot_(static_cast<Eigen::Index>(settings.window), static_cast<Eigen::Index>(plant.n_inputs() + plant.n_outputs())),
        nan_(plant.n_outputs(), std::numeric_limits<double>::quiet_NaN()) {}

  void on_row(const double* u, const double* d, ResidualFrontEnd::Stage stage) {
    ring_.record(u, stage == ResidualFrontEnd::Stage::kReady ? d : nan_.data());
  }
  void on_ready(std::size_t k) {
    if (!scan_.on_ready_sample()) return;
    const std::size_t n = scan_.look_length();
    ring_.copy_last(n, snapshot_);
    const auto rows = static_cast<Eigen::Index>(n), m = static_cast<Eigen::Index>(plant_.n_inputs());
    const diagnosis::Result result =
        diagnose_window(plant_, nominal_, snapshot_.topLeftCorner(rows, m),
                        snapshot_.block(0, m, rows, static_cast<Eigen::Index>(plant_.n_outputs())), scan_.alpha_look());
    scan_.conclude(flagged_outputs(result, plant_.n_outputs()), [&](std::size_t j, bool raised) {
      msg::Diagnosis d;
      std::optional<std::size_t> input;
      double lr = 0.0;
      if (const diagnosis::Finding* f = raised ? finding_for(result, j) : nullptr) {
        describe_finding(plant_, *f, d);
        input = finding_input(*f, j);
        lr = f->lr;
      } else {
        d.text = "no finding on " + plant_.outputs[j] + " in " + std::to_string(scan_.settings().clear_after) +
                 " looks in a row";
      }
      print_scan_event(plant_, k, j, raised, d, input, lr, n, scan_.alpha_look());
    });
  }

 private:
  const PlantModel& plant_;
  std::vector<std::optional<DiscreteTf>> nominal_;
  DiagnosisScan scan_;
  SampleRing ring_;
  Eigen::MatrixXd snapshot_;
  std::vector<double> nan_;
};

int run(int argc, char** argv) {
  const auto valued = with_limit_flags(with_flags(
      config::ServiceSettings::monitor_fields(), with_flags(scan_rows(), {"plant", "data", "threads", "channel"})));
  return run_command("mpm monitor", usage().c_str(), argc, argv, valued, {"json", "events", "plain-lags"},
                     [](const Args& args) {
    config::ServiceSettings service;
    service.monitor.forgetting = kRecordForgetting;  // the whole record, unless told
    service.plain_lags = args.flag("plain-lags");
    apply_flags(args, config::ServiceSettings::monitor_fields(), service);
    apply_flags(args, scan_rows(), service);
    MonitorSettings& settings = service.monitor;
    const config::Limits limits = limits_from(args);
    const PlantModel plant = config::load_plant(args.required("plant"), limits);
    const DataOptions data_options{args.get("channel").value_or("MPM_SAMPLE"), "mpm monitor", limits};
    if (service.input_pole_auto) settings.input_pole = dominant_pole(plant);
    if (const std::vector<FieldError> e = service.errors(); !e.empty()) throw UsageError(joined(e));
    const int requested_threads = args.integer("threads", 0);  // 0: one per core
    if (args.get("threads") && requested_threads < 1) throw UsageError("--threads must be >= 1");
    // The diagnosis scan takes its share of the stated rate from the
    // sequential detector (share_rate) as in mpmd, so that the table's
    // 'first raised' is mpmd's sequential detector; it runs with --events.
    const bool events = args.flag("events");
    ScanSettings scan;
    scan.interval = static_cast<std::size_t>(std::max(0, service.scan_interval));
    scan.window = static_cast<std::size_t>(std::max(0, service.diagnosis_window));
    scan.min_samples = std::min(scan.min_samples, scan.window);
    if (const std::string e = scan.validate(); !e.empty()) throw UsageError(e);
    const double scan_rate = share_rate(settings.detector, scan, plant.sample_time);
    std::optional<ScanReplay> replay;
    if (events && scan.interval > 0) replay.emplace(plant, scan, scan_rate);
    const int settle = service.settle_samples;  // -1: settle_length's automatic rule

    std::vector<ChannelTrace> trace(plant.n_inputs() * plant.n_outputs());
    AlarmEdges edges(plant.n_outputs(), plant.n_inputs());
    // On each part's thread: only its outputs, so the parts write disjoint traces.
    if (events && requested_threads > 1) throw UsageError("--events needs one thread (events in sample order)");
    const PartSampleCallback on_sample = [&](std::size_t k, const GrangerMonitor& m) {
      edges.scan(m, m.first_modelled_output(), m.end_modelled_output(), [&](std::size_t j, std::size_t i, bool now) {
        ChannelTrace& t = trace[j * m.n_inputs() + i];
        if (now && t.raised_at < 0) t.raised_at = static_cast<long>(k);
        if (!now) t.cleared_at = static_cast<long>(k);
        if (events) print_event(plant, m, k, j, i);
      });
      if (replay) replay->on_ready(k);
    };
    const RowCallback on_row = [&](const double* u, const double* d, ResidualFrontEnd::Stage stage) {
      if (replay) replay->on_row(u, d, stage);
    };
    // By default the recording is streamed (memory independent of its
    // length); --threads N > 1 loads it whole and splits the outputs.
    std::size_t samples = 0, transient = 0;
    const GrangerMonitor monitor = [&] {
      if (requested_threads <= 1) {
        const auto open = [&] { return open_data(args.required("data"), plant, data_options); };
        StreamedRecord r = monitor_csv_stream(plant, open, settings, service.plain_lags, on_sample, settle, on_row);
        if (!r.notes.empty()) std::fprintf(stderr, "mpm monitor: %s\n", r.notes.c_str());
        samples = r.samples;
        transient = r.transient;
        return std::move(r.monitor);
      }
      const config::Recording rec = load_data(args.required("data"), plant, data_options);
      const ResidualSeries series = compute_residuals(plant, rec, config::bind(plant, rec), settle);
      samples = rec.samples();
      transient = series.transient;
      return monitor_record(plant, series, settings, static_cast<std::size_t>(requested_threads),
                            service.plain_lags, on_sample);
    }();
    if (events) {
      // the events were the output
    } else if (args.flag("json")) {
      print_json(plant, monitor, trace, samples);
    } else {
      print_table(plant, monitor, trace, samples, transient);
    }
    return kExitOk;
  });
}

const bool registered = register_command({"monitor", "replay a recording through the online monitor", &run});

}  // namespace
}  // namespace mpm
