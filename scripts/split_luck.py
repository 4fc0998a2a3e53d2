#!/usr/bin/env python3
"""How much of a benchmark's physics score hangs on the held-out split.

usage: scripts/split_luck.py PHASE0.json PHASE1.json PHASE2.json

Reads three `scripts/generalisation_bench.py --out` files of the same
seed and runs, made with `--holdout-phase 0`, `1` and `2`, and prints the
true findings whose physics word is right under each phase, under all
three, under some phase (an oracle no method has: what any cure of the
split's luck alone could reach at most), and under a vote (a finding kept
where two phases report it, scored as the benchmark scores a run).
docs/method.md, "The split's luck", has the figures.
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import generalisation_bench as bench  # noqa: E402


def load(path):
    with open(path) as f:
        d = json.load(f)
    return d["args"], d["runs"]


def right(run, truth):
    """Whether the run names the truth's word, as the benchmark judges it."""
    found = [{"physics": f["physics"], "channels": {tuple(c) for c in f["channels"]}} for f in run["found"]]
    t = {"physics": truth["physics"], "channels": {tuple(c) for c in truth["channels"]}}
    return bench.reported_word(found, t) == truth["physics"]


def vote(runs):
    """The run as two of the three phases report it."""
    out = dict(runs[2])
    if any("error" in r for r in runs):
        return out
    seen = {}
    for r in runs:
        for f in r["found"]:
            seen.setdefault((f["physics"], tuple(sorted(tuple(c) for c in f["channels"]))), []).append(f)
    out["found"] = [v[0] for v in seen.values() if len(v) >= 2]
    out["mismatch"] = bool(out["found"]) or sum(bool(r["mismatch"]) for r in runs) >= 2
    return out


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__.strip().split("\n\n")[1])
    loaded = [load(p) for p in sys.argv[1:]]
    for want, (args, _) in enumerate(loaded):
        if args.get("holdout_phase") != want:
            sys.exit("split_luck: %s was made with --holdout-phase %s, not %d" % (
                sys.argv[1 + want], args.get("holdout_phase"), want))
    first = loaded[0][0]
    for path, (args, _) in zip(sys.argv[2:], loaded[1:]):
        for key in ("seed", "runs", "words", "none_fraction", "random_fraction", "alpha"):
            if args.get(key) != first.get(key):
                sys.exit("split_luck: %s differs from %s in %s" % (path, sys.argv[1], key))
    phases = [runs for _, runs in loaded]
    per_phase, on_all, on_some, total = [0, 0, 0], 0, 0, 0
    for runs in zip(*phases):
        if any("error" in r for r in runs):
            continue
        if any(r["desc"] != runs[0]["desc"] for r in runs):
            sys.exit("split_luck: run %d was drawn differently in the three files" % runs[0]["index"])
        for t in runs[0]["truth"]:
            ok = [right(r, t) for r in runs]
            total += 1
            for p in range(3):
                per_phase[p] += ok[p]
            on_all += all(ok)
            on_some += any(ok)
    voted = bench.score([vote(list(r)) for r in zip(*phases)])
    print("true findings %d: physics right under phase 0 %d, phase 1 %d, phase 2 %d; on all three %d; "
          "on some phase %d; a vote of two phases %d" % (
              total, per_phase[0], per_phase[1], per_phase[2], on_all, on_some, voted["physics_right"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
