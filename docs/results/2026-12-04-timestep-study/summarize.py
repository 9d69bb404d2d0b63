#!/usr/bin/env python3
"""Tables and a plot of the time-step study (issue 18 item 4): front position over 2 ms against
dt/t_n, mean of the seeds +- standard error; collision and energy errors from the validation CSVs."""
import csv, glob, json, math, os, sys
from collections import defaultdict

here = os.path.dirname(os.path.abspath(__file__))
front = defaultdict(list)
for f in sorted(glob.glob(os.path.join(here, "runs", "*.json"))):
    preset, rest = os.path.basename(f)[:-5].split("_", 1)
    integ, frac, seed = rest.rsplit("_", 2)
    p = json.load(open(f))["points"][0]
    front[(preset, integ, float(frac))].append(p["front_m"] * 1e6)

rows = []
for (preset, integ, frac), v in sorted(front.items()):
    m = sum(v) / len(v)
    se = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1) / len(v)) if len(v) > 1 else float("nan")
    rows.append((preset, integ, frac, len(v), m, se, " ".join(f"{x:.1f}" for x in v)))
with open(os.path.join(here, "front_vs_dt.csv"), "w", newline="") as fh:
    w = csv.writer(fh)
    w.writerow(["preset", "integrator", "dt_over_tn", "seeds", "front_um_mean", "front_um_stderr", "front_um_per_seed"])
    for r in rows: w.writerow([r[0], r[1], r[2], r[3], f"{r[4]:.1f}", f"{r[5]:.1f}", r[6]])
print("| preset | integrator | dt/t_n | seeds | front [um] | per seed |\n|---|---|---|---|---|---|")
for r in rows: print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]:.1f} ± {r[5]:.1f} | {r[6]} |")

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
ax = axes[0]
for preset, mk in (("black", "o"), ("color", "s")):
    for integ, ls in (("velocity_verlet", "-"), ("newmark_explicit", "--")):
        pts = [r for r in rows if r[0] == preset and r[1] == integ]
        if pts:
            ax.errorbar([r[2] for r in pts], [r[4] for r in pts], yerr=[r[5] for r in pts], marker=mk, ls=ls,
                        capsize=3, label=f"{preset}, {integ.replace('_', ' ')}")
ax.set_xlabel("time step dt / t_n"); ax.set_ylabel("front position over 2 ms [um]")
ax.set_title("nip front (3 seeds, mean ± s.e.)"); ax.legend(fontsize=7)
col = list(csv.DictReader(open(os.path.join(here, "collision_error_vs_dt.csv"))))
ax = axes[1]
for integ, ls in (("velocity_verlet", "-"), ("newmark_explicit", "--")):
    for kind in ("toner_toner", "toner_roller", "toner_drum"):
        pts = [r for r in col if r["integrator"] == integ and r["kind"] == kind]
        ax.plot([float(r["dt_over_tn"]) for r in pts], [100 * float(r["e_rel_err_max"]) for r in pts], ls=ls, marker="o",
                label=f"{kind.replace('_', '-')}, {integ.split('_')[0]}")
ax.set_xlabel("dt / t_n"); ax.set_ylabel("worst restitution error [%]"); ax.set_title("binary collision, 64 impact moments")
ax.legend(fontsize=6)
en = list(csv.DictReader(open(os.path.join(here, "energy_drift_vs_dt.csv"))))
ax = axes[2]
for integ in ("velocity_verlet", "newmark_explicit"):
    fr = sorted({float(r["dt_over_tn"]) for r in en if r["integrator"] == integ})
    ax.semilogy(fr, [max(float(r["max_rel_dev"]) for r in en if r["integrator"] == integ and float(r["dt_over_tn"]) == f)
                     for f in fr], marker="o", label=integ.replace("_", " "))
ax.set_xlabel("dt / t_n"); ax.set_ylabel("max |dE|/E over 2000 t_n"); ax.set_title("undamped packing (e = 1)")
ax.legend(fontsize=7)
fig.tight_layout(); fig.savefig(os.path.join(here, "timestep_study.png"), dpi=110)
