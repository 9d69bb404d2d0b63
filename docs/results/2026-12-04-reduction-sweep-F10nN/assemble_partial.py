#!/usr/bin/env python3
"""Writes an `experiment reduction`-shaped JSON from the finished realizations of a sweep that
is still running (OUT/reduction/realizations/*.json), so `calibrate cohesion --from-sweep` can
pool it before the sweep ends. Usage: assemble_partial.py SWEEP_DIR PRESET SEED > partial.json"""
import glob, json, os, sys
d, preset, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
pts = []
for f in sorted(glob.glob(os.path.join(d, "reduction", "realizations", "*.json"))):
    j = json.load(open(f))
    if j.get("ok"):
        r = dict(j["result"]); r.pop("series_t_front_back_size_n", None); r["index"] = j["index"]
        pts.append(r)
print(json.dumps({"experiment": "reduction", "pile_width_m": 4e-4, "partial": True, "points": pts,
                  "meta": {"config": "", "preset": preset, "seed": seed,
                           "set": ["adhesion.roller_force_N=1e-8", "geometry.roughness.height_m=7.1e-6",
                                   "collision.stiffness_scale=0.01"]}}, indent=1))
