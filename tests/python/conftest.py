"""Shared helpers of the pytest suite: the CLI to compare with, and the small nip the
regression tests use (tests/regression/test_nip_run.cpp: a 300 um window, soft contacts)."""
import json
import os
import shutil
import subprocess

import pytest

CLI = os.environ.get("NIPDEM_CLI") or shutil.which("nipdem") or os.path.join(
    os.path.dirname(__file__), "..", "..", "build", "nipdem")

SMALL_NIP = {
    "geometry.window_x_min_m": -150e-6,
    "geometry.window_x_max_m": 150e-6,
    "collision.stiffness_scale": 0.01,
    "output.vtk": False,
}


def cli(*args, check=True):
    """Runs the CLI; returns (exit status, stdout, stderr)."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"nipdem {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    return r.returncode, r.stdout, r.stderr


def cli_json(*args):
    return json.loads(cli(*args, "--json")[1])


@pytest.fixture
def small_config():
    import nipdem
    cfg = nipdem.preset("black")
    cfg.update(SMALL_NIP)
    return cfg
