#!/usr/bin/env python3
"""Per-channel means of a skinlab EXR's layers over pixel classes, through `oiiotool --dumpdata` (no Python
imaging modules needed). Usage: exr-skin-stats.py A.exr [B.exr]
One EXR: mean beauty, diffuse and specular on skin (mask.Y > 0.5), on non-skin surface and on the background.
Two EXRs (same camera): the same means for both, and B's relative difference to A per class, channel and layer,
plus the mean absolute difference of the diffuse layer on skin relative to A's mean (a noise/error figure).
docs/pathtraced.md uses it for the rasterizer-versus-Cycles table."""
import math
import re
import subprocess
import sys


def read(path):
    out = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    info = subprocess.run(["oiiotool", "--info", "-v", path], check=True, capture_output=True, text=True).stdout
    names = re.search(r"channel list: (.*)", info).group(1).split(", ")
    pixels = {}
    for line in out.splitlines():
        m = re.match(r"\s*Pixel \((\d+), (\d+)\): (.*)", line)
        if m:
            pixels[(int(m.group(1)), int(m.group(2)))] = dict(zip(names, map(float, m.group(3).split())))
    return pixels


def classify(p):
    if math.isinf(p["depth.Z"]):
        return "background"
    return "skin" if p["mask.Y"] > 0.5 else "surface"


def means(pixels, classes):
    sums = {}
    for key, p in pixels.items():
        c = classes[key]
        for layer, prefix in (("beauty", ""), ("diffuse", "diffuse."), ("specular", "specular.")):
            for ch in "RGB":
                sums.setdefault((c, layer, ch), []).append(p[prefix + ch])
    return {k: sum(v) / len(v) for k, v in sums.items()}, {c: list(classes.values()).count(c) for c in set(classes.values())}


a = read(sys.argv[1])
classes = {k: classify(p) for k, p in a.items()}
ma, counts = means(a, classes)
print("pixels:", counts)
if len(sys.argv) == 2:
    for k in sorted(ma):
        print("%-10s %-8s %s %.5f" % (k[0], k[1], k[2], ma[k]))
    sys.exit(0)
b = read(sys.argv[2])
mb, _ = means(b, classes)
for k in sorted(ma):
    rel = (mb[k] - ma[k]) / ma[k] if ma[k] > 1e-9 else float("nan")
    print("%-10s %-8s %s A %.5f B %.5f rel %+.3f" % (k[0], k[1], k[2], ma[k], mb[k], rel))
for ch in "RGB":
    skin = [key for key, c in classes.items() if c == "skin"]
    if skin:
        mad = sum(abs(b[key]["diffuse." + ch] - a[key]["diffuse." + ch]) for key in skin) / len(skin)
        ref = sum(a[key]["diffuse." + ch] for key in skin) / len(skin)
        print("skin diffuse %s mean |B-A| / mean A = %.4f" % (ch, mad / ref))
