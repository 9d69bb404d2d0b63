"""The CLI's functions from Python return the JSON the `--json` commands print, and raise the
CLI's messages as ValueError."""
import pytest

import nipdem
from conftest import cli, cli_json


def test_collision_params_equal_the_cli():
    assert nipdem.collision_params("black") == cli_json("params", "collision", "--preset", "black")
    cfg = nipdem.preset("color")
    cfg["collision.stiffness_scale"] = 0.01
    assert nipdem.collision_params(cfg) == cli_json("params", "collision", "--preset", "color",
                                                    "--set", "collision.stiffness_scale=0.01")


@pytest.mark.parametrize("model", ["exact", "series", "approx"])
def test_force_electric_equals_the_cli(model):
    py = nipdem.force_electric(5.25e-6, 40, 1e-6, model=model)
    assert py == cli_json("force", "electric", "--radius", "5.25e-6", "--voltage", "40", "--gap", "1e-6", "--model", model)
    assert py["force_N"] > 0


def test_force_electric_with_layer_equals_the_cli():
    py = nipdem.force_electric(5.25e-6, 40, 1e-6, dielectric_layer=True, layer_thickness=1e-6)
    assert py == cli_json("force", "electric", "--radius", "5.25e-6", "--voltage", "40", "--gap", "1e-6",
                          "--dielectric-layer", "--layer-thickness", "1e-6")


def test_force_dipole_equals_the_cli():
    py = nipdem.force_dipole(3.7e-11, 13e-6, 30, pigments=13, samples=200, seed=4)
    assert py == cli_json("force", "dipole", "--moment", "3.7e-11", "--distance", "13e-6", "--angle", "30",
                          "--pigments", "13", "--samples", "200", "--seed", "4")
    assert py["force_std_N"] > 0


def test_field_probe_equals_the_cli():
    assert nipdem.field_probe(0, 100e-6) == cli_json("field", "probe", "--preset", "black", "--x", "0", "--y", "100e-6")
    py = nipdem.field_probe(-50e-6, 30e-6, preset="color", br=0.9, tip_depth=2e-4, radius=4e-6)
    assert py == cli_json("field", "probe", "--preset", "color", "--x", "-50e-6", "--y", "30e-6", "--br", "0.9",
                          "--tip-depth", "2e-4", "--radius", "4e-6")


def test_exported_field_map_is_what_the_probe_reads(tmp_path):
    out = tmp_path / "knife_br1.csv"
    nipdem.export_field_map(out, br=1.0, x0=-200e-6, x1=200e-6, nx=41, y0=0, y1=200e-6, ny=21)
    at_node = nipdem.field_probe(0.0, 100e-6, map=out)
    exact = nipdem.field_probe(0.0, 100e-6, br=1.0)
    assert at_node["By_T"] == pytest.approx(exact["By_T"], rel=1e-9)
    assert exact["By_T"] != pytest.approx(nipdem.field_probe(0.0, 100e-6)["By_T"], rel=1e-3)  # Br matters
    with pytest.raises(ValueError) as e:
        nipdem.export_field_map(tmp_path / "x.csv", br=3.0)
    assert "--br" in str(e.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["knife_br1.csv"]


def test_rc_response_equals_the_cli():
    py = nipdem.rc_response(5.9e11, 1.8e24, 3.9e-16, 1, "100:2000:100")
    assert py == cli_json("rc", "response", "--R", "5.9e11", "--Rd", "1.8e24", "--C", "3.9e-16", "--voltage", "1",
                          "--freq", "100:2000:100")
    assert len(py["rows"]) == 20
    assert nipdem.rc_response(5.9e11, 1.8e24, 3.9e-16, 1, (100, 2000, 100)) == py


def test_ldc_verify_equals_the_cli():
    py = nipdem.ldc_verify()
    assert py == cli_json("ldc", "verify")
    assert set(py) == {"table_3_1", "table_3_2", "table_3_3", "table_3_4", "fig_3_6"}


@pytest.mark.parametrize("call,args", [
    (lambda: nipdem.force_electric(-1.0, 40, 1e-6), ["force", "electric", "--radius", "-1", "--voltage", "40", "--gap", "1e-6"]),
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, model="magic"),
     ["force", "electric", "--radius", "5e-6", "--voltage", "40", "--gap", "1e-6", "--model", "magic"]),
    (lambda: nipdem.force_dipole(3.7e-11, 0.0, 0), ["force", "dipole", "--moment", "3.7e-11", "--distance", "0", "--angle", "0"]),
    (lambda: nipdem.field_probe(0, 100e-6, br=9), ["field", "probe", "--x", "0", "--y", "100e-6", "--br", "9"]),
    (lambda: nipdem.rc_response(-1, 1.8e24, 3.9e-16, 1, "100:200:100"),
     ["rc", "response", "--R", "-1", "--Rd", "1.8e24", "--C", "3.9e-16", "--voltage", "1", "--freq", "100:200:100"]),
    (lambda: nipdem.rc_response(5.9e11, 1.8e24, 3.9e-16, 1, "200:100"),
     ["rc", "response", "--R", "5.9e11", "--Rd", "1.8e24", "--C", "3.9e-16", "--voltage", "1", "--freq", "200:100"]),
])
def test_invalid_input_raises_the_cli_message(call, args):
    with pytest.raises(ValueError) as e:
        call()
    status, _, err = cli(*args, "--json", check=False)
    assert status == 2
    assert str(e.value) in err, (str(e.value), err)


# Values the CLI refuses (tests/hostile/test_hostile_rc.cpp, test_hostile_field.cpp) that the
# Python functions used to accept with a result (their checks were an older copy of the CLI's):
# now both call one library check each and give the same message.
_RC = (5.9e11, 1.8e24, 3.9e-16)
_RC_CLI = ["rc", "response", "--R", "5.9e11", "--Rd", "1.8e24", "--C", "3.9e-16"]
_EL_CLI = ["force", "electric", "--radius", "5e-06", "--gap", "1e-06"]
_DI_CLI = ["force", "dipole", "--distance", "1.3e-05"]


@pytest.mark.parametrize("call,args", [
    # rc response: a negative amplitude, Rm beyond its range, frequencies above the bound
    (lambda: nipdem.rc_response(*_RC, -1, "100:200:100"), [*_RC_CLI, "--voltage", "-1", "--freq", "100:200:100"]),
    (lambda: nipdem.rc_response(*_RC, 0, "100:200:100"), [*_RC_CLI, "--voltage", "0", "--freq", "100:200:100"]),
    (lambda: nipdem.rc_response(*_RC, 1, "100:200:100", Rm=1e308),
     [*_RC_CLI, "--voltage", "1", "--freq", "100:200:100", "--Rm", "1e+308"]),
    (lambda: nipdem.rc_response(*_RC, 1, "1e13:1e13:1"), [*_RC_CLI, "--voltage", "1", "--freq", "1e13:1e13:1"]),
    # force electric: options without effect, an approx coefficient / layer out of range
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, approx_coefficient=0.5),
     [*_EL_CLI, "--voltage", "40", "--approx-coefficient", "0.5"]),
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, layer_thickness=2e-06),
     [*_EL_CLI, "--voltage", "40", "--layer-thickness", "2e-06"]),
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, layer_permittivity=5),
     [*_EL_CLI, "--voltage", "40", "--layer-permittivity", "5"]),
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, model="approx", approx_coefficient=1e308),
     [*_EL_CLI, "--voltage", "40", "--model", "approx", "--approx-coefficient", "1e+308"]),
    (lambda: nipdem.force_electric(5e-6, 40, 1e-6, dielectric_layer=True, layer_permittivity=0.5),
     [*_EL_CLI, "--voltage", "40", "--dielectric-layer", "--layer-permittivity", "0.5"]),
    # force dipole: a negative moment, overlapping spheres, an absurd angle, samples < 1
    (lambda: nipdem.force_dipole(-3.7e-11, 13e-6, 0), [*_DI_CLI, "--moment", "-3.7e-11", "--angle", "0"]),
    (lambda: nipdem.force_dipole(3.7e-11, 10e-6, 0), ["force", "dipole", "--moment", "3.7e-11", "--distance", "1e-05",
                                                      "--angle", "0"]),
    (lambda: nipdem.force_dipole(3.7e-11, 13e-6, 1e308), [*_DI_CLI, "--moment", "3.7e-11", "--angle", "1e+308"]),
    (lambda: nipdem.force_dipole(3.7e-11, 13e-6, 0, samples=0),
     [*_DI_CLI, "--moment", "3.7e-11", "--angle", "0", "--samples", "0"]),
    # field probe: the knife edge (a corner of the magnet: NaN) and points inside its blocks
    (lambda: nipdem.field_probe(0, -1e-4), ["field", "probe", "--x", "0", "--y", "-0.0001"]),
    (lambda: nipdem.field_probe(-3e-4, -1e-4, preset="color"),
     ["field", "probe", "--preset", "color", "--x", "-0.0003", "--y", "-0.0001"]),
    (lambda: nipdem.field_probe(0, -5e-5, tip_depth=5e-5), ["field", "probe", "--tip-depth", "5e-05", "--x", "0", "--y", "-5e-05"]),
])
def test_python_refuses_what_the_cli_refuses(call, args):
    with pytest.raises(ValueError) as e:
        call()
    status, out, err = cli(*args, "--json", check=False)
    assert status == 2 and out == ""
    assert str(e.value) in err, (str(e.value), err)
