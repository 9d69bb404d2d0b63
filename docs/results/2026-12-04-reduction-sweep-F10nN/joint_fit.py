#!/usr/bin/env python3
"""One cohesion ratio r for both units (issue 17, as the thesis chose one r, §4.6).

Reads the pooled `calibrate cohesion --from-sweep` reports calibration/{black,color}.json (mean and
standard error of the toner removed in 100 ms at each swept r, and the Table 4.3 target band), and
finds the r that minimises chi2(r) = sum over the units of (mean(r) - target)^2 / (stderr(r)^2 +
half-band^2), mean and stderr interpolated linearly between the swept r as `calibrate cohesion`
does. Interval: chi2 <= chi2_min + 1 (one parameter). Writes joint_r.json, removed_vs_r.csv and
removed_vs_r.png (fig. 4.25 analogue: seeds, mean +- s.e., target bands, the chosen r)."""
import csv, glob, json, os
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
units = {}
for u in ("black", "color"):
    j = json.load(open(os.path.join(here, "calibration", f"{u}.json")))
    rows = j["rows"]
    lo, hi = j["target_removed_range"]
    units[u] = dict(r=np.array([x["r"] for x in rows]), m=np.array([x["removed_mean"] for x in rows]),
                    s=np.array([x["removed_stderr"] for x in rows]), n=[x["seeds"] for x in rows],
                    target=j["target_removed"], lo=lo, hi=hi, own=j["r_fit"], own_1sigma=j["r_1sigma"], sweeps=j["sweeps"])
r_max = min(u["r"].max() for u in units.values())
grid = np.linspace(0.0, r_max, int(r_max * 1000) + 1)
chi = {}
for name, u in units.items():
    m = np.interp(grid, u["r"], u["m"]); s = np.interp(grid, u["r"], u["s"])
    chi[name] = (m - u["target"]) ** 2 / (s ** 2 + ((u["hi"] - u["lo"]) / 2) ** 2)
tot = chi["black"] + chi["color"]
i = int(np.argmin(tot))
inside = grid[tot <= tot[i] + 1.0]
out = {"method": "joint chi2 over both units of the pooled reduction-sweep counts (joint_fit.py)",
       "r_fit": round(float(grid[i]), 3), "r_interval_dchi2_1": [round(float(inside.min()), 3), round(float(inside.max()), 3)],
       "chi2_min": round(float(tot[i]), 3), "chi2_black": round(float(chi["black"][i]), 3),
       "chi2_color": round(float(chi["color"][i]), 3), "dof": 1,
       "per_unit": {k: {"r_fit": v["own"], "r_1sigma": v["own_1sigma"], "target_removed": v["target"],
                        "sweeps": v["sweeps"]} for k, v in units.items()}}
json.dump(out, open(os.path.join(here, "joint_r.json"), "w"), indent=1)
print(json.dumps(out, indent=1))

rs = sorted(set(units["black"]["r"]) | set(units["color"]["r"]))
with open(os.path.join(here, "removed_vs_r.csv"), "w", newline="") as fh:
    w = csv.writer(fh)
    w.writerow(["r", "black_removed_mean", "black_removed_stderr", "black_seeds", "color_removed_mean", "color_removed_stderr", "color_seeds"])
    for r in rs:
        row = [r]
        for u in ("black", "color"):
            k = np.where(units[u]["r"] == r)[0]
            row += [units[u]["m"][k[0]], units[u]["s"][k[0]], units[u]["n"][k[0]]] if len(k) else ["", "", ""]
        w.writerow(row)

# per-seed counts from the realization files
seeds = {"black": [], "color": []}
for f in glob.glob(os.path.join(here, "*_s*", "reduction", "realizations", "*.json")):
    unit = os.path.relpath(f, here).split("_")[0]
    res = json.load(open(f)).get("result", {})
    if "r" in res and "removed" in res: seeds[unit].append((res["r"], res["removed"]))

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
fig, ax = plt.subplots(figsize=(7, 4.4))
for u, c in (("black", "k"), ("color", "tab:blue")):
    d = units[u]
    ax.errorbar(d["r"], d["m"], yerr=d["s"], color=c, marker="o", capsize=3, label=f"{u}: mean ± s.e. of the seeds")
    if seeds[u]:
        ax.plot([p[0] for p in seeds[u]], [p[1] for p in seeds[u]], ls="none", marker=".", color=c, alpha=0.5,
                label=f"{u}: single seeds")
    ax.axhspan(d["lo"], d["hi"], color=c, alpha=0.12)
    ax.text(d["r"].max(), d["target"], f"  Table 4.3 ({u})", va="center", fontsize=7, color=c)
ax.axvspan(*out["r_interval_dchi2_1"], color="tab:orange", alpha=0.2)
ax.axvline(out["r_fit"], color="tab:orange", label=f"one r for both: {out['r_fit']:.2f} ({out['r_interval_dchi2_1'][0]:.2f}-{out['r_interval_dchi2_1'][1]:.2f})")
ax.set_xlabel("cohesion ratio r = F_coh / F_adh")
ax.set_ylabel("toner removed from the pile in 100 ms")
ax.set_title("Reduction experiment, F_adh = 10 nN, 7.1 um cut (fig. 4.25 analogue)", fontsize=9)
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(os.path.join(here, "removed_vs_r.png"), dpi=120)
