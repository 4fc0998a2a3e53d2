#!/usr/bin/env python3
"""Renders an `mpm diagnose --html` report in headless Chromium and checks
that it drew: the page's own count of drawn plots equals the plots it holds
(and is > 0), the browser console printed nothing (no script error, no
warning), and in a screenshot every plot's area holds drawn pixels: more than
a few non-white pixels and some in the plot colours (not only black text).

usage: render_report.py REPORT.html SCREENSHOT.png"""
import json, re, struct, subprocess, sys, zlib

def chromium(args):
    cmd = ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--enable-logging=stderr", "--v=0"] + args
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)

def read_png(path):
    """RGB(A) 8-bit non-interlaced PNG -> (width, height, channels, rows of bytes)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", chunk)
            assert depth == 8 and ctype in (2, 6) and interlace == 0, "unsupported PNG"
            ch = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + n
    raw, stride, rows, prev = zlib.decompress(idat), w * ch, [], bytearray(w * ch)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - ch] if x >= ch else 0
            b, c = prev[x], prev[x - ch] if x >= ch else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line); prev = line
    return w, h, ch, rows

def main():
    html, png = sys.argv[1], sys.argv[2]
    url = "file://" + html
    dom = chromium(["--window-size=1200,1000", "--dump-dom", url])
    console = [l for l in dom.stderr.splitlines() if ":CONSOLE" in l]
    assert not console, "console output:\n" + "\n".join(console)
    m = re.search(r"drawn (\d+) of (\d+) plots", dom.stdout)
    assert m, "the page's script did not run (no 'drawn N of M plots')"
    drawn, total = int(m.group(1)), int(m.group(2))
    assert drawn == total > 0, m.group(0)
    layout = json.loads(re.search(r'data-layout="([^"]*)"', dom.stdout).group(1).replace("&quot;", '"'))
    height = int(layout["height"]) + 20
    shot = chromium(["--window-size=1200,%d" % height, "--screenshot=" + png, url])
    console = [l for l in shot.stderr.splitlines() if ":CONSOLE" in l]
    assert not console, "console output:\n" + "\n".join(console)
    w, h, ch, rows = read_png(png)
    bad = []
    for pid, left, top, width, ht in layout["plots"]:
        x0, y0, x1, y1 = int(left), int(top), min(w, int(left + width)), min(h, int(top + ht))
        inked = coloured = 0
        for y in range(y0, y1, 2):
            row = rows[y]
            for x in range(x0, x1, 2):
                r, g, b = row[x * ch], row[x * ch + 1], row[x * ch + 2]
                if min(r, g, b) < 200: inked += 1
                if max(r, g, b) - min(r, g, b) > 80: coloured += 1
        area = max(1, (x1 - x0) * (y1 - y0) // 4)
        if inked < 0.01 * area or coloured < 0.002 * area:
            bad.append("%s: %d inked, %d coloured of %d pixels" % (pid, inked, coloured, area))
    assert not bad, "plots that did not draw:\n" + "\n".join(bad)
    print("ok: %d plots drawn, screenshot %s (%dx%d)" % (drawn, png, w, h))

if __name__ == "__main__":
    try:
        main()
    except AssertionError as e:
        print("FAIL:", e); sys.exit(1)
