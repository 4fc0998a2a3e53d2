// The measurement plan of `mpm bench`: which figures, in which order, with how
// many repetitions (full run well under 2 minutes, --quick a smoke test).
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/alloc_counter.hpp"
#include "bench/batch_baseline.hpp"
#include "bench/cpu_clock.hpp"
#include "bench/diagnose_throughput.hpp"
#include "bench/figures.hpp"
#include "bench/flops.hpp"
#include "bench/lcm_latency.hpp"
#include "bench/memory.hpp"
#include "bench/limits.hpp"
#include "bench/replay.hpp"
#include "bench/update_timing.hpp"
#include "bench/workload.hpp"

namespace mpm::bench {
namespace {

struct Size {
  std::size_t n;           // n inputs x n outputs
  std::size_t per_repeat;  // timed updates per repeat
  std::size_t repeats;
};

// printf into a string of the length it takes; the attribute has the
// compiler check every call's arguments against its format.
[[gnu::format(printf, 1, 2)]] std::string fmt(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list again;
  va_copy(again, args);
  const int length = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(static_cast<std::size_t>(std::max(length, 0)), '\0');
  std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

std::string tag(std::size_t n) { return std::to_string(n) + "x" + std::to_string(n); }

class Plan {
 public:
  explicit Plan(const BenchOptions& o) : o_(o) {}
  void say(const std::string& what) const {
    if (o_.progress) o_.progress(what);
  }
  void add(std::string name, std::optional<double> value, std::string unit, std::string note) {
    figures.push_back({std::move(name), value, std::move(unit), std::move(note)});
  }
  bool quick() const { return o_.quick; }
  std::vector<Figure> figures;

 private:
  const BenchOptions& o_;
};

// The real mpmd, started and fed samples over LCM (bench/memory.hpp). First,
// while this process is still small: the forked child starts as a copy of it.
void memory_figures(Plan& plan) {
  std::string why;
  const std::optional<std::string> mpmd = find_mpmd(own_exe_dir(), why);
  std::optional<double> anon_2x2;
  // Samples the monitor must have used (a 50x50 update takes ~50 ms); the
  // first ~120 sent only fill its lags and settle its model filters.
  const std::size_t used_50 = plan.quick() ? 20 : 60;
  for (const auto& [n, used] : {std::pair<std::size_t, std::size_t>{2, 400}, {50, used_50}}) {
    const std::string name = "mpmd_rss_mb_" + tag(n);
    if (!mpmd) {
      plan.add(name, std::nullopt, "MB", why);
      continue;
    }
    plan.say("resident memory of mpmd monitoring a " + tag(n) + " plant (" + *mpmd + ")");
    MpmdRun run;
    run.mpmd = *mpmd;
    run.n = n;
    run.used = used;
    std::string failed;
    const std::optional<MpmdMemory> m = measure_mpmd_memory(run, failed);
    if (!m) {
      plan.add(name, std::nullopt, "MB", failed);
      continue;
    }
    std::string note =
        fmt("VmRSS of mpmd (pid %d, %s) monitoring a %s plant (%s; na=20 nb=10 lambda=0.999, "
            "model-filtered regressors, gamma on) after %zu samples over LCM (%s), all processed (its status: "
            "%zu seen, %zu used by the monitor); VmHWM %.1f MB; RssAnon %.1f MB (heap: monitor, models, "
            "queues, buffers), RssFile %.1f MB (executable, shared libraries); at READY=1, monitor built and "
            "no sample yet: VmRSS %.1f MB",
            static_cast<int>(m->pid), mpmd->c_str(), tag(n).c_str(),
            n == 2 ? "Wood-Berry" : "generated, first order plus dead time per channel", m->samples_sent,
            m->url.c_str(), m->samples_seen, m->samples_used, m->hwm_mb, m->anon_mb, m->file_mb, m->ready_rss_mb);
    if (anon_2x2) {
      note += fmt("; what grows with the plant (monitor, models): about %.1f MB (RssAnon minus the 2x2 run's)",
                  m->anon_mb - *anon_2x2);
    }
    if (n == 2) anon_2x2 = m->anon_mb;
    plan.add(name, m->rss_mb, "MB", note);
  }
}

void update_figures(Plan& plan, const PeakRate& peak, std::int64_t& allocations, std::size_t& updates) {
  const std::vector<Size> sizes = plan.quick()
      ? std::vector<Size>{{2, 300, 3}, {4, 50, 3}, {20, 2, 1}, {50, 1, 1}}
      : std::vector<Size>{{2, 3000, 7}, {4, 500, 7}, {20, 4, 5}, {50, 2, 5}};
  const MonitorSettings s = paper_settings();
  for (const Size& size : sizes) {
    plan.say("GrangerMonitor::update at " + tag(size.n));
    const UpdateTiming t = time_updates(size.n, size.n, size.per_repeat, size.repeats);
    allocations += t.allocations;
    updates += t.updates;
    plan.add("update_ns_" + tag(size.n), t.ns_per_update, "ns",
             fmt("thread CPU time, median of %.0f repeats of %.0f updates (fastest %.0f ns); na=20 nb=10 lambda=0.999, all statistics "
                 "and gamma",
                 static_cast<double>(size.repeats), static_cast<double>(size.per_repeat), t.ns_min));
    if (size.n == 2) {
      const UpdateTiming live = time_updates(2, 2, size.per_repeat, size.repeats, Reads::kAlarmsOnly);
      allocations += live.allocations;
      updates += live.updates;
      plan.add("update_ns_2x2_alarms_only", live.ns_per_update, "ns",
               fmt("as update_ns_2x2, reading only the alarm flags after each update as mpmd does per sample "
                   "(the statistics are computed when read); fastest %.0f ns",
                   live.ns_min));
    }
    const MonitorFlops f = monitor_flops(size.n, size.n, s);
    plan.add("flops_per_update_" + tag(size.n), f.total(), "flop",
             fmt("analytic (bench/flops.hpp): multiply and add counted separately (FMA = 2), sqrt, divide, log 1 "
                 "each; %.0f%% full-model RLS, %.0f%% pairwise RLS, %.0f%% conditional RSS",
                 100.0 * f.full_updates / f.total(), 100.0 * f.pairwise_updates / f.total(),
                 100.0 * f.conditional / f.total()));
    const double rate = f.total() / (t.ns_per_update * 1e-9);
    plan.add("peak_fraction_" + tag(size.n), rate / peak.flops_per_s, "",
             fmt("%.2f GFLOP/s achieved (flops_per_update / update_ns; FMA = 2 flops) / %.1f GFLOP/s measured "
                 "single-core peak (same convention)",
                 rate * 1e-9, peak.flops_per_s * 1e-9));
  }
}

// What bounds the update from below (bench/limits.hpp), beside the update
// times measured above: the dependent chain of rotations at 2x2, the bytes
// of state streamed at 50x50.
void limit_figures(Plan& plan) {
  const MonitorSettings s = paper_settings();
  const auto measured = [&](const std::string& name) -> std::optional<double> {
    for (const Figure& f : plan.figures)
      if (f.name == name) return f.value;
    return std::nullopt;
  };
  plan.say("latency of one rotation step (the dependent division)");
  const double step_ns = measure_rotation_step_ns(plan.quick() ? 0.02 : 0.2);
  const std::size_t chain = rotation_chain_length(2, s);
  plan.add("rotation_step_ns", step_ns, "ns",
           "measured: dependent chain w <- (w f) / (f + w c), the part of a square-root-free rotation the next one "
           "waits on (a multiply-add, a division, a product)");
  const auto update_2x2 = measured("update_ns_2x2");
  plan.add("latency_floor_ns_2x2", static_cast<double>(chain) * step_ns, "ns",
           fmt("%.0f dependent rotations per output (the rows of [1, AR], then the inputs' factor) x rotation_step_ns; "
               "the two outputs' chains overlap, everything else must hide under them (update_ns_2x2 = %.2f x this)",
               static_cast<double>(chain), update_2x2 ? *update_2x2 / (static_cast<double>(chain) * step_ns) : 0.0));

  const double state = state_bytes_per_update(50, 50, s);
  plan.add("state_mb_per_update_50x50", state / (1024.0 * 1024.0), "MB",
           "analytic (bench/limits.hpp): factor storage one update reads and writes back, triangles where only "
           "triangles are touched");
  plan.say("streaming rate over a working set of that size");
  const StreamRate stream = measure_stream_rate(state, plan.quick() ? 0.05 : 0.5);
  plan.add("stream_gb_per_s", stream.bytes_per_s * 1e-9, "GB/s",
           fmt("measured: read-modify-write passes over %.0f MB (2 reads + 1 write per element), one thread, best pass",
               stream.working_set / (1024.0 * 1024.0)));
  const auto update_50 = measured("update_ns_50x50");
  // The same work without the memory traffic: one output of a 50-input
  // monitor (its factors, a few MB, stay in cache from one update to the
  // next), times 50.
  plan.say("GrangerMonitor::update at 50 inputs x 1 output (its factors warm in cache)");
  const UpdateTiming warm = time_updates(50, 1, plan.quick() ? 5 : 40, plan.quick() ? 1 : 5);
  const double warm_ms = 50.0 * warm.ns_per_update * 1e-6;
  plan.add("warm_output_ms_50x50", warm_ms, "ms",
           fmt("50 x the update of a 50-input, 1-output monitor (median of repeats; its factors stay in cache): "
               "the 50x50 update's computation without its memory traffic (update_ns_50x50 = %.2f x this)",
               update_50 ? *update_50 * 1e-6 / warm_ms : 0.0));
  const double floor_ms = 2.0 * state / stream.bytes_per_s * 1e3;
  plan.add("memory_floor_ms_50x50", floor_ms, "ms",
           fmt("2 x state_mb_per_update_50x50 / stream_gb_per_s: the time to read and write the state once "
               "(update_ns_50x50 = %.2f x this)",
               update_50 ? *update_50 * 1e-6 / floor_ms : 0.0));
}

void batch_figures(Plan& plan) {
  plan.say("sliding-window batch QR at 2x2 (window 2000)");
  const MonitorSettings s = paper_settings();
  constexpr std::size_t kWindow = 2000;
  const Workload w = make_workload(2, 2, kWindow + 600, 3);
  SlidingWindowBatch batch(w, s.ar_order, s.input_order, kWindow);
  const std::size_t n = plan.quick() ? 3 : 20;
  volatile double sink = batch.update(0);  // first call sizes the QR storage
  const double start = thread_cpu_seconds();
  for (std::size_t k = 1; k <= n; ++k) sink = sink + batch.update(k);
  const double ns = (thread_cpu_seconds() - start) * 1e9 / static_cast<double>(n);
  plan.add("batch_ns_2x2", ns, "ns",
           fmt("Householder QR of [X y] over the last 2000 samples, %.0f fits per sample (full, without each "
               "input, AR-only, pairwise), thread CPU time, mean of %.0f samples",
               static_cast<double>(batch.fits_per_update()), static_cast<double>(n)));
  double update_ns = 0.0;
  for (const Figure& f : plan.figures)
    if (f.name == "update_ns_2x2" && f.value) update_ns = *f.value;
  plan.add("batch_ratio_2x2", update_ns > 0.0 ? std::optional<double>(ns / update_ns) : std::nullopt, "x",
           "batch_ns_2x2 / update_ns_2x2, same run");
}

void replay_figure(Plan& plan, std::int64_t& allocations, std::size_t& updates) {
  const std::size_t samples = plan.quick() ? 20000 : 1000000;
  plan.say("offline replay of " + std::to_string(samples) + " Wood-Berry samples");
  const ReplayResult r = measure_replay(samples);
  allocations += r.allocations;
  updates += r.samples;
  plan.add("replay_samples_per_s_2x2", r.parallel_samples_per_s, "samples/s",
           fmt("%.0f-sample recording in memory (Wood-Berry, built-in plant) replayed as `mpm monitor` does: "
               "ResidualGenerator, then GrangerMonitor (na=20 nb=10 lambda=0.999, gamma on) with the outputs "
               "split over %.0f threads, wall-clock time, median of 3 runs (%.0f, %.0f, %.0f); statistics ",
               static_cast<double>(samples), static_cast<double>(r.threads), r.parallel_runs[0], r.parallel_runs[1],
               r.parallel_runs[2]) +
               (r.parallel_identical ? "identical to the one-thread replay's" : "DIFFERENT FROM the one-thread replay's"));
  plan.add("replay_samples_per_s_2x2_one_thread", r.samples_per_s, "samples/s",
           "the same replay on one thread (residual and monitor per sample), thread CPU time");
}

// `mpm diagnose` end to end on a recording with a planted mismatch: only a
// diagnosis that names the planted channel gives a figure.
void diagnose_figure(Plan& plan) {
  const std::size_t samples = plan.quick() ? 3000 : 1000000;
  const std::size_t repeats = plan.quick() ? 1 : 3;
  plan.say("mpm diagnose pipeline on " + std::to_string(samples) + " closed-loop Wood-Berry samples");
  const std::string name = "diagnose_samples_per_s_2x2";
  std::string why;
  const std::optional<DiagnoseThroughput> d = measure_diagnose(samples, repeats, why);
  if (!d) {
    plan.add(name, std::nullopt, "samples/s", why);
    return;
  }
  const std::string note =
      fmt("%zu-sample closed-loop recording of scenario %s (seed 1; built-in wood-berry.yaml) written to "
          "temporary files, then diagnosed as `mpm diagnose --quiet` does, in this process by the command's "
          "own pipeline (daemon/offline.hpp diagnose_record, with the command's heap settings): load and "
          "parse plant YAML and CSV, bind, residuals, Granger monitor (forgetting 1) over %zu threads, "
          "family-wise verdict, structured hypotheses (core/diagnosis.hpp, generators on every core); JSON report "
          "not timed; wall-clock, "
          "median of %zu runs (fastest %.0f samples/s; %.2f s wall, %.2f s process CPU)",
          d->samples, d->scenario.c_str(), d->threads, d->repeats, d->fastest_samples_per_s, d->wall_seconds,
          d->cpu_seconds);
  if (!d->found_planted) {
    plan.add(name, std::nullopt, "samples/s",
             "the diagnosis did not name the planted channel " + d->planted + " (found: " + d->findings +
                 "), so its time is no figure; it ran at " + fmt("%.0f", d->samples_per_s) + " samples/s. " + note);
    return;
  }
  plan.add(name, d->samples_per_s, "samples/s",
           note + "; the diagnosis named the planted channel " + d->planted + ": " + d->findings);
  plan.add("diagnose_peak_rss_mb_2x2", d->peak_rss_mb, "MB",
           std::to_string(d->samples) + "-sample recording as above: " + d->rss_note);
}

void lcm_figures(Plan& plan) {
  const std::size_t messages = plan.quick() ? 100 : 2000;
  plan.say("LCM loopback latency (" + std::to_string(messages) + " messages)");
  std::string why;
  const auto l = measure_lcm_latency(messages, why);
  if (!l) {
    plan.add("lcm_latency_p50_us", std::nullopt, "us", why);
    plan.add("lcm_latency_p99_us", std::nullopt, "us", why);
    return;
  }
  const std::string note = fmt("udpm ttl=0, 256-byte messages, publish in one thread to receive in another, "
                               "one in flight; %.0f timed, %.0f lost",
                               static_cast<double>(l->messages), static_cast<double>(l->lost));
  plan.add("lcm_latency_p50_us", l->p50_us, "us", note);
  plan.add("lcm_latency_p99_us", l->p99_us, "us", note);
}

}  // namespace

std::vector<Figure> run_all(const BenchOptions& options) {
  Plan plan(options);
  memory_figures(plan);

  plan.say("FMA throughput (peak)");
  const PeakRate peak = measure_peak(options.quick ? 0.02 : 0.2);
  plan.add("peak_gflops", peak.flops_per_s * 1e-9, "GFLOP/s", "measured: " + peak.how + ", one thread");

  std::int64_t allocations = 0;
  std::size_t updates = 0;
  update_figures(plan, peak, allocations, updates);
  limit_figures(plan);
  batch_figures(plan);
  replay_figure(plan, allocations, updates);
  diagnose_figure(plan);
  plan.add("allocations_per_update", static_cast<double>(allocations) / static_cast<double>(updates), "",
           fmt("%.0f heap allocations over %.0f timed updates and replay samples (operator new",
               static_cast<double>(allocations), static_cast<double>(updates)) +
               (test::counts_malloc() ? " and malloc counted)" : " counted; malloc not: sanitizer build)"));
  lcm_figures(plan);
  return plan.figures;
}

}  // namespace mpm::bench
