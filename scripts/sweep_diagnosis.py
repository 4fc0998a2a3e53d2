#!/usr/bin/env python3
"""How `mpm diagnose` does beyond ../shared/data: the benchmark's case types
on other channels, magnitudes and seeds, simulated with `mpm simulate`.

usage: scripts/sweep_diagnosis.py [--mpm build/daemon/mpm] [--seeds 61,62,63] [--only SUBSTRING]

Each case is a scenario plus --edit specs (or a plant file with a channel the
model lacks) and the findings it must produce: exactly these physics words on
exactly these channels. Prints one line per run and a count; exits 1 when a
run differs (a developer's check, not part of ctest: about 2 s a run).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WB = os.path.join(ROOT, "config", "wood-berry.yaml")
QT = os.path.join(ROOT, "config", "quad-tank.yaml")
TT = os.path.join(ROOT, "config", "three-by-three.yaml")
# The 3x3 under plant-nominal with the excitation of the benchmark's tt_*
# recordings (input moves of 0.2-0.3 per sample).
TIGHT = ["--move-weight-scale", "0.001"]


def wb(name, edits, expect):
    return (name, "wood-berry-nominal", WB, WB, edits, expect)


def tt(name, edits, expect, sim_plant=TT):
    return (name, "plant-nominal", sim_plant, TT, TIGHT + edits, expect)


def edit(*specs):
    out = []
    for s in specs:
        out += ["--edit", s]
    return out


# (name, scenario, plant simulated, plant diagnosed, extra args, expected findings)
CASES = [
    wb("wb nominal", [], set()),
    wb("wb gain g11 x0.75", edit("y1.u1.gain=0.75"), {"gain[y1<-u1]"}),
    wb("wb gain g21 x1.4", edit("y2.u1.gain=1.4"), {"gain[y2<-u1]"}),
    wb("wb gain g22 x0.7", edit("y2.u2.gain=0.7"), {"gain[y2<-u2]"}),
    wb("wb time constant g12 x1.6", edit("y1.u2.time_constant=1.6"), {"time_constant[y1<-u2]"}),
    wb("wb time constant g22 x0.6", edit("y2.u2.time_constant=0.6"), {"time_constant[y2<-u2]"}),
    wb("wb dead time g21 +3", edit("y2.u1.delay=3"), {"dead_time[y2<-u1]"}),
    wb("wb dead time g11 +2", edit("y1.u1.delay=2"), {"dead_time[y1<-u1]"}),
    wb("wb extra lag g22", edit("y2.u2.lag=0.6"), {"unmodeled_dynamics[y2<-u2]"}),
    wb("wb actuator u1", edit("u1.actuator_lag=0.5"), {"actuator_dynamics[y1<-u1,y2<-u1]"}),
    wb("wb saturation u2 upper", edit("u2.upper=0.8"), {"saturation[y1<-u2,y2<-u2]"}),
    wb("wb saturation u1 lower", edit("u1.lower=-0.9"), {"saturation[y1<-u1,y2<-u1]"}),
    wb("wb deadband u1", edit("u1.deadband=0.5"), {"deadband[y1<-u1,y2<-u1]"}),
    wb("wb sensor y2", edit("y2.sensor_lag=0.5"), {"sensor_dynamics[y2<-u1,y2<-u2]"}),
    wb("wb g22 gain + g12 lag", edit("y2.u2.gain=1.3", "y1.u2.lag=0.6"),
       {"gain[y2<-u2]", "unmodeled_dynamics[y1<-u2]"}),
    ("qt nominal", "quad-tank-nominal", QT, QT, [], set()),
    ("qt sensor level2", "quad-tank-nominal", QT, QT, edit("level2.sensor_lag=0.3"),
     {"sensor_dynamics[level2<-pump1,level2<-pump2]"}),
    ("qt actuator pump2", "quad-tank-nominal", QT, QT, edit("pump2.actuator_lag=0.5"),
     {"actuator_dynamics[level1<-pump2,level2<-pump2]"}),
    ("qt wide high", "quad-tank-wide-high", QT, QT, [],
     {"nonlinear_gain[level1<-pump1,level1<-pump2,level2<-pump1,level2<-pump2]"}),
    tt("3x3 nominal", [], set()),
    tt("3x3 dead time y1<-u2 +3", edit("y1.u2.delay=3"), {"dead_time[y1<-u2]"}),
    tt("3x3 gain y2<-u2 x0.7", edit("y2.u2.gain=0.7"), {"gain[y2<-u2]"}),
    tt("3x3 actuator u2", edit("u2.actuator_lag=0.6"), {"actuator_dynamics[y1<-u2,y2<-u2,y3<-u2]"}),
    tt("3x3 sensor y3", edit("y3.sensor_lag=0.6"), {"sensor_dynamics[y3<-u2,y3<-u3]"}),
    # The benchmark's integrator: the slowest pole moved to 1 (pole x 1/p),
    # slope 0.7 K/tau.
    tt("3x3 integrator y3<-u3", edit("y3.u3.pole=1.0951694398533898", "y3.u3.gain=0.7"), {"integrator[y3<-u3]"}),
    tt("3x3 integrator y2<-u3", edit("y2.u3.pole=1.1175190687418637", "y2.u3.gain=0.7"), {"integrator[y2<-u3]"}),
    tt("3x3 missing y1<-u3", [], {"missing_channel[y1<-u3]"}, sim_plant="with y1<-u3"),
]


def plant_with_y1u3(folder):
    """The 3x3 plant file with a channel y1 <- u3 its model lacks."""
    text = open(TT).read()
    anchor = "  - output: y2\n    input: u1\n"
    at = text.index(anchor)
    path = os.path.join(folder, "three-by-three-y1u3.yaml")
    with open(path, "w") as f:
        f.write(text[:at] + "  - output: y1\n    input: u3\n    continuous: {num: [0.3], den: [20, 1], dead_time: 2}\n"
                + text[at:])
    return path


def findings(report):
    out = set()
    for f in report["findings"]:
        chans = ",".join(c["output"] + "<-" + (c.get("input") or f.get("signal") or "-") for c in f["channels"])
        out.add(f["physics"] + "[" + chans + "]")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mpm", default=os.path.join(ROOT, "build", "daemon", "mpm"))
    ap.add_argument("--seeds", default="61,62,63")
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    if not os.access(args.mpm, os.X_OK):
        sys.exit(f"sweep_diagnosis: no mpm binary at {args.mpm} (build first, or give --mpm)")
    seeds = [int(s) for s in args.seeds.split(",") if s]
    right = total = 0
    with tempfile.TemporaryDirectory(prefix="mpm_sweep_") as tmp:
        extra_plant = plant_with_y1u3(tmp)
        for name, scenario, sim_plant, diag_plant, extra, expect in CASES:
            if args.only not in name:
                continue
            if sim_plant == "with y1<-u3":
                sim_plant = extra_plant
            for seed in seeds:
                csv, out = os.path.join(tmp, "run.csv"), os.path.join(tmp, "report.json")
                # The benchmark's lengths: 4000 samples for the wide-range tank
                # (qt_wide_low), 3000 elsewhere.
                samples = "4000" if scenario.startswith("quad-tank-wide") else "3000"
                sim = subprocess.run([args.mpm, "simulate", "--scenario", scenario, "--plant", sim_plant, "--seed",
                                      str(seed), "--samples", samples, "--out", csv] + extra,
                                     capture_output=True, text=True)
                if sim.returncode != 0:
                    sys.exit(f"sweep_diagnosis: {name} seed {seed}: mpm simulate failed: {sim.stderr.strip()}")
                diag = subprocess.run([args.mpm, "diagnose", "--quiet", "--plant", diag_plant, "--data", csv, "--json",
                                       out], capture_output=True, text=True)
                if diag.returncode != 0:
                    sys.exit(f"sweep_diagnosis: {name} seed {seed}: mpm diagnose failed: {diag.stderr.strip()}")
                report = json.load(open(out))
                got = findings(report)
                ok = got == expect and report["mismatch"] == bool(expect)
                right += ok
                total += 1
                print(f"{'ok  ' if ok else 'DIFF'} {name:32s} seed {seed}: {' '.join(sorted(got)) or 'no finding'}"
                      + ("" if ok else f"   (expected {' '.join(sorted(expect)) or 'no finding'})"), flush=True)
    print(f"{right} of {total} runs name exactly the expected findings")
    return 0 if right == total else 1


if __name__ == "__main__":
    sys.exit(main())
