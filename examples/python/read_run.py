#!/usr/bin/env python3
"""Reads a run folder of `nipdem run` and summarises it: counts, the time series, what left
the window, and the particles of the last checkpoint as NumPy arrays.

    build/nipdem run examples/nip_black_small.toml --out runs/a --set run.end_time_s=2e-4
    PYTHONPATH=build/python python3 examples/python/read_run.py runs/a [--plot runs/a/energy.png]
"""
import argparse

import numpy as np

import nipdem

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("run", help="run folder (summary.json, config.toml, timeseries.csv, checkpoint.bin)")
ap.add_argument("--plot", help="write the kinetic energy against time to this PNG")
args = ap.parse_args()

run = nipdem.read_run(args.run)
s = run["summary"]
if s:
    print(f"{args.run}: t = {s['time_s'] * 1e3:.3f} ms in {s['steps']} steps of {s['dt_s']:.3g} s; "
          f"{s['particles_in_window']} particles; developed {s['developed']}, returned {s['returned']}, lost {s['lost']}")
cfg = run["config"]
print(f"config: preset {cfg.preset_name}, gap {cfg['geometry.gap_m'] * 1e6:g} um, seed {cfg['run.seed']}")

ts = run["timeseries"]
print(f"time series: {len(ts['time_s'])} rows; particles {int(ts['bodies'][0])} -> {int(ts['bodies'][-1])}, "
      f"kinetic energy at the end {ts['kinetic_energy_J'][-1]:.3g} J")
rm = run["removals"]
if rm and len(rm["time_s"]):
    exits, counts = np.unique(rm["exit"], return_counts=True)
    print("removed:", ", ".join(f"{e} {c}" for e, c in zip(exits, counts)),
          f"(mean diameter {np.mean(rm['diameter_m']) * 1e6:.2f} um)")

if run["checkpoint"]:
    sim = nipdem.Simulation(cfg)
    sim.load_checkpoint(run["checkpoint"])
    speed = np.hypot(sim.bodies.vx, sim.bodies.vy)
    print(f"checkpoint at t = {sim.time * 1e3:.3f} ms: {sim.n_bodies} particles of {sim.n_discs} discs, "
          f"median speed {np.median(speed):.3g} m/s, d50 of those present {np.median(sim.bodies.size) * 1e6:.2f} um")

if args.plot:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.plot(ts["time_s"] * 1e3, ts["kinetic_energy_J"])
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("kinetic energy [J]")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=110)
    print("wrote", args.plot)
