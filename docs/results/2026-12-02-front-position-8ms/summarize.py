#!/usr/bin/env python3
"""Front position vs gap per unit and sleeve speed: mean over the seeds present, with the
standard error of the seed means, the mean temporal fluctuation and the window's mean
outflow/inflow over the steady part. Usage: summarize.py RUNDIR (holds <preset>/seed_s<k>/)"""
import csv, glob, json, math, os, statistics as st, sys

root = sys.argv[1]
for preset in ("color", "black"):
    pts = {}
    for f in sorted(glob.glob(f"{root}/{preset}/seed_s*/front_position/realizations/*.json")):
        rec = json.load(open(f))
        if not rec["ok"]:
            sys.exit(f"{f}: failed realization")
        r = rec["result"]
        key = (round(r["sleeve_speed_m_per_s"] * 60), round(r["gap_m"] * 1e6))
        pts.setdefault(key, []).append(r)
    if not pts:
        continue
    with open(f"{preset}_front_vs_gap.csv", "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(["gap_um", "sleeve_m_per_min", "seeds", "front_um", "sem_um", "tstd_um",
                    "outflow_over_inflow", "all_steady", "fronts_um"])
        for (v, g), L in sorted(pts.items(), key=lambda kv: (kv[0][1], kv[0][0])):
            fr = [x["front_m"] * 1e6 for x in L]
            sem = st.stdev(fr) / math.sqrt(len(fr)) if len(fr) > 1 else float("nan")
            ratios = [x["outflow_over_inflow_steady"] for x in L if x.get("outflow_over_inflow_steady") is not None]
            w.writerow([g, v, len(L), f"{st.mean(fr):.1f}", f"{sem:.1f}",
                        f"{st.mean(x['front_std_m'] for x in L) * 1e6:.1f}",
                        f"{st.mean(ratios):.2f}" if ratios else "nan",
                        int(all(x["steady"] for x in L)), ";".join(f"{x:.1f}" for x in fr)])
    # wide table for plotting: one row per gap, both speeds
    with open(f"{preset}_plot.csv", "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(["gap_um", "front_vh10_um", "sem_vh10_um", "front_vh30_um", "sem_vh30_um"])
        for g in sorted({g for _, g in pts}):
            row = [g]
            for v in (10, 30):
                L = pts.get((v, g), [])
                fr = [x["front_m"] * 1e6 for x in L]
                row += [f"{st.mean(fr):.1f}" if fr else "nan",
                        f"{st.stdev(fr) / math.sqrt(len(fr)):.1f}" if len(fr) > 1 else "0"]
            w.writerow(row)
