// `mpm bench [--json] [--quick]`: the performance figures of issue 4 (monitor
// update cost from 2x2 to 50x50, the batch fit it replaces, flops and peak
// fraction, allocations, replay throughput, memory, LCM latency), measured on
// this machine by bench/ (mpm_bench_lib).
#include <cstdio>
#include <string>

#include "daemon/args.hpp"
#include "daemon/command.hpp"
#ifdef MPM_HAVE_BENCH_LIB
#include "bench/figures.hpp"
#endif

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm bench [--json] [--quick]\n"
    "  Measures the monitor on this machine and prints one table of figures.\n"
    "options:\n"
    "  --json    print {\"machine\": ..., \"figures\": [{\"name\", \"value\", \"unit\", \"note\"}]}\n"
    "  --quick   shorten every measurement (seconds instead of about a minute; rough numbers)\n";

int run_bench(int argc, char** argv) {
  try {
    const Args args(argc, argv, {}, {"json", "quick", "help"});
    if (args.flag("help")) {
      std::fputs(kUsage, stdout);
      return 0;
    }
#ifdef MPM_HAVE_BENCH_LIB
    bench::BenchOptions options;
    options.quick = args.flag("quick");
    options.progress = [](const std::string& what) { std::fprintf(stderr, "mpm bench: %s\n", what.c_str()); };
    const auto figures = bench::run_all(options);
    const std::string machine = bench::machine_description();
    const std::string out = args.flag("json") ? bench::to_json(machine, figures) : bench::to_table(machine, figures);
    std::fputs(out.c_str(), stdout);
    return 0;
#else
    std::fprintf(stderr, "mpm bench: this mpm was built without the benchmark suite (MPM_BUILD_BENCH=OFF)\n");
    return 1;
#endif
  } catch (const UsageError& e) {
    std::fprintf(stderr, "mpm bench: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpm bench: %s\n", e.what());
    return 1;
  }
}

const bool registered = register_command({"bench", "measure the monitor's speed, memory and latency here", &run_bench});

}  // namespace
}  // namespace mpm
