// `mpm-bench [--json] [--quick]` (also run as `mpm bench`, which execs this
// program): the performance figures of issue 4 (monitor update cost from
// 2x2 to 50x50, the batch fit it replaces, flops and peak fraction,
// allocations, replay throughput, memory, LCM latency), measured on this
// machine by bench/ (mpm_bench_lib). A program of its own so that nothing of
// the bench, its malloc-counting allocator least of all, is in `mpm` or `mpmd`.
#include <cstdio>
#include <string>

#include "bench/figures.hpp"
#include "daemon/args.hpp"

namespace {

constexpr const char* kUsage =
    "usage: mpm-bench [--json] [--quick]   (or: mpm bench ...)\n"
    "  Measures the monitor on this machine and prints one table of figures.\n"
    "options:\n"
    "  --json    print {\"machine\": ..., \"figures\": [{\"name\", \"value\", \"unit\", \"note\"}]}\n"
    "  --quick   shorten every measurement (seconds instead of about a minute; rough numbers)\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace mpm;
  try {
    const Args args(argc, argv, {}, {"json", "quick", "help"});
    if (args.flag("help")) {
      std::fputs(kUsage, stdout);
      return 0;
    }
    bench::BenchOptions options;
    options.quick = args.flag("quick");
    options.progress = [](const std::string& what) { std::fprintf(stderr, "mpm bench: %s\n", what.c_str()); };
    const auto figures = bench::run_all(options);
    const std::string machine = bench::machine_description();
    const std::string out = args.flag("json") ? bench::to_json(machine, figures) : bench::to_table(machine, figures);
    std::fputs(out.c_str(), stdout);
    return 0;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "mpm bench: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpm bench: %s\n", e.what());
    return 1;
  }
}
