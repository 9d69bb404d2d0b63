#!/usr/bin/env python3
"""Python-driven Simulation.advance_to against `nipdem run` on the same configuration.

Prints one figure, the median over rounds of the per-round ratio Python / CLI of the CPU time
spent advancing, with its parameters, the wall-time ratio and the git hash. Each round runs, in
this order, the CLI and a Python process on the full run, then both on a one-step run (their
start-up: process, import, configuration, construction, outputs); a tool's advancing CPU time is
its full run's minus its one-step run's (getrusage of the child). Alternating the tools within
every round lets both see the same load on a shared machine. The wall-time ratio uses the tools'
own clocks around the stepping (the CLI's summary.json `wall_time_s`, Python's perf_counter
around advance_to) and is noisier on a loaded machine. Both runs must end with the same steps and
particles (the comparison is of the same work); the CLI writes no snapshots, checkpoints or VTK
in between (one output interval = the end time).

    PYTHONPATH=build/python python3 bench/bench_python.py [--rounds 8] [--end-time 1e-3] [--cli build/nipdem]
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import nipdem

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("--rounds", type=int, default=8)
ap.add_argument("--end-time", type=float, default=1e-3, help="simulated time per run [s]")
ap.add_argument("--half-width", type=float, default=300e-6, help="window half width [m]")
ap.add_argument("--threads", type=int, default=1)
ap.add_argument("--cli", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "nipdem"))
ap.add_argument("--child", help=argparse.SUPPRESS)  # internal: run CONFIG in this process and report
args = ap.parse_args()

if args.child:
    sim = nipdem.Simulation(nipdem.load_config(args.child))
    t0 = time.perf_counter()
    sim.advance_to(sim.config["run.end_time_s"])
    wall = time.perf_counter() - t0
    print(json.dumps({"wall_s": wall, "steps": sim.step_count, "particles": sim.n_bodies}))
    sys.exit(0)


def config(end_time):
    cfg = nipdem.preset("black")
    cfg.update({
        "geometry.window_x_min_m": -args.half_width, "geometry.window_x_max_m": args.half_width,
        "collision.stiffness_scale": 0.01, "output.vtk": False, "run.threads": args.threads,
        "run.end_time_s": end_time, "run.output_interval_s": end_time, "run.checkpoint_interval_s": end_time,
    })
    return cfg


work = tempfile.mkdtemp(prefix="nipdem_bench_python_")
full = config(args.end_time)
one_step = config(nipdem.Simulation(full).dt)  # one time step
files = {}
for name, cfg in (("full", full), ("one_step", one_step)):
    files[name] = os.path.join(work, name + ".toml")
    cfg.save(files[name])


def child_cpu(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, OMP_WAIT_POLICY="passive"))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, json.loads(r.stdout)


runs = 0


def run_cli(which):
    global runs
    runs += 1
    cpu, s = child_cpu([args.cli, "run", files[which], "--out", os.path.join(work, f"cli{runs}"), "--quiet", "--json"])
    return cpu, s["wall_time_s"], s["steps"], s["particles_in_window"]


def run_python(which):
    cpu, s = child_cpu([sys.executable, os.path.abspath(__file__), "--child", files[which]])
    return cpu, s["wall_s"], s["steps"], s["particles"]


rows = []
for k in range(args.rounds):
    c, p = run_cli("full"), run_python("full")
    c0, p0 = run_cli("one_step"), run_python("one_step")
    if c[2:] != p[2:] or c0[2:] != p0[2:]:
        sys.exit(f"round {k}: the runs differ: CLI {c[2:]} steps/particles, Python {p[2:]}")
    row = {"cli_cpu_s": c[0] - c0[0], "python_cpu_s": p[0] - p0[0], "cli_startup_cpu_s": c0[0], "python_startup_cpu_s": p0[0],
           "cli_wall_s": c[1], "python_wall_s": p[1]}
    row["cpu_ratio"] = row["python_cpu_s"] / row["cli_cpu_s"]
    row["wall_ratio"] = row["python_wall_s"] / row["cli_wall_s"]
    rows.append(row)
    print(f"round {k}: advancing CPU: CLI {row['cli_cpu_s']:.3f} s, Python {row['python_cpu_s']:.3f} s, ratio {row['cpu_ratio']:.4f}; "
          f"wall ratio {row['wall_ratio']:.4f}", file=sys.stderr, flush=True)


def med(key):
    return statistics.median(r[key] for r in rows)


print(json.dumps({
    "benchmark": "bench_python", "git_hash": nipdem.git_hash, "date": time.strftime("%Y-%m-%d %H:%M"),
    "end_time_s": args.end_time, "window_half_width_m": args.half_width, "threads": args.threads, "rounds": args.rounds,
    "steps": c[2], "particles_at_end": c[3],
    "median_cpu_ratio_python_over_cli": med("cpu_ratio"),
    "cpu_ratio_range": [min(r["cpu_ratio"] for r in rows), max(r["cpu_ratio"] for r in rows)],
    "median_wall_ratio_python_over_cli": med("wall_ratio"),
    "wall_ratio_range": [min(r["wall_ratio"] for r in rows), max(r["wall_ratio"] for r in rows)],
    "median_cli_cpu_s": med("cli_cpu_s"), "median_python_cpu_s": med("python_cpu_s"),
    "rounds_detail": rows,
}, indent=1))
