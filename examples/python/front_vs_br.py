#!/usr/bin/env python3
"""Clean-state front position against the remanence Br of the black unit's knife magnet.

The CLI cannot do this in one command: the knife's Br is not a configuration key. For each Br
this script samples the knife with that Br into a field map (nipdem.export_field_map), points
the configuration's magnet at it (magnet.field = "map") and runs the front-position experiment;
then it plots front position against Br (matplotlib, Agg backend).

Small, fast settings (an 800 um window, soft contacts, a 30 um inflow layer, at most 4 ms of
simulated time per point): a few minutes on two cores; a demonstration of the scan, not
converged physics. The points run on Python threads side by side (the simulations release the
GIL).

    PYTHONPATH=build/python python3 examples/python/front_vs_br.py [--out runs/front_vs_br] [--jobs 2]
"""
import argparse
import concurrent.futures
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import nipdem  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("--out", default="runs/front_vs_br")
ap.add_argument("--br", default="0.6,0.8,1.0,1.2,1.4", help="knife remanences [T], comma-separated")
ap.add_argument("--gap", type=float, default=150e-6, help="gap w_h [m]")
ap.add_argument("--max-time", type=float, default=4e-3, help="simulated time per point at most [s]")
ap.add_argument("--jobs", type=int, default=2, help="points run at the same time (threads)")
args = ap.parse_args()

half = 400e-6  # window half width [m]
cfg = nipdem.preset("black")
cfg.update({
    "collision.stiffness_scale": 0.01,
    "inflow.layer_thickness_m": 30e-6,
    "geometry.window_x_min_m": -half,
    "geometry.window_x_max_m": half,
})
os.makedirs(os.path.join(args.out, "maps"), exist_ok=True)


def front_at(br):
    """One point of the scan: the knife with remanence `br` [T] as a field map, then the
    front-position experiment on it."""
    # the map must cover every place a toner centre can reach: the window, from the bottom of
    # the sleeve's pits to the drum (the loader refuses a map that does not)
    field = os.path.abspath(os.path.join(args.out, "maps", f"knife_br{br:g}.csv"))
    nipdem.export_field_map(field, br=br, x0=-1.25 * half, x1=1.25 * half, nx=101, y0=-40e-6, y1=args.gap + 60e-6, ny=26)
    point = cfg.copy()
    point.update({"magnet.field": "map", "magnet.map_file": field})  # checked together: a map needs its file
    res = nipdem.front_position(point, gaps_m=[args.gap], min_time_s=0.5 * args.max_time, max_time_s=args.max_time,
                                out=os.path.join(args.out, f"br{br:g}"))
    p = res["points"][0]
    for k in ("front_m", "front_std_m"):  # null in the JSON when no assembly formed
        p[k] = float("nan") if p[k] is None else p[k]
    print(f"Br = {br:4.2f} T: front {p['front_m'] * 1e6:7.1f} +- {p['front_std_m'] * 1e6:5.1f} um"
          f"  (steady: {p['steady']}, {p['particles_at_end']} particles)", flush=True)
    return {"Br_T": br, "front_m": p["front_m"], "front_std_m": p["front_std_m"], "steady": p["steady"],
            "particles_at_end": p["particles_at_end"]}


# The simulations release the GIL, so plain Python threads run the points side by side.
with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
    rows = list(pool.map(front_at, [float(b) for b in args.br.split(",")]))

with open(os.path.join(args.out, "front_vs_br.json"), "w") as f:
    json.dump({"gap_m": args.gap, "max_time_s": args.max_time, "points": rows}, f, indent=2)

fig, ax = plt.subplots(figsize=(5, 3.5))
ax.errorbar([r["Br_T"] for r in rows], [r["front_m"] * 1e6 for r in rows], yerr=[r["front_std_m"] * 1e6 for r in rows],
            marker="o", capsize=3)
ax.set_xlabel("knife remanence $B_r$ [T]")
ax.set_ylabel("front position x [µm] (magnet edge = 0)")
ax.set_title(f"Clean-state front, gap {args.gap * 1e6:.0f} µm (small settings)")
fig.tight_layout()
png = os.path.join(args.out, "front_vs_br.png")
fig.savefig(png, dpi=120)
print("wrote", png)
