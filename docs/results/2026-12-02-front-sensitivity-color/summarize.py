#!/usr/bin/env python3
"""Collects the front-position sensitivity runs of run.sh into CSV tables (one row per
variant and sleeve speed; the steady part of each run's front/back series, mean over seeds
with the standard error of the seed means). Usage: summarize.py SWEEPDIR OUTPREFIX"""
import csv, glob, json, math, statistics as st, sys

root, prefix = sys.argv[1], sys.argv[2]
rows = {}
for f in sorted(glob.glob(f"{root}/*/s*/front_position/realizations/*.json")):
    name = f.split("/")[-5]
    real = json.load(open(f))
    if not real["ok"]:
        sys.exit(f"{f}: realization failed")
    r = real["result"]
    v = round(r["sleeve_speed_m_per_s"] * 60)
    series = r.get("series_t_front_back_m_in_out", r.get("series_t_front_back_m"))  # newer files add in/out counts
    steady = [x for x in series if x[0] >= r["t_onset_s"]]
    rows.setdefault((name, v), []).append(dict(
        front=st.mean(x[1] for x in steady) * 1e6, back=st.mean(x[2] for x in steady) * 1e6,
        tstd=r["front_std_m"] * 1e6, steady=r["steady"], seed=real["seed"]))

def sem(xs):
    return st.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")

with open(f"{prefix}.csv", "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(["variant", "sleeve_m_per_min", "seeds", "front_um", "front_sem_um",
                "front_tstd_um", "back_um", "size_um", "all_steady", "fronts_per_seed_um"])
    for (name, v), L in sorted(rows.items()):
        fr = [x["front"] for x in L]
        w.writerow([name, v, len(L), f"{st.mean(fr):.1f}", f"{sem(fr):.1f}",
                    f"{st.mean(x['tstd'] for x in L):.1f}", f"{st.mean(x['back'] for x in L):.1f}",
                    f"{st.mean(x['back'] - x['front'] for x in L):.1f}",
                    int(all(x["steady"] for x in L)), ";".join(f"{x:.1f}" for x in fr)])

# trend tables for plotting: one parameter at a time, both speeds side by side
trends = {
    "layer": [("layer_15um", 15), ("layer_30um", 30), ("layer_45um", 45), ("base", 60)],
    "toner_mu": [("toner_mu_x0.5", 0.5), ("base", 1.0), ("toner_mu_x1.5", 1.5), ("toner_mu_x2", 2.0)],
    "discs": [("shape_single", 1), ("base", 3), ("shape_quad4", 4), ("shape_penta5", 5), ("shape_hexa6", 6)],
}
for t, pts in trends.items():
    have = [(n, x) for n, x in pts if (n, 10) in rows and (n, 30) in rows]
    if len(have) < 2:
        continue
    with open(f"{prefix}_{t}.csv", "w", newline="") as out:
        w = csv.writer(out)
        w.writerow([t, "front_vh10_um", "sem_vh10_um", "front_vh30_um", "sem_vh30_um"])
        for n, x in have:
            a = [y["front"] for y in rows[(n, 10)]]; b = [y["front"] for y in rows[(n, 30)]]
            w.writerow([x, f"{st.mean(a):.1f}", f"{sem(a):.1f}", f"{st.mean(b):.1f}", f"{sem(b):.1f}"])
