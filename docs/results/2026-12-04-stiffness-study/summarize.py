#!/usr/bin/env python3
"""Front position against stiffness_scale (issue 17 item 3): mean +- standard error of the seeds."""
import glob, json, math, os
from collections import defaultdict
here = os.path.dirname(os.path.abspath(__file__))
d = defaultdict(list)
for f in sorted(glob.glob(os.path.join(here, "runs", "*.json"))):
    preset, k, seed = os.path.basename(f)[:-5].split("_")
    p = json.load(open(f))["points"][0]
    d[(preset, float(k[1:]))].append((seed, p["front_m"] * 1e6, p["steady"]))
print("| preset | stiffness_scale | seeds | front [um] | per seed (steady?) |\n|---|---|---|---|---|")
for (preset, k), v in sorted(d.items()):
    x = [e[1] for e in v]; m = sum(x) / len(x)
    se = math.sqrt(sum((a - m) ** 2 for a in x) / (len(x) - 1) / len(x)) if len(x) > 1 else float("nan")
    print(f"| {preset} | {k} | {len(x)} | {m:.1f} ± {se:.1f} | " + ", ".join(f"{e[0]} {e[1]:.1f}{'' if e[2] else ' (drifting)'}" for e in v) + " |")
