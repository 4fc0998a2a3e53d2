// `mpm diagnose`: reads a plant file and a recording and explains the
// mismatch in the diagnosis JSON of formats.md section 3. Detection and
// location come from the online monitor run over the whole record (the
// paper's method, forgetting 1); the physics from core/diagnosis.hpp, which
// compares structured hypotheses fitted to the whitened residual.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "config/json_text.hpp"
#include "config/output_file.hpp"
#include "config/plant_loader.hpp"
#include "core/diagnosis.hpp"
#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/data_input.hpp"
#include "daemon/limit_flags.hpp"
#include "daemon/offline.hpp"
#include "daemon/plant_writer.hpp"
#include "daemon/report_html.hpp"
#include "daemon/series_allocator.hpp"
#include "daemon/setting_flags.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm diagnose --plant PLANT.yaml --data RUN.csv [--json OUT.json]\n"
    "  Detects and locates model-plant mismatch in the recording (Granger causality of the\n"
    "  residual, as the online monitor) and names its physics by fitting structured\n"
    "  hypotheses (gain, dead time, time constant, extra lag, integrator, missing channel,\n"
    "  actuator / sensor lag, saturation, deadband, nonlinear gain, unmodelled recorded\n"
    "  signal, disturbance model) on 70 % of the record, checked on the other 30 %.\n"
    "  Writes the diagnosis JSON (formats.md section 3) to OUT.json, or to stdout. RUN is a\n"
    "  CSV or an lcm-logger file of the sample channel (told by its content; formats.md 4.4).\n"
    "  Exit status: 0 done, 1 error (also a failed write; OUT.json may not be an input),\n"
    "  2 usage, 3 cannot decide (too few samples with every input and output finite).\n"
    "options:\n"
    "  --json OUT.json   where to write the report (default: standard output)\n"
    "  --channel NAME    the sample channel of an LCM log (default MPM_SAMPLE)\n"
    "  --write-plant P2.yaml  also write the plant file with the accepted corrections\n"
    "                    applied, each change commented (never the input plant file)\n"
    "  --html REPORT.html  also write a self-contained HTML report (plots, fit %)\n"
    "  --quiet           no progress lines on standard error\n"
    "  --verbose         also list every hypothesis tried, with its statistics\n";
constexpr const char* kUsageTail = MPM_LIMIT_FLAGS_USAGE "  --help            this text\n";

// --alpha: the settings an engineer sets, from their table.
const std::vector<FieldRow<diagnosis::Settings>>& setting_rows() { return diagnosis::Settings::fields(); }

bool g_quiet = false;
void progress(const char* message) {
  if (!g_quiet) std::fprintf(stderr, "mpm diagnose: %s\n", message);
}

// --- JSON writing -----------------------------------------------------------

std::string quoted(const std::string& s) { return config::json_string(s); }
std::string number(double v) { return config::json_number(v, 8); }
std::string number_list(const std::vector<double>& v) { return config::json_number_list(v, 8); }

std::string tf_json(const DiscreteTf& tf, const std::map<std::string, double>& extra = {}) {
  std::string o = "{\"num\": " + number_list(tf.num) + ", \"den\": " + number_list(tf.den) +
                  ", \"delay\": " + std::to_string(tf.delay);
  for (const auto& [k, v] : extra) o += ", " + quoted(k) + ": " + number(v);
  return o + "}";
}

std::string finding_json(const PlantModel& plant, const diagnosis::Finding& f) {
  std::ostringstream o;
  o << "    {\n      \"channels\": [";
  for (std::size_t c = 0; c < f.channels.size(); ++c) {
    const auto& ch = f.channels[c];
    o << (c ? ", " : "") << "{\"output\": " << quoted(plant.outputs[ch.output])
      << ", \"input\": " << (ch.input ? quoted(plant.inputs[*ch.input]) : "null") << "}";
  }
  o << "],\n      \"physics\": " << quoted(f.physics) << ",\n      \"signal\": "
    << (f.signal ? quoted(*f.signal) : "null") << ",\n      \"summary\": " << quoted(f.summary)
    << ",\n      \"nominal\": " << (f.nominal ? tf_json(*f.nominal) : "null")
    << ",\n      \"fitted\": " << (f.fitted ? tf_json(*f.fitted, f.parameters) : "null")
    << ",\n      \"fit\": {\"residual_variance_before\": " << number(f.fit.residual_variance_before)
    << ", \"residual_variance_after\": " << number(f.fit.residual_variance_after)
    << ", \"holdout_variance_before\": " << number(f.fit.holdout_variance_before)
    << ", \"holdout_variance_after\": " << number(f.fit.holdout_variance_after)
    << "},\n      \"raw_residual\": {\"residual_variance_before\": " << number(f.raw.residual_variance_before)
    << ", \"residual_variance_after\": " << number(f.raw.residual_variance_after)
    << ", \"holdout_variance_before\": " << number(f.raw.holdout_variance_before)
    << ", \"holdout_variance_after\": " << number(f.raw.holdout_variance_after) << "},\n      \"likelihood_ratio\": "
    << number(f.lr) << ",\n      \"parameters\": " << f.params << ",\n      \"alternatives\": [";
  for (std::size_t a = 0; a < f.alternatives.size(); ++a) o << (a ? ", " : "") << quoted(f.alternatives[a]);
  o << "],\n      \"implausible\": " << (f.implausible.empty() ? "null" : quoted(f.implausible)) << "\n    }";
  return o.str();
}

std::string report_json(const PlantModel& plant, std::size_t samples, const GrangerMonitor& m,
                        const RecordVerdict& verdict, const diagnosis::Result& r, const diagnosis::Settings& settings) {
  std::ostringstream o;
  o << "{\n  \"schema\": \"mpm.diagnosis/1\",\n  \"samples\": " << samples << ",\n  \"alpha\": "
    << number(settings.alpha) << ",\n  \"holdout_phase\": " << settings.holdout_phase
    << ",\n  \"mismatch\": " << (r.mismatch ? "true" : "false") << ",\n  \"loops\": [\n";
  for (std::size_t j = 0; j < plant.n_outputs(); ++j) {
    bool loop_mismatch = verdict.loop_mismatch[j];
    for (const auto& f : r.findings)
      for (const auto& c : f.channels) loop_mismatch = loop_mismatch || c.output == j;
    const LoopStats& l = m.loop(j);
    o << "    {\"output\": " << quoted(plant.outputs[j]) << ", \"mismatch\": " << (loop_mismatch ? "true" : "false")
      << ", \"diverging\": " << (l.diverging ? "true" : "false")
      << ", \"residual_variance\": " << number(l.residual_variance) << ",\n     \"granger\": [";
    for (std::size_t i = 0; i < plant.n_inputs(); ++i) {
      const ChannelStats& c = m.channel(j, i);
      o << (i ? ", " : "") << "{\"input\": " << quoted(plant.inputs[i]) << ", \"F\": " << number(c.f_pairwise)
        << ", \"F_conditional\": " << number(c.f_conditional) << ", \"p_value\": " << number(m.p_value(c.lr_conditional))
        << "}";
    }
    o << "],\n     \"gamma\": [";
    for (std::size_t i = 0; i < plant.n_inputs(); ++i)
      o << (i ? ", " : "") << "{\"input\": " << quoted(plant.inputs[i]) << ", \"gamma\": " << number(m.channel(j, i).gamma)
        << "}";
    o << "]}" << (j + 1 < plant.n_outputs() ? "," : "") << "\n";
  }
  o << "  ],\n  \"findings\": [\n";
  for (std::size_t k = 0; k < r.findings.size(); ++k)
    o << finding_json(plant, r.findings[k]) << (k + 1 < r.findings.size() ? "," : "") << "\n";
  o << "  ],\n  \"notes\": [";
  for (std::size_t k = 0; k < r.notes.size(); ++k) o << (k ? ", " : "") << quoted(r.notes[k]);
  o << "]\n}\n";
  return o.str();
}

// --- What an engineer takes away: the corrected plant, the HTML report --------

void write_products(const Args& args, const std::string& plant_path, const std::string& data_path,
                    const PlantModel& plant, const diagnosis::Problem& problem, const GrangerMonitor& monitor,
                    const RecordVerdict& verdict, const diagnosis::Result& result, const DetectorTrace& trace,
                    const diagnosis::Settings& settings) {
  const auto plant_out = args.get("write-plant"), html_out = args.get("html");
  if (!plant_out && !html_out) return;
  const std::vector<std::string> inputs{plant_path, data_path};
  const CorrectedPlant corrected = apply_findings(plant, result);
  if (plant_out) {
    const std::string yaml = plant_yaml(corrected, plant_path, data_path);
    config::parse_plant(yaml, *plant_out);  // what we write must read back
    write_text_file(*plant_out, yaml, inputs);
    if (!g_quiet) std::fprintf(stderr, "mpm diagnose: corrected plant written to %s\n", plant_out->c_str());
  }
  if (html_out) {
    write_text_file(*html_out, report_html({plant, corrected, problem, monitor, verdict, result, plant_path, data_path, &trace, settings}),
                    inputs);
    if (!g_quiet) std::fprintf(stderr, "mpm diagnose: HTML report written to %s\n", html_out->c_str());
  }
}

// --- Problem set-up ----------------------------------------------------------

int run(int argc, char** argv) {
  static const std::string usage = kUsage + flags_usage(setting_rows(), true) + kUsageTail;
  const auto valued = with_limit_flags(with_flags(setting_rows(), {"plant", "data", "json", "write-plant", "html", "channel"}));
  return run_command("mpm diagnose", usage.c_str(), argc, argv, valued, {"quiet", "verbose"}, [&](const Args& args) {
    g_quiet = args.flag("quiet");
    diagnosis::Settings settings;
    apply_flags(args, setting_rows(), settings);
    settings.verbose = args.flag("verbose");
    keep_freed_columns_in_heap();
    const std::string plant_path = args.required("plant");
    const std::string data_path = args.required("data");
    if (const auto out = args.get("json")) config::refuse_input_as_output(*out, {plant_path, data_path});
    const config::Limits limits = limits_from(args);
    const PlantModel plant = config::load_plant(plant_path, limits);
    config::Recording rec = load_data(
        data_path, plant, {args.get("channel").value_or("MPM_SAMPLE"), g_quiet ? "" : "mpm diagnose", limits});
    // The HTML report shows the live detector's statistic over this same run.
    DetectorTrace trace(plant.n_outputs(), args.get("html") ? rec.samples() : 0);
    const RecordDiagnosis d = diagnose_record(
        plant, std::move(rec),
        {.progress = g_quiet ? nullptr : &progress,
         .on_sample = args.get("html") ? trace.callback() : PartSampleCallback{},
         .settings = settings});
    // A header-only or all-NaN record leaves every statistic at its prior
    // (F = 0, p = 1): that is no evidence of a match, so say so instead of
    // printing "mismatch": false.
    if (!d.decided()) {
      std::fprintf(stderr,
                   "mpm diagnose: cannot decide: %llu of %zu samples could be used (rows with "
                   "every input and output finite, after the model settles); the tests need at "
                   "least %llu\n",
                   static_cast<unsigned long long>(d.monitor.counters().used), d.samples,
                   static_cast<unsigned long long>(d.needed));
      // A record shorter than the nominal model takes to settle, whose
      // residual the tool computes from rest: what would decide it.
      // (Integrating channels never settle: the cap, and no hint.)
      constexpr std::size_t kNeverSettles = 10'000'000;
      if (const std::size_t settling = settling_samples(plant, 0.01, kNeverSettles);
          settling < kNeverSettles && d.samples < 2 * settling)
        std::fprintf(stderr,
                     "mpm diagnose: the model takes %zu samples to settle from rest; a record this short "
                     "is decided from its first samples when it carries the controller's prediction of "
                     "every output (sim_<output> columns, docs/formats.md section 2)\n",
                     settling);
      return kExitUndecided;
    }

    const std::string json = report_json(plant, d.samples, d.monitor, d.verdict, d.result, settings);
    if (const auto out = args.get("json"))
      config::write_output_file(*out, json);
    else
      config::write_stdout(json);
    write_products(args, plant_path, data_path, plant, d.problem, d.monitor, d.verdict, d.result, trace, settings);
    return 0;
  });
}

const bool registered = register_command({"diagnose", "explain the mismatch in a recording (diagnosis JSON)", &run});

}  // namespace
}  // namespace mpm
