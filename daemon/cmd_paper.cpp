// `mpm paper`: the paper's case studies reproduced (Tables 3-6, Sec. 4.2):
// per scenario, our online monitor's verdict with F, p and gamma, beside the
// decussation baseline's verdict and the figures the paper reports.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "config/output_file.hpp"
#include "core/monitor_front_end.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/paper_cases.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm paper [--scenario NAME] [--samples N] [--seed S] [--out DIR]\n"
    "  Simulates the paper's case studies under the MPC, runs the online monitor (conditional\n"
    "  Granger causality, all inputs in the model) and the decussation baseline on the same data,\n"
    "  and prints both verdicts beside the paper's figures. --out DIR keeps each recording as CSV.\n"
    "  Defaults: every case, each at its own record length (3000 samples; 20000 for the\n"
    "  concealed G21 x 1.2), seed 1.\n";

std::string channel_list(const PlantModel& plant, const std::vector<Channel>& cs) {
  if (cs.empty()) return "none";
  std::string s;
  for (const auto& [o, i] : cs) s += (s.empty() ? "" : ", ") + plant.inputs[i] + "->" + plant.outputs[o];
  return s;
}

void print_case(const PaperCase& pc, const PaperCaseResult& r) {
  const GrangerMonitor& m = r.monitor;
  std::printf("\n== %s (%zu samples)\n", pc.scenario, r.samples);
  std::printf("   truth        : %s%s\n", channel_list(r.plant, pc.truth).c_str(), pc.unstable ? " (unstable loop)" : "");
  std::printf("   paper        : %s\n", pc.paper_result);
  if (r.diverging) {
    std::printf("   mpm          : loop diverging: reported as unstable, not analysed\n");
    return;
  }
  std::printf("   mpm located  : %s\n", channel_list(r.plant, r.located).c_str());
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    std::printf("     %-7s joint p=%.1e%s", r.plant.outputs[j].c_str(), m.joint_p_value(m.loop(j).lr_joint),
                m.loop(j).lr_joint > m.joint_raise_threshold() ? "*" : " ");
    for (std::size_t i = 0; i < m.n_inputs(); ++i) {
      const ChannelStats& c = m.channel(j, i);
      std::printf("  %s: F=%.4f p=%.1e g=%.4f%s", r.plant.inputs[i].c_str(), c.f_pairwise,
                  m.p_value(c.lr_conditional), c.gamma,
                  c.lr_conditional > m.raise_threshold() ? "*" : r.by_gamma[j * m.n_inputs() + i] ? "(g)" : "");
    }
    std::printf("\n");
  }
  const auto& d = r.decussation;
  std::printf("   decussation  : %s   MQI (", channel_list(r.plant, d.located).c_str());
  for (Eigen::Index j = 0; j < d.mqi.size(); ++j) std::printf("%s%.4f", j ? ", " : "", d.mqi[j]);
  std::printf(")\n");
  const bool ours_right = r.located == pc.truth;
  const bool theirs_right = d.located == pc.truth;
  std::printf("   verdict      : mpm %s, decussation %s\n", ours_right ? "correct" : "WRONG",
              theirs_right ? "correct" : "wrong");
}

int run(int argc, char** argv) {
  return run_command("mpm paper", kUsage, argc, argv, {"scenario", "samples", "seed", "out", "input-order", "ar-order"}, {}, [&](const Args& args) {
    const int samples_override = args.integer("samples", 0);
    const auto seed = static_cast<std::uint64_t>(args.integer("seed", 1));
    const std::string only = args.get("scenario").value_or("");
    const std::string out_dir = args.get("out").value_or("");
    if (!out_dir.empty()) std::filesystem::create_directories(out_dir);  // throws, naming it, when it cannot
    MonitorSettings settings;  // whole record (lambda = 1)
    settings.input_order = args.integer("input-order", settings.input_order);
    settings.ar_order = args.integer("ar-order", settings.ar_order);
    settings.forgetting = kRecordForgetting;
    std::printf("mpm paper: online monitor na=%d nb=%d, conditional LR test at alpha=%g per channel "
                "(* = significant, (g) = located by gamma); F = paper's pairwise index, g = gamma (noise-model index)\n",
                settings.ar_order, settings.input_order, settings.false_alarm);
    int ours = 0, theirs = 0, n = 0;
    for (const PaperCase& pc : paper_cases()) {
      if (!only.empty() && only != pc.scenario) continue;
      std::fprintf(stderr, "mpm paper: simulating %s ...\n", pc.scenario);
      const std::string csv = out_dir.empty() ? "" : out_dir + "/" + pc.scenario + ".csv";
      const std::size_t samples = samples_override > 0 ? static_cast<std::size_t>(samples_override) : pc.samples;
      const PaperCaseResult r = run_paper_case(pc.scenario, seed, samples, settings, csv);
      print_case(pc, r);
      ++n;
      if (pc.unstable) {
        ours += r.diverging;
        continue;
      }
      ours += !r.diverging && r.located == pc.truth;
      theirs += r.decussation.located == pc.truth;
    }
    if (n == 0) throw UsageError("no paper case named '" + only + "'");
    std::printf("\nsummary: mpm right on %d/%d cases; decussation right on %d/%d analysable cases\n", ours, n, theirs,
                n - (only.empty() ? 1 : 0));
    config::write_stdout("");  // flushes; a failed write of the report is an error
    return 0;
  });
}

const bool registered = register_command({"paper", "reproduce the paper's case studies, beside decussation", &run});

}  // namespace
}  // namespace mpm
