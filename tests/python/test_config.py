"""Configs from Python are validated by the library's loader exactly as `--set` is."""
import os

import pytest

import nipdem
from conftest import cli


def test_preset_gives_resolved_values():
    cfg = nipdem.preset("black")
    assert cfg["geometry.gap_m"] == 150e-6
    assert cfg["run.integrator"] == "velocity_verlet"
    assert cfg["geometry.roughness.enabled"] is True
    assert "geometry.gap_m" in cfg and "geometry.gap_mm" not in cfg
    # derived values are in the resolved config as in a run folder's config.toml
    assert cfg["magnet.saturation_magnetisation_A_per_m"] > 0
    assert nipdem.preset("color")["run.seed"] == 1
    with pytest.raises(KeyError):
        cfg["geometry.no_such_key"]


def test_setting_a_valid_value_is_resolved():
    cfg = nipdem.preset("black")
    cfg["geometry.gap_m"] = 120e-6
    assert cfg["geometry.gap_m"] == 120e-6
    assert cfg.overrides == ["geometry.gap_m=0.00012"]
    assert "gap_m = 0.00012" in cfg.to_toml()
    cfg["geometry.gap_m"] = 100e-6  # replaces the earlier override
    assert cfg.overrides == ["geometry.gap_m=0.0001"]
    del cfg["geometry.gap_m"]
    assert cfg["geometry.gap_m"] == 150e-6
    with pytest.raises(KeyError):
        del cfg["geometry.gap_m"]


def test_out_of_range_raises_the_cli_message_and_changes_nothing():
    cfg = nipdem.preset("black")
    with pytest.raises(ValueError) as e:
        cfg["geometry.gap_m"] = -1e-6
    msg = str(e.value)
    assert "geometry.gap_m" in msg and "allowed" in msg, msg
    assert cfg["geometry.gap_m"] == 150e-6 and cfg.overrides == []
    # the CLI reports the same text for the same --set (exit 2)
    status, _, err = cli("params", "collision", "--preset", "black", "--set", "geometry.gap_m=-1e-06", "--json", check=False)
    assert status == 2
    assert msg in err, (msg, err)


@pytest.mark.parametrize("key,value,needle", [
    ("geometry.gap_mm", 1e-4, "geometry.gap_mm"),              # unknown key
    ("run.integrator", "leapfrog", "velocity_verlet"),         # not one of the choices: names them
    ("collision.toner_toner.restitution", 1.5, "restitution"),
    ("run.threads", 0, "run.threads"),
    ("geometry.gap_m", "wide", "geometry.gap_m"),              # wrong type
])
def test_invalid_values_name_the_key(key, value, needle):
    cfg = nipdem.preset("black")
    before = cfg.to_toml()
    with pytest.raises(ValueError) as e:
        cfg[key] = value
    assert needle in str(e.value), str(e.value)
    assert cfg.to_toml() == before


def test_update_is_all_or_nothing():
    cfg = nipdem.preset("black")
    with pytest.raises(ValueError):
        cfg.update({"geometry.gap_m": 120e-6, "run.threads": -3})
    assert cfg["geometry.gap_m"] == 150e-6
    cfg.update({"geometry.gap_m": 120e-6, "run.threads": 2})
    assert cfg["geometry.gap_m"] == 120e-6 and cfg["run.threads"] == 2


def test_save_and_load_round_trip(tmp_path):
    cfg = nipdem.preset("color")
    cfg["geometry.gap_m"] = 110e-6
    p = tmp_path / "c.toml"
    cfg.save(p)
    back = nipdem.load_config(p)
    assert back.to_toml() == cfg.to_toml()
    assert back["geometry.gap_m"] == 110e-6 and back.preset_name == "color"
    assert os.listdir(tmp_path) == ["c.toml"]  # no temp file left


def test_failed_save_leaves_nothing(tmp_path):
    cfg = nipdem.preset("black")
    (tmp_path / "a_folder").mkdir()
    with pytest.raises(ValueError) as e:
        cfg.save(tmp_path / "a_folder")  # cannot replace a folder by a file: invalid input
    assert "a_folder" in str(e.value)
    assert os.listdir(tmp_path) == ["a_folder"]  # no temp file left beside it
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(ValueError):  # its folder cannot be made: a file is in the way
        cfg.save(tmp_path / "a_file" / "c.toml")
    assert sorted(os.listdir(tmp_path)) == ["a_file", "a_folder"]
    assert (tmp_path / "a_file").read_text() == "x"


def test_load_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[geometry]\ngap_m = -5\n")
    with pytest.raises(ValueError) as e:
        nipdem.load_config(bad)
    assert str(bad) in str(e.value) and "geometry.gap_m" in str(e.value)
    with pytest.raises(ValueError) as e:
        nipdem.load_config(tmp_path)  # a folder
    assert str(tmp_path) in str(e.value)
