#!/usr/bin/env python3
"""Front position against stiffness_scale (issue 17 item 3).

Per (preset, stiffness_scale): mean of the seeds' time-averaged fronts and an interval sigma
that is the larger of (a) the standard error of the seed means and (b) the runs' own
autocorrelation-aware standard errors combined, sqrt(sum se_i^2)/n. With 3 seeds (a) alone can
be accidentally small (black at 0.01: 0.4 um while each run's own error is 2.1-2.4 um).
Then every pair of softenings of a preset: difference and how many combined sigmas it is.
"""
import glob, json, math, os
from collections import defaultdict
here = os.path.dirname(os.path.abspath(__file__))
d = defaultdict(list)
for f in sorted(glob.glob(os.path.join(here, "runs", "*.json"))):
    preset, k, seed = os.path.basename(f)[:-5].split("_")
    p = json.load(open(f))["points"][0]
    d[(preset, float(k[1:]))].append((seed, p["front_m"] * 1e6, p["front_stderr_m"] * 1e6, p["steady"]))
stats = {}
print("| preset | stiffness_scale | seeds | front [um] ± sigma | seed s.e. | runs' s.e. | per seed (steady?) |")
print("|---|---|---|---|---|---|---|")
for (preset, k), v in sorted(d.items()):
    x = [e[1] for e in v]; n = len(x); m = sum(x) / n
    se_seed = math.sqrt(sum((a - m) ** 2 for a in x) / (n - 1) / n) if n > 1 else float("nan")
    se_runs = math.sqrt(sum(e[2] ** 2 for e in v)) / n
    sig = max(se_seed, se_runs) if n > 1 else se_runs
    stats[(preset, k)] = (m, sig)
    print(f"| {preset} | {k} | {n} | {m:.1f} ± {sig:.1f} | {se_seed:.1f} | {se_runs:.1f} | "
          + ", ".join(f"{e[0]} {e[1]:.1f}{'' if e[3] else ' (drifting)'}" for e in v) + " |")
print("\n| preset | softenings | difference [um] | in combined sigmas |\n|---|---|---|---|")
for preset in sorted({p for p, _ in stats}):
    ks = sorted(k for p, k in stats if p == preset)
    for i, a in enumerate(ks):
        for b in ks[i + 1:]:
            (ma, sa), (mb, sb) = stats[(preset, a)], stats[(preset, b)]
            diff = mb - ma
            print(f"| {preset} | {a} → {b} | {diff:+.1f} | {abs(diff) / math.hypot(sa, sb):.1f} |")
