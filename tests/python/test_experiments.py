"""An experiment from Python returns the JSON the CLI prints for the same settings (paths and
wall times aside) and reads the series files it names."""
import json

import numpy as np
import pytest

import nipdem
from conftest import cli

TINY = ["--r", "1", "--time", "2e-5", "--pile-width", "100e-6", "--pile-height", "40e-6"]
VOLATILE = ("wall", "git_hash", "elapsed")


def normalise(node, out_dir):
    """Drops wall-clock fields and the output folder from a JSON document."""
    if isinstance(node, dict):
        return {k: normalise(v, out_dir) for k, v in node.items() if not any(w in k for w in VOLATILE)}
    if isinstance(node, list):
        return [normalise(v, out_dir) for v in node]
    if isinstance(node, str):
        return node.replace(str(out_dir), "OUT")
    return node


def test_tiny_reduction_equals_the_cli(tmp_path):
    _, stdout, _ = cli("experiment", "reduction", *TINY, "--set", "collision.stiffness_scale=0.01", "--quiet", "--json",
                       "--out", tmp_path / "cli")
    by_cli = json.loads(stdout)
    cfg = nipdem.preset("black")
    cfg["collision.stiffness_scale"] = 0.01
    by_py = nipdem.reduction(cfg, cohesion_ratios=[1], time_s=2e-5, pile_width_m=100e-6, pile_height_m=40e-6,
                             out=tmp_path / "py")
    assert normalise(dict(by_py), tmp_path / "py") == normalise(by_cli, tmp_path / "cli")
    assert by_py["points"][0]["initial_particles"] > 0
    # the JSON is also where the CLI puts it
    assert json.loads((tmp_path / "py" / "reduction.json").read_text()) == dict(by_py)
    # and the CSV files it names are read into arrays
    assert by_py.series, by_py
    for cols in by_py.series.values():
        assert cols and all(isinstance(v, np.ndarray) for v in cols.values())


def test_experiment_input_errors_are_value_errors(tmp_path):
    cfg = nipdem.preset("black")
    cfg["adhesion.cohesion_ratio"] = 3.0  # the experiment sets it per point
    with pytest.raises(ValueError) as e:
        nipdem.reduction(cfg, time_s=1e-5, out=tmp_path / "a")
    assert "adhesion.cohesion_ratio" in str(e.value)
    with pytest.raises(ValueError) as e:
        nipdem.reduction("black", cohesion_ratios=[float("nan")], time_s=1e-5, out=tmp_path / "b")
    assert "--r" in str(e.value)
    with pytest.raises(ValueError):
        nipdem.reduction("black", seed=-1, out=tmp_path / "c")
