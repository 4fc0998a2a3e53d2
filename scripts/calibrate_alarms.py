#!/usr/bin/env python3
"""Full calibration of the live alarm path (issue 11): no-mismatch closed loops
of Wood-Berry, the 3x3 and the quadruple tank (mpm simulate --scenario
plant-nominal), each replayed through the live monitor (mpm monitor --events,
mpmd's forgetting 0.999; both live detectors: the sequential detector and the
periodic diagnosis scan, which share the stated rate half and half) at a stated
rate high enough to observe (default one false alarm per 2e4 samples per
controller). Prints, per plant and in all, raises against the stated count with
a 95 % Poisson interval, the raises of each detector, and the split between the
first and second half of the runs (flat in time). --partial FILE rewrites the
table there after every run (a long run that is stopped still leaves its figures).

usage: scripts/calibrate_alarms.py [--mpm build/daemon/mpm] [--runs 500]
                                   [--samples 10000] [--per-alarm 2e4] [--seed 1]
"""
import argparse, json, math, os, subprocess, sys, tempfile

PLANTS = ["wood-berry.yaml", "three-by-three.yaml", "quad-tank.yaml"]
SECONDS_PER_YEAR = 365.25 * 86400


def poisson_cdf(k, mu):
    term, total = math.exp(-mu), 0.0
    for i in range(k + 1):
        if i:
            term *= mu / i
        total += term
    return total


def poisson_interval(n, level=0.95):
    a = (1 - level) / 2

    def solve(f, lo, hi):
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if f(mid) else (lo, mid)
        return 0.5 * (lo + hi)

    lower = 0.0 if n == 0 else solve(lambda mu: 1 - poisson_cdf(n - 1, mu) < a, 0.0, n + 10 * math.sqrt(n) + 10)
    upper = solve(lambda mu: poisson_cdf(n, mu) > a, 0.0, n + 10 * math.sqrt(n) + 20)
    return lower, upper


def sample_time(path):
    for line in open(path):
        if line.startswith("sample_time:"):
            return float(line.split(":")[1].split("#")[0])
    return 1.0


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    ap = argparse.ArgumentParser()
    ap.add_argument("--mpm", default=os.path.join(root, "build", "daemon", "mpm"))
    ap.add_argument("--runs", type=int, default=500, help="runs in all, split over the plants")
    ap.add_argument("--samples", type=int, default=10000)
    ap.add_argument("--per-alarm", type=float, default=2e4, help="stated samples per false alarm")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--plants", default=",".join(PLANTS), help="comma-separated plant files in config/")
    ap.add_argument("--partial", help="rewrite the table in this file after every run")
    args = ap.parse_args()
    plants = args.plants.split(",")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        csv = os.path.join(tmp, "run.csv")
        for p_index, plant_file in enumerate(plants):
            plant = os.path.join(root, "config", plant_file)
            rate = SECONDS_PER_YEAR / (args.per_alarm * sample_time(plant))
            runs = args.runs // len(plants) + (1 if p_index < args.runs % len(plants) else 0)
            raises = first = monitored = by_scan = 0
            rows.append(None)
            for r in range(runs):
                seed = args.seed + 1000 * p_index + r
                subprocess.run([args.mpm, "simulate", "--scenario", "plant-nominal", "--plant", plant, "--samples",
                                str(args.samples), "--seed", str(seed), "--out", csv], check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                out = subprocess.run([args.mpm, "monitor", "--plant", plant, "--data", csv, "--forgetting", "0.999",
                                      "--events", "--false-alarms-per-year", repr(rate)], check=True,
                                     capture_output=True, text=True).stdout
                summary = json.loads(subprocess.run([args.mpm, "monitor", "--plant", plant, "--data", csv,
                                                     "--forgetting", "0.999", "--json", "--threads", "1",
                                                     "--false-alarms-per-year", repr(rate)],
                                                    check=True, capture_output=True, text=True).stdout)
                used = summary["counters"]["used"]
                monitored += used
                for line in out.splitlines():
                    e = json.loads(line)
                    if e["event"] == "raised":
                        raises += 1
                        by_scan += e.get("detector") == "scan"
                        first += e["sample"] < args.samples / 2
                os.unlink(csv)
                rows[-1] = (plant_file, r + 1, monitored, raises, first, by_scan)
                print(f"\r{plant_file}: run {r + 1}/{runs}, {raises} raises", end="", file=sys.stderr, flush=True)
                if args.partial:
                    with open(args.partial, "w") as f:
                        f.write(table(rows, args) + "\n")
            print(file=sys.stderr)
    print(table(rows, args))


def table(rows, args):
    rows = [r for r in rows if r]
    lines = [f"stated: one false alarm per {args.per_alarm:g} samples per controller; {args.samples} samples per run",
             f"{'plant':22s} {'runs':>5s} {'samples':>10s} {'raises':>7s} {'scan':>5s} {'stated':>8s} {'ratio':>6s} "
             f"{'95% CI':>13s} {'1st/2nd half':>13s}"]
    total = ("all",) + tuple(sum(r[c] for r in rows) for c in range(1, 6))
    for name, runs, n, k, first, scan in rows + [total]:
        expected = max(n, 1) / args.per_alarm
        lo, hi = poisson_interval(k)
        lines.append(f"{name:22s} {runs:5d} {n:10d} {k:7d} {scan:5d} {expected:8.1f} {k / expected:6.2f} "
                     f"{lo / expected:6.2f}-{hi / expected:<6.2f} {first:6d}/{k - first:<6d}")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
