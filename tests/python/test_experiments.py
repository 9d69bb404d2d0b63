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


def test_tiny_edge_sharpness_equals_the_cli(tmp_path):
    sets = {"geometry.window_x_min_m": -60e-6, "geometry.window_x_max_m": 60e-6, "collision.stiffness_scale": 0.01,
            "print.voltage_V": 35.0}
    args = ["--realizations", "2", "--line-start", "0", "--line-length", "20e-6", "--margin", "20e-6"]
    for k, v in sets.items():
        args += ["--set", f"{k}={v!r}"]
    _, stdout, _ = cli("experiment", "edge-sharpness", *args, "--quiet", "--json", "--out", tmp_path / "cli")
    by_cli = json.loads(stdout)
    cfg = nipdem.preset("black")
    cfg.update(sets)
    by_py = nipdem.edge_sharpness(cfg, realizations=2, line_start_m=0.0, line_length_m=20e-6, margin_m=20e-6,
                                  out=tmp_path / "py")
    assert normalise(dict(by_py), tmp_path / "py") == normalise(by_cli, tmp_path / "cli")
    assert by_py["realizations"] == 2 and by_py["voltage_V"] == 35.0
    lines = by_py.series["lines_file"]  # lines.csv, named by the JSON, read into arrays
    assert lines["index"].tolist() == [0, 1] and lines["printed"].dtype.kind == "i"
    seeds = [json.loads((tmp_path / "py" / "edge_sharpness" / "realizations" / f"{i}.json").read_text())["seed"] for i in (0, 1)]
    assert lines["seed"].tolist() == seeds  # 64-bit seeds exact, not rounded through float


@pytest.mark.parametrize("call,args", [
    (lambda o: nipdem.vo_level(nipdem.preset("black").copy(), v0_V=0, coarse_step_V=1.2, out=o), ["vo-level", "--coarse-step", "1.2"]),
    (lambda o: nipdem.edge_sharpness("black", realizations=1, out=o), ["edge-sharpness", "--realizations", "1"]),
    (lambda o: nipdem.front_position("black", gaps_m=[-1e-6], out=o), ["front-position", "--gap", "-1e-6"]),
])
def test_experiment_errors_are_the_clis(tmp_path, call, args):
    with pytest.raises(ValueError) as e:
        call(tmp_path / "py")
    status, _, err = cli("experiment", *args, "--quiet", "--out", tmp_path / "cli", check=False)
    assert status == 2
    assert str(e.value) in err, (str(e.value), err)
