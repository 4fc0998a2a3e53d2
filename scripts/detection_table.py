#!/usr/bin/env python3
"""Detection table (issue 11): every shared case in DATA/*/ (plant.yaml,
run.csv, truth.json) replayed whole through the live path (mpm monitor
--events with mpmd's defaults: forgetting 0.999, one false alarm per year)
beside mpm diagnose's offline verdict. Live = both detectors: the
sequential detector (per channel) and the periodic diagnosis scan (per
output, with its physics word); each raise is tagged seq or scan. Prints per case: the truth, the
offline verdict (mismatched outputs), the live raises (output, channel,
sample of the first raise) and whether live agrees.

usage: scripts/detection_table.py [--mpm build/daemon/mpm] [--data /work/shared/data]
"""
import argparse, glob, json, os, subprocess, sys


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser()
    ap.add_argument("--mpm", default=os.path.join(root, "build", "daemon", "mpm"))
    ap.add_argument("--data", default="/work/shared/data")
    ap.add_argument("--live-args", default="", help="extra mpm monitor options, e.g. '--diagnosis-window 10000'")
    args = ap.parse_args()
    print(f"{'case':38s} {'truth':18s} {'offline':14s} {'live raises (output/channel@sample(detector))':60s} agree")
    tally = {"flagged": 0, "raised_all": 0, "raised_any": 0, "wrong_output": 0, "nominal": 0, "nominal_raised": 0}
    ratios = []
    for case in sorted(glob.glob(os.path.join(args.data, "*", "truth.json"))):
        d = os.path.dirname(case)
        name = os.path.basename(d)
        truth = json.load(open(case))
        t = truth.get("mismatch")
        true_channels = sorted({f"{c['output']}/{c['input']}" for f in (truth.get("findings") or []) for c in (f.get("channels") or [])})
        plant, run = os.path.join(d, "plant.yaml"), os.path.join(d, "run.csv")
        off = subprocess.run([args.mpm, "diagnose", "--quiet", "--plant", plant, "--data", run], capture_output=True, text=True)
        try:
            diag = json.loads(off.stdout)
            offline = [l["output"] for l in diag["loops"] if l.get("mismatch")]
        except (ValueError, KeyError):
            offline = ["error"]
        ev = subprocess.run([args.mpm, "monitor", "--plant", plant, "--data", run, "--forgetting", "0.999", "--events"] + args.live_args.split(),
                            capture_output=True, text=True)
        raises = [json.loads(l) for l in ev.stdout.splitlines() if '"raised"' in l]
        first = {}
        for e in raises:
            tag = "scan:" + str(e.get("physics")) if e.get("detector") == "scan" else "seq"
            first.setdefault(e["output"], f"{e['output']}/{e['channel']}@{e['sample']}({tag})")
        live_outputs = sorted(first)
        if t is None:
            agree = "n/a"
        elif t:
            agree = "yes" if offline and set(offline) <= set(live_outputs) else ("missed" if offline and offline != ["error"] else "-")
        else:
            agree = "yes" if not live_outputs else "FALSE ALARM"
        samples = sum(1 for _ in open(run)) - 1
        true_outputs = {c.split("/")[0] for c in true_channels}
        if t and offline and offline != ["error"]:
            tally["flagged"] += 1
            tally["raised_all"] += agree == "yes"
            tally["raised_any"] += bool(set(offline) & set(live_outputs))
            for e in raises:
                if e["output"] in set(offline):
                    ratios.append(e["sample"] / samples)  # the offline test used the whole record
                    break
        if t:
            tally["wrong_output"] += sum(1 for o in live_outputs if o not in true_outputs and o not in offline)
        if t is False:
            tally["nominal"] += 1
            tally["nominal_raised"] += bool(live_outputs)
        truth_text = ("none" if t is False else "unknown" if t is None else ",".join(true_channels) or "yes")
        print(f"{name:38s} {truth_text[:18]:18s} {','.join(offline) or 'none':14s} {' '.join(first.values()) or 'none':60s} {agree}",
              flush=True)
    ratios.sort()
    print(f"\nmismatch cases flagged by offline: {tally['flagged']}; raised live on every flagged output: "
          f"{tally['raised_all']}, on at least one: {tally['raised_any']}; live raises on an output neither "
          f"true nor flagged: {tally['wrong_output']}; no-mismatch cases raised: {tally['nominal_raised']} of "
          f"{tally['nominal']}")
    if ratios:
        print(f"first live raise on a flagged output / record length (the offline test's samples): median "
              f"{ratios[len(ratios) // 2]:.2f}, max {ratios[-1]:.2f} over {len(ratios)} cases")


if __name__ == "__main__":
    main()
