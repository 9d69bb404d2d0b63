"""The Python examples run (shortened) and say what they should."""
import json
import os
import subprocess
import sys

from conftest import cli

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "..", "examples", "python")


def run_example(name, *args):
    r = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *map(str, args)], capture_output=True, text=True,
                       env=dict(os.environ, MPLBACKEND="Agg"))
    assert r.returncode == 0, r.stderr
    return r.stdout


def test_read_run_reads_a_cli_run_folder(tmp_path):
    run = tmp_path / "run"
    cli("run", os.path.join(HERE, "..", "..", "examples", "nip_black_small.toml"), "--out", run, "--quiet",
        "--set", "run.end_time_s=2e-5", "--set", "run.output_interval_s=1e-5", "--set", "output.vtk=false")
    summary = json.loads((run / "summary.json").read_text())
    out = run_example("read_run.py", run, "--plot", tmp_path / "energy.png")
    assert f"{summary['particles_in_window']} particles;" in out, out
    assert f"checkpoint at t = {summary['time_s'] * 1e3:.3f} ms: {summary['particles_in_window']} particles" in out, out
    assert "time series: 3 rows" in out, out
    assert (tmp_path / "energy.png").stat().st_size > 1000


def test_front_vs_br_scans_and_plots(tmp_path):
    out = run_example("front_vs_br.py", "--out", tmp_path, "--br", "0.8,1.2", "--max-time", "1e-3", "--jobs", "2")
    res = json.loads((tmp_path / "front_vs_br.json").read_text())
    assert [p["Br_T"] for p in res["points"]] == [0.8, 1.2]
    assert all(p["particles_at_end"] > 0 for p in res["points"])
    assert "Br = 0.80 T" in out and "Br = 1.20 T" in out
    assert (tmp_path / "front_vs_br.png").stat().st_size > 1000
    # each point ran on its own map of the knife with its Br
    maps = [(tmp_path / "maps" / f"knife_br{b}.csv").read_text() for b in ("0.8", "1.2")]
    assert maps[0] != maps[1]
    cfgs = [(tmp_path / f"br{b}" / "front_position" / "realizations" / "0.json") for b in ("0.8", "1.2")]
    assert all(c.exists() for c in cfgs), os.listdir(tmp_path / "br0.8")
