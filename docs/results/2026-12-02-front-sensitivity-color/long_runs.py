#!/usr/bin/env python3
"""Front position vs time of the long colour runs (w_h = 100 um, 10 m/min, seed 1), in 0.5 ms
bins: drum inflow layers 15/30/60 um (runs/long20/L*) and, at 60 um, the friction and shape
variants run to 8 ms (runs/long10/*). Usage: long_runs.py FOLDER (writes front_vs_time_*.csv)"""
import csv, glob, json, math, os, statistics as st, sys

root = sys.argv[1]
def series(path):
    r = json.load(open(path))["result"]
    return r.get("series_t_front_back_m_in_out", r.get("series_t_front_back_m"))

def binned(runs, name, width=0.5e-3):
    tmax = max(x[0] for s in runs.values() for x in s)
    nb = int(math.ceil(tmax / width))
    with open(os.path.join(root, name), "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(["t_ms"] + [f"front_{k}_um" for k in runs])
        for b in range(nb):
            row = [f"{(b + 0.5) * width * 1e3:.2f}"]
            for s in runs.values():
                v = [x[1] for x in s if b * width <= x[0] < (b + 1) * width]
                row.append(f"{st.mean(v) * 1e6:.1f}" if v else "nan")
            w.writerow(row)

layers = {f"L{L}": series(f"{root}/runs/long20/L{L}/front_position/realizations/0.json") for L in (15, 30, 60)}
binned(layers, "front_vs_time_layer.csv")
variants = {"base": layers["L60"]}
for n in ("toner_mu_x0.5", "toner_mu_x2", "shape_single", "shape_hexa6"):
    variants[n] = series(f"{root}/runs/long10/{n}/front_position/realizations/0.json")
binned({k: [x for x in s if x[0] <= 8.2e-3] for k, s in variants.items()}, "front_vs_time_variants.csv")
