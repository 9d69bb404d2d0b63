#!/usr/bin/env python3
"""Tables of the calibrated chapter-5 reruns (issue 17 item 4) from the JSON each step wrote.

Front position: per (preset, softening, w_h, sleeve speed) the mean over the seeds of the
time-averaged front and sigma = max(seed-mean s.e., the runs' own s.e. combined), as in
docs/results/2026-12-04-stiffness-study/summarize.py. Vo-level and edge sharpness: the
experiments' own summary numbers. Missing steps are listed as pending.
"""
import glob, json, math, os, re
from collections import defaultdict
here = os.path.dirname(os.path.abspath(__file__))
os.chdir(here)

def front_table():
    d = defaultdict(list)
    for f in sorted(glob.glob("front/*.json")):
        m = re.match(r"(black|color)(?:_k([0-9.]+))?_s(\d)", os.path.basename(f)[:-5])
        preset, k = m.group(1), m.group(2) or "0.01"
        for p in json.load(open(f))["points"]:
            key = (preset, k, round(p["gap_m"] * 1e6), round(p["sleeve_speed_m_per_s"] * 60))
            d[key].append((p["front_m"] * 1e6, p["front_stderr_m"] * 1e6, p["steady"]))
    print("| preset | stiffness_scale | w_h [um] | sleeve [m/min] | seeds | front [um] ± sigma | steady |")
    print("|---|---|---|---|---|---|---|")
    for key, v in sorted(d.items()):
        x = [e[0] for e in v]; n = len(x); m = sum(x) / n
        se_seed = math.sqrt(sum((a - m) ** 2 for a in x) / (n - 1) / n) if n > 1 else 0.0
        sig = max(se_seed, math.sqrt(sum(e[1] ** 2 for e in v)) / n)
        print(f"| {key[0]} | {key[1]} | {key[2]} | {key[3]} | {n} | {m:.1f} ± {sig:.1f} | {sum(e[2] for e in v)}/{n} |")

def vo_table():
    print("\n| step | seeds | Vo mean ± std [V] | per seed |\n|---|---|---|---|")
    for f in sorted(glob.glob("vo/*.json")):
        j = json.load(open(f))
        seeds = [s.get("vo_V") for s in j.get("per_seed", [])]
        print(f"| {f[:-5]} | {j['seeds_found']}/{j['seeds_total']} | {j['vo_mean_V']:.2f} ± {j['vo_std_V']:.2f} | {seeds} |")

def edge_table():
    print("\n| step | lines | front 10–90 % (95 % CI) [um] | back 10–90 % (95 % CI) [um] | printed |\n|---|---|---|---|---|")
    for f in sorted(glob.glob("edge*/*.json") + glob.glob("size/*.json")):
        j = json.load(open(f)); u = 1e6
        fc, bc = j["edge_front_ci_m"], j["edge_back_ci_m"]
        print(f"| {f[:-5]} | {j['realizations']} | {j['edge_front_m']*u:.0f} ({fc[0]*u:.0f}–{fc[1]*u:.0f}) | "
              f"{j['edge_back_m']*u:.0f} ({bc[0]*u:.0f}–{bc[1]*u:.0f}) | {j['printed_particles']} |")
    for d in sorted(glob.glob("edge*/*/") + glob.glob("size/*/")):
        if not os.path.exists(d.rstrip("/") + ".json"):
            n = len(glob.glob(d + "edge_sharpness/realizations/*.json"))
            print(f"| {d.rstrip('/')} (running) | {n} done | | | |")

front_table(); vo_table(); edge_table()
