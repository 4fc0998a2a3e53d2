// `mpm-bench [--json] [--quick]` (also run as `mpm bench`, which execs this
// program): the performance figures of issue 4 (monitor update cost from
// 2x2 to 50x50, the batch fit it replaces, flops and peak fraction,
// allocations, replay throughput, memory, LCM latency), measured on this
// machine by bench/ (mpm_bench_lib). A program of its own so that nothing of
// the bench, its malloc-counting allocator least of all, is in `mpm` or `mpmd`.
// `mpm-bench --soak N`: the soak of issue 12 (bench/soak.hpp) instead, N
// samples through mpmd's real service.
#include <cstdio>
#include <string>

#include "bench/figures.hpp"
#include "daemon/args.hpp"
#include "daemon/series_allocator.hpp"
#ifdef MPM_BENCH_HAVE_SOAK
#include "bench/soak.hpp"
#endif

namespace {

constexpr const char* kUsage =
    "usage: mpm-bench [--json] [--quick]   (or: mpm bench ...)\n"
    "       mpm-bench --soak N [--seed S]\n"
    "  Measures the monitor on this machine and prints one table of figures.\n"
    "options:\n"
    "  --json    print {\"machine\": ..., \"figures\": [{\"name\", \"value\", \"unit\", \"note\"}]}\n"
    "  --quick   shorten every measurement (seconds instead of about a minute; rough numbers)\n"
    "  --soak N  instead, feed N samples (e.g. 1e8, as scripts/soak.sh does; about 5 s of CPU per 10^6)\n"
    "            of matched and mismatched stretches, gaps, NaN bursts, outliers, frozen inputs and\n"
    "            values x 1e8 and x 1e-8 through mpmd's service; prints samples soaked, faults injected,\n"
    "            the largest deviation from a batch fit and the resident memory growth; exit 1 when a\n"
    "            check failed\n";

#ifdef MPM_BENCH_HAVE_SOAK
// Prints the soak's figures; 0 when every check held (bench/soak.hpp).
int print_soak(const mpm::bench::SoakReport& r) {
  const mpm::bench::SoakFaults& f = r.faults;
  int mismatched = 0, found = 0, raised_clean = 0, raised_disturbed = 0, standing = 0, blind = 0;
  for (const mpm::bench::SoakStretch& s : r.stretches) {
    mismatched += s.mismatched ? 1 : 0;
    found += s.mismatched && s.raises_true > 0 ? 1 : 0;
    raised_clean += s.raises_other;
    raised_disturbed += s.raises_disturbed;
    standing += !s.mismatched && s.raised_at_end ? 1 : 0;
    blind += s.diverging_at_end ? 1 : 0;
  }
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::printf("samples soaked          %llu (%llu delivered to the service, %llu used by the monitor), %zu stretches, %.1f s\n",
              u(r.samples), u(r.delivered), u(r.used), r.stretches.size(), r.seconds);
  std::printf("faults injected         %llu events: %llu gaps (%llu samples missing), %llu NaN bursts (%llu samples), "
              "%llu outliers (%llu of 1e100), %llu disturbed stretches (%llu mismatched, %llu frozen, %llu x1e8, "
              "%llu x1e-8 samples)\n",
              u(f.events()), u(f.gap_events), u(f.missing), u(f.nan_bursts), u(f.nan_samples), u(f.outliers),
              u(f.outliers_1e100), u(f.stretches), u(f.mismatched), u(f.frozen), u(f.huge), u(f.tiny));
  std::printf("service counted         %llu gaps, %llu missing, %llu NaN samples, %llu outliers skipped, %llu output "
              "restarts, %llu raises, %llu log lines\n",
              u(r.service_gaps), u(r.service_missing), u(r.service_nan), u(r.monitor_outliers), u(r.monitor_resets),
              u(r.monitor_raises), u(r.log_lines));
  std::printf("max deviation from batch %.3g (%llu checks, at the end of every stretch, both outputs)\n",
              r.max_deviation, u(r.checks));
  std::printf("non-finite statistics   %llu (every sample; %llu status messages)\n", u(r.nonfinite), u(r.statuses));
  std::printf("alarms                  %d of %d mismatched stretches raised u1 -> y2; %d raises on clean matched "
              "data; %d still raised at the end of a matched stretch; %d outputs blind (diverging) at a stretch end; "
              "%d raises while disturbed data came\n",
              found, mismatched, raised_clean, standing, blind, raised_disturbed);
  // Where raises on clean data came: the stretch's kind, how far into it, the channel.
  std::string where;
  for (const mpm::bench::SoakStretch& s : r.stretches) {
    if (s.raises_other == 0) continue;
    char one[96];
    std::snprintf(one, sizeof one, "%s%s+%lld (y%d<-u%d, %d)", where.empty() ? "" : ", ", mpm::bench::soak_kind_name(s.kind),
                  static_cast<long long>(s.first_clean_raise), s.first_clean_output + 1, s.first_clean_input + 1,
                  s.raises_other);
    where += one;
  }
  if (!where.empty()) std::printf("clean-data raises at     %s\n", where.c_str());
  std::printf("resident memory         %.0f kB after the first stretch, max growth %.0f kB after it\n",
              r.rss_first_kb, r.rss_max_growth_kb);
  const bool ok = r.nonfinite == 0 && r.max_deviation <= 1e-6 && found == mismatched && raised_clean == 0 &&
                  standing == 0 && blind == 0;
  std::printf("%s\n", ok ? "soak held" : "SOAK FAILED a check");
  return ok ? 0 : 1;
}
#endif


}  // namespace

int main(int argc, char** argv) {
  using namespace mpm;
  return run_command("mpm bench", kUsage, argc, argv, {"soak", "seed"}, {"json", "quick"}, [](const Args& args) {
    if (args.get("soak")) {
#ifdef MPM_BENCH_HAVE_SOAK
      const double n = args.number("soak", 0.0);
      if (!(n >= 1.0 && n <= 1e12)) throw UsageError("--soak needs a number of samples in [1, 1e12]");
      bench::SoakOptions soak;
      soak.samples = static_cast<std::uint64_t>(n);
      soak.seed = static_cast<std::uint64_t>(args.number("seed", 1.0));
      soak.progress = [](std::uint64_t done, std::uint64_t total) {
        if (done % 1'000'000 < 25'000 || done == total)
          std::fprintf(stderr, "mpm bench: soaked %llu of %llu samples\n", static_cast<unsigned long long>(done),
                       static_cast<unsigned long long>(total));
      };
      return print_soak(bench::run_soak(soak));
#else
      std::fprintf(stderr, "mpm bench: built without mpmd's service library (MPM_BUILD_TRANSPORTS=OFF): no soak\n");
      return 1;
#endif
    }
    // The heap `mpm diagnose` runs with (daemon/series_allocator.hpp), set
    // before any figure starts a thread: glibc's arena limit binds only the
    // threads started after it, and the diagnose figure times the command's
    // pipeline in this process (set just before that figure, after the
    // replay's threads, the same pipeline took 17.5 s of CPU, 88 k
    // samples/s, against 11.5 s and 155 k set here).
    keep_freed_columns_in_heap();
    bench::BenchOptions options;
    options.quick = args.flag("quick");
    options.progress = [](const std::string& what) { std::fprintf(stderr, "mpm bench: %s\n", what.c_str()); };
    const auto figures = bench::run_all(options);
    const std::string machine = bench::machine_description();
    const std::string out = args.flag("json") ? bench::to_json(machine, figures) : bench::to_table(machine, figures);
    std::fputs(out.c_str(), stdout);
    return 0;
  });
}
