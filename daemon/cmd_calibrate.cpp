// `mpm calibrate`: the live detector's thresholds for one plant, by Monte
// Carlo under "no mismatch" with the plant's own closed loop (sim scenario
// plant-nominal). Each window's crossing-rate constant is refitted from its
// excursions at moderate levels (where they are frequent enough to count)
// and its threshold re-solved for the stated rate; the result is a
// `monitor:` block mpmd.yaml can take as it is.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "core/chi_square.hpp"
#include "daemon/args.hpp"
#include "daemon/calibration.hpp"
#include "daemon/command.hpp"
#include "daemon/offline.hpp"
#include "daemon/setting_flags.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm calibrate --plant PLANT.yaml [--runs N] [--samples N] [--seed S] [--out FILE]\n"
    "  Simulates N no-mismatch closed loops of the plant (MPC tuned from the model, as\n"
    "  `mpm simulate --scenario plant-nominal`), runs the live monitor on each, refits each\n"
    "  detector window's crossing-rate constant from its excursions at moderate levels and\n"
    "  prints (or writes to FILE, never over an existing file) the per-window thresholds for\n"
    "  the stated false-alarm rate as a monitor: block for mpmd.yaml. Progress on stderr.\n"
    "options:\n"
    "  --runs N                   closed-loop runs (default 40)\n"
    "  --samples N                samples per run (default 40000)\n"
    "  --seed S                   first seed (default 1; run r uses S + r)\n"
    "monitor settings, as in mpmd.yaml (defaults mpmd's):\n";

// The monitor settings calibrate takes: those its thresholds depend on.
const std::vector<FieldRow<MonitorSettings>>& setting_rows() {
  static const auto rows =
      only(MonitorSettings::fields(), {"ar_order", "input_order", "forgetting", "false_alarms_per_year"});
  return rows;
}

int run(int argc, char** argv) {
  static const std::string usage = kUsage + flags_usage(setting_rows());
  return run_command("mpm calibrate", usage.c_str(), argc, argv,
                     with_flags(setting_rows(), {"plant", "runs", "samples", "seed", "out"}), {},
                     [&](const Args& args) {
    const std::string plant_path = args.required("plant");
    const PlantModel plant = config::load_plant(plant_path);
    MonitorSettings settings;
    apply_flags(args, setting_rows(), settings);
    if (const std::string e = settings.validate(); !e.empty()) throw UsageError(e);
    const int runs = args.integer("runs", 40);
    const int samples = args.integer("samples", 40000);
    const int seed = args.integer("seed", 1);
    if (runs < 1 || samples < 1000) throw UsageError("--runs must be >= 1 and --samples >= 1000");
    const std::string out = args.get("out").value_or("");
    if (!out.empty() && std::filesystem::exists(out))
      throw UsageError("--out " + out + " exists: calibrate never overwrites a file");

    const GrangerMonitor shape = MonitorBlueprint(plant, settings).build();
    const SequentialDetector& det = shape.detector();
    const double d = static_cast<double>(det.dof());
    std::vector<std::vector<double>> levels(det.windows());
    for (auto& l : levels)
      for (double tail : {1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5}) l.push_back(chi_square_quantile_upper(tail, d));
    std::vector<std::vector<std::size_t>> total(det.windows(), std::vector<std::size_t>(levels[0].size(), 0));
    std::size_t monitored = 0, raises = 0, first_half = 0;
    for (int r = 0; r < runs; ++r) {
      const NullRun run = null_alarm_run(plant, settings, static_cast<std::uint64_t>(seed + r),
                                         static_cast<std::size_t>(samples), levels);
      monitored += run.samples;
      raises += run.raises.size();
      for (std::size_t k : run.raises) first_half += k < run.samples / 2 ? 1 : 0;
      for (std::size_t k = 0; k < total.size(); ++k)
        for (std::size_t l = 0; l < total[k].size(); ++l) total[k][l] += run.excursions[k][l];
      std::fprintf(stderr, "\rmpm calibrate: run %d/%d (%zu samples, %zu raises at the built-in thresholds)", r + 1,
                   runs, monitored, raises);
    }
    std::fprintf(stderr, "\n");
    const double output_samples = static_cast<double>(monitored * plant.n_outputs());
    const Calibration c = fit_thresholds(shape, levels, total, output_samples, 20);

    std::string text;
    char line[512];
    std::snprintf(line, sizeof line,
                  "# mpm calibrate --plant %s: %d runs x %d samples (seeds %d..%d), %zu monitored samples;\n"
                  "# stated %g false alarms per year at %g s per sample; %zu raises at the built-in thresholds\n"
                  "# (%.3g per year).\n",
                  plant_path.c_str(), runs, samples, seed, seed + runs - 1, monitored,
                  settings.detector.false_alarms_per_year, plant.sample_time, raises,
                  static_cast<double>(raises) / static_cast<double>(monitored) / plant.sample_time * 365.25 * 86400.0);
    text += line;
    {
      // Against the stated count, with an exact 95 % Poisson interval, and
      // split by half-run: flat in time means about as many in each half.
      const double stated = settings.detector.false_alarms_per_year * plant.sample_time / (365.25 * 86400.0) *
                            static_cast<double>(monitored);
      const auto n = static_cast<double>(raises);
      const double lo = raises == 0 ? 0.0 : 0.5 * chi_square_quantile_upper(0.975, 2.0 * n);
      const double hi = 0.5 * chi_square_quantile_upper(0.025, 2.0 * n + 2.0);
      std::snprintf(line, sizeof line,
                    "# raises %zu against %.1f stated: %.2f x (95%% CI %.2f..%.2f); first half of the runs %zu, second %zu\n",
                    raises, stated, n / stated, lo / stated, hi / stated, first_half, raises - first_half);
      text += line;
    }
    for (std::size_t k = 0; k < det.windows(); ++k) {
      std::snprintf(line, sizeof line, "# window %.0f: constant %.3g from %zu excursions (built-in %.3g), threshold %.2f (built-in %.2f)\n",
                    det.window(k), c.constants[k], c.counts[k], settings.detector.crossing_constant, c.thresholds[k],
                    det.threshold(k));
      text += line;
    }
    text += "monitor:\n  false_alarms_per_year: ";
    std::snprintf(line, sizeof line, "%.17g\n  detector_thresholds: [", settings.detector.false_alarms_per_year);
    text += line;
    for (std::size_t k = 0; k < c.thresholds.size(); ++k) {
      std::snprintf(line, sizeof line, "%s%.6f", k ? ", " : "", c.thresholds[k]);
      text += line;
    }
    text += "]\n";
    if (out.empty()) {
      std::fputs(text.c_str(), stdout);
    } else {
      std::ofstream f(out);
      f << text;
      if (!f.flush()) throw std::runtime_error("cannot write " + out);
    }
    return 0;
  });
}

const bool registered = register_command({"calibrate", "detector thresholds for a plant by Monte Carlo under no mismatch", &run});

}  // namespace
}  // namespace mpm
