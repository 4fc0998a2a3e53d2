#!/usr/bin/env python3
"""The HTML report's live-detector plots against `mpm monitor --json` on the
same recording: for every output, the first bin whose statistic T_W / h_W
exceeds 1 holds the sample where `mpm monitor` first raised one of that
output's channels, and an output `mpm monitor` never raised never exceeds 1.
Also: each located loop has its paper plots (variance per input, AR part).

usage: check_report_detector.py REPORT.html MONITOR.json"""
import json, re, sys

def plots(html):
    out = {}
    for m in re.finditer(r'\{id:"([^"]+)",title:.*?,labels:(\[.*?\]),opts:\{.*?\},rows:(\[\[.*?\]\])\}', html):
        out[m.group(1)] = (json.loads(m.group(2)), json.loads(m.group(3)))
    return out

def main():
    html = open(sys.argv[1], encoding="utf-8").read()
    monitor = json.load(open(sys.argv[2]))
    ts = float(re.search(r"sample time ([0-9.eE+-]+) s", html).group(1))
    p = plots(html)
    for j, loop in enumerate(monitor["loops"]):
        labels, rows = p["t%d" % j]
        assert labels[1:] == ["all inputs", "focused", "threshold"], labels
        raised = [c["raised_at"] for c in loop["channels"] if c["raised_at"] >= 0]
        above = [r[0] / ts for r in rows if max(v or 0 for v in r[1:3]) > 1.0]
        stride = (rows[1][0] - rows[0][0]) / ts
        if raised:
            assert above, "%s: mpm monitor raised at %d, the report never crosses 1" % (loop["output"], min(raised))
            assert above[0] <= min(raised) < above[0] + stride, \
                "%s: first crossing at sample %g, mpm monitor raised at %d" % (loop["output"], above[0], min(raised))
        else:
            assert not above, "%s: the report crosses 1 at sample %g, mpm monitor never raised" % (loop["output"], above[0])
        if loop["mismatch"]:
            for i, c in enumerate(loop["channels"]):
                labels, rows = p["v%d_%d" % (j, i)]
                assert len(rows) == 20 and labels[1] == "R(%s,0)" % c["input"], labels
                # nested least squares: more lags never leave more variance
                assert all(r[3] <= r[1] + 1e-9 for r in rows), "v%d_%d" % (j, i)
            labels, rows = p["g%d" % j]
            assert labels[1].startswith("1 ") and len(rows) == 20, labels
    print("ok: detector traces match mpm monitor on %d outputs" % len(monitor["loops"]))

if __name__ == "__main__":
    try:
        main()
    except (AssertionError, KeyError, IndexError) as e:
        print("FAIL:", repr(e)); sys.exit(1)
