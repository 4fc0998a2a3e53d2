#!/usr/bin/env python3
"""The mission in one run, printed for a person (called by scripts/run.sh):
a mismatch the MPC hides, found, named, fitted, written back, and the fit
improving. usage: mission.py MPM PLANT OUT_DIR"""
import json, subprocess, sys

mpm, plant, out = sys.argv[1], sys.argv[2], sys.argv[3]
TRUE_GAIN, SAMPLES, SEED = 1.5, 3000, 1
EDIT = "y2.u1.gain=%g" % TRUE_GAIN

def run(*args):
    subprocess.run([mpm, *args], check=True, stdout=subprocess.DEVNULL)

def control_error_variances(csv):
    with open(csv) as f:
        head = f.readline().strip().split(",")
        cols = {n: [] for n in head}
        for line in f:
            for n, v in zip(head, line.strip().split(",")):
                cols[n].append(float(v) if v not in ("", "nan") else float("nan"))
    res = {}
    for y in (n for n in head if "r_" + n in cols):
        e = [r - v for r, v in zip(cols["r_" + y], cols[y]) if r == r and v == v]
        m = sum(e) / len(e)
        res[y] = sum((x - m) ** 2 for x in e) / (len(e) - 1)
    return res

matched, mismatched = out + "/matched.csv", out + "/mismatch.csv"
run("simulate", "--scenario", "wood-berry-nominal", "--samples", str(SAMPLES), "--seed", str(SEED), "--out", matched)
run("simulate", "--scenario", "wood-berry-nominal", "--edit", EDIT, "--samples", str(SAMPLES), "--seed", str(SEED),
    "--out", mismatched)
vm, vx = control_error_variances(matched), control_error_variances(mismatched)
print("1. A mismatch the MPC hides: the plant's y2 <- u1 gain is %g x the model's (Wood-Berry column, %d samples)."
      % (TRUE_GAIN, SAMPLES))
print("   control-error variance (setpoint - output), matched plant vs mismatched plant, same disturbances:")
for y in vm:
    print("     %-4s %8.4g  vs %8.4g   (%+.1f %%)" % (y, vm[y], vx[y], 100.0 * (vx[y] / vm[y] - 1.0)))

report, fixed, html = out + "/diagnosis.json", out + "/corrected-plant.yaml", out + "/report.html"
run("diagnose", "--quiet", "--plant", plant, "--data", mismatched, "--json", report, "--write-plant", fixed,
    "--html", html)
r = json.load(open(report))
print("2. mpm diagnose on the recording (its model: %s):" % plant)
for loop in r["loops"]:
    gamma = {g["input"]: g["gamma"] for g in loop["gamma"]}
    print("     loop %s: %s" % (loop["output"], "MISMATCH" if loop["mismatch"] else "no mismatch"))
    for g in loop["granger"]:
        mark = "  <- gamma < 0.01: the paper's rule locates it" if loop["mismatch"] and gamma[g["input"]] < 0.01 else ""
        print("       %s <- %s  F %.4f  F_conditional %.4f  p %.3g  gamma %.4f%s"
              % (loop["output"], g["input"], g["F"], g["F_conditional"], g["p_value"], gamma[g["input"]], mark))
for f in r["findings"]:
    ch = ", ".join("%s <- %s" % (c["output"], c["input"]) for c in f["channels"])
    fitted = f.get("fitted") or {}
    hb, ha = f["fit"]["holdout_variance_before"], f["fit"]["holdout_variance_after"]
    print("   finding: channel %s, physics '%s': %s" % (ch, f["physics"], f["summary"]))
    if "gain_factor" in fitted:
        print("     fitted gain factor %.3f, true %.3f (error %+.1f %%)"
              % (fitted["gain_factor"], TRUE_GAIN, 100.0 * (fitted["gain_factor"] / TRUE_GAIN - 1.0)))
    print("     held-out one-step prediction-error variance %.4g -> %.4g (%.1f %% less, on data the fit never saw)"
          % (hb, ha, 100.0 * (1.0 - ha / hb)))
if not r["findings"]:
    print("   no finding (the mission failed on this seed)")

# Fit % per output from the HTML report's table (simulation and one step ahead).
import re
page = open(html).read()
cells = {k: re.findall(r"<td class=%s>([^<]*)" % k, page) for k in ("fitb", "fita", "fit1b", "fit1a")}
print("   fit % (NRMSE, as MATLAB compare) with the nominal -> the corrected model, per output:")
for j, loop in enumerate(r["loops"]):
    f = [float(cells[k][j]) if cells[k][j] != "null" else float("nan") for k in ("fitb", "fita", "fit1b", "fit1a")]
    print("     %-4s simulation %6.1f -> %6.1f   one step ahead %5.1f -> %5.1f" % (loop["output"], *f))

after = out + "/diagnosis-corrected.json"
run("diagnose", "--quiet", "--plant", fixed, "--data", mismatched, "--json", after)
r2 = json.load(open(after))
print("3. The same recording diagnosed with the corrected plant: mismatch %s, %d finding(s)."
      % ("found" if r2["mismatch"] else "none left", len(r2["findings"])))
print("   corrected plant file: %s\n   HTML report:          %s\n   diagnosis JSON:       %s" % (fixed, html, report))
