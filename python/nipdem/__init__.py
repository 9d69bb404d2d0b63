"""nipdem from Python: configurations, simulations, the CLI's functions and experiments.

    import nipdem
    cfg = nipdem.preset("black")
    cfg["geometry.window_x_min_m"] = -150e-6       # validated as `--set` is: ValueError if not
    sim = nipdem.Simulation(cfg)
    sim.advance(1e-4)                              # GIL released; Ctrl-C -> KeyboardInterrupt
    x = sim.bodies.x                               # NumPy view of the engine's array

The API and its guarantees (which arrays are views, what invalidates them) are in
docs/python.md. Errors: invalid input raises ValueError with the CLI's message (file, key,
value, allowed range); any other failure RuntimeError.
"""

import json as _json
import math as _math
import os as _os
import tomllib as _tomllib

import numpy as _np

# The engine's OpenMP waits: a short spin, as the CLI sets them (core/wait_policy.hpp,
# docs/performance.md, tenth pass), unless the user chose. libgomp reads them once, when the
# extension below loads it; if it was loaded before (by another module) they stay as they were.
if "OMP_WAIT_POLICY" not in _os.environ and "GOMP_SPINCOUNT" not in _os.environ:
    _os.environ["GOMP_SPINCOUNT"] = "10000"

from . import _nipdem  # noqa: E402
from ._nipdem import git_hash, version  # noqa: E402

__all__ = [
    "Config", "Simulation", "preset", "preset_names", "load_config", "read_run",
    "collision_params", "force_electric", "force_dipole", "field_probe", "export_field_map",
    "rc_response", "ldc_verify", "front_position", "reduction", "vo_level", "edge_sharpness",
    "ExperimentResult", "version", "git_hash",
]


# ---------------------------------------------------------------- configuration

def _toml_literal(value):
    """A Python value as the TOML literal `--set KEY=VALUE` reads."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if _math.isnan(value):
            return "nan"
        if _math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)  # shortest round-trip form: the value the loader sees is this float
    if isinstance(value, str):
        return _json.dumps(value, ensure_ascii=False)  # a TOML basic string
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_literal(v) for v in value) + "]"
    if isinstance(value, _np.generic):
        return _toml_literal(value.item())
    raise TypeError(f"cannot set a config value of type {type(value).__name__}")


def _write_atomic(path, content):
    """The library's atomic write (temp file "<path>.tmp.<pid>", fsync, rename). A path that
    cannot be an output file (a folder, a device, empty, an unwritable folder) raises
    ValueError naming it; a failed write leaves nothing behind (io::write_file_atomic)."""
    _nipdem.write_file_atomic(_os.fspath(path), content)


def _leaves(table, prefix=""):
    for k, v in table.items():
        key = prefix + k
        if isinstance(v, dict):
            yield from _leaves(v, key + ".")
        else:
            yield key, v


class Config:
    """A nip configuration: a TOML text laid over its preset, plus KEY=VALUE overrides.

    Dict-like on dotted keys of the complete resolved configuration (`config.toml` of a run
    folder): ``cfg["geometry.gap_m"]`` is the value a run would use; ``cfg[key] = value`` is
    checked by the library's loader exactly as ``--set key=value`` is and raises ValueError
    with the CLI's message (the config is unchanged then); ``del cfg[key]`` drops an override.
    """

    def __init__(self, text, file="<string>", overrides=(), origin=None):
        self._text = text
        self._file = file
        self._origin = origin  # ("preset", name) | ("file", path) | None
        self._overrides = list(overrides)
        self._resolve(self._overrides)

    # -- construction
    @classmethod
    def preset(cls, name="black"):
        return cls(_nipdem.preset_text(name), "preset:" + name, origin=("preset", name))

    @classmethod
    def load(cls, path):
        """Reads a config file as `nipdem run FILE` does (laid over the preset it names)."""
        path = _os.fspath(path)
        return cls(_nipdem.read_file(path).decode("utf-8"), path, origin=("file", path))

    @classmethod
    def from_toml(cls, text, name="<string>"):
        return cls(text, name)

    def copy(self):
        c = Config.__new__(Config)
        c._text, c._file, c._origin = self._text, self._file, self._origin
        c._overrides = list(self._overrides)
        c._resolved, c._preset, c._table = self._resolved, self._preset, self._table
        return c

    def _resolve(self, overrides):
        resolved, preset = _nipdem.resolve_config(self._text, self._file, overrides)
        self._resolved, self._preset = resolved, preset
        self._table = _tomllib.loads(resolved)

    # -- dict-like access
    def __getitem__(self, key):
        node = self._table
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                raise KeyError(key)
            node = node[part]
        return _json.loads(_json.dumps(node)) if isinstance(node, (dict, list)) else node

    def __setitem__(self, key, value):
        self.set(key, value)

    def set(self, key, value):
        """Sets one key to a Python value (bool, int, float, str, or a list of them)."""
        self.set_raw(key, _toml_literal(value))

    def set_raw(self, key, literal):
        """Sets one key from its TOML literal text, exactly as `--set key=literal`."""
        trial = [o for o in self._overrides if o.split("=", 1)[0] != key] + [f"{key}={literal}"]
        self._resolve(trial)  # raises ValueError and leaves everything as it was
        self._overrides = trial

    def update(self, values=(), **kw):
        """Sets several keys at once (checked together: either all are set or none)."""
        items = list(dict(values).items()) + list(kw.items())
        keys = {k for k, _ in items}
        trial = [o for o in self._overrides if o.split("=", 1)[0] not in keys]
        trial += [f"{k}={_toml_literal(v)}" for k, v in items]
        self._resolve(trial)
        self._overrides = trial

    def __delitem__(self, key):
        trial = [o for o in self._overrides if o.split("=", 1)[0] != key]
        if len(trial) == len(self._overrides):
            raise KeyError(f"{key}: not overridden (the file or preset sets it)")
        self._resolve(trial)
        self._overrides = trial

    def __contains__(self, key):
        try:
            self[key]
            return True
        except KeyError:
            return False

    def get(self, key, default=None):
        try:
            return self[key]
        except KeyError:
            return default

    def keys(self):
        return [k for k, _ in _leaves(self._table)]

    def items(self):
        return list(_leaves(self._table))

    def __iter__(self):
        return iter(self.keys())

    def __len__(self):
        return len(self.keys())

    def __repr__(self):
        return f"<nipdem.Config {self._file} preset={self._preset} overrides={self._overrides}>"

    # -- the text
    @property
    def overrides(self):
        """The KEY=VALUE strings applied over the file, in order (as `--set`)."""
        return list(self._overrides)

    @property
    def file(self):
        return self._file

    @property
    def preset_name(self):
        return self._preset

    def to_toml(self):
        """The complete resolved configuration (what a run folder's config.toml holds)."""
        return self._resolved

    def to_dict(self):
        return _json.loads(_json.dumps(self._table))

    def save(self, path):
        """Writes the resolved configuration atomically (a temp file renamed over `path`)."""
        _write_atomic(path, self._resolved.encode("utf-8"))

    # -- how the CLI's experiment options name it
    def _experiment_source(self, out):
        """(preset, config path, sets) for ExperimentOptions; a config without a file is
        written to OUT/input_config.toml first."""
        if self._origin and self._origin[0] == "preset":
            return self._origin[1], "", list(self._overrides)
        if self._origin and self._origin[0] == "file":
            return "black", self._origin[1], list(self._overrides)
        _os.makedirs(out, exist_ok=True)
        path = _os.path.join(out, "input_config.toml")
        _write_atomic(path, self._text.encode("utf-8"))
        return "black", path, list(self._overrides)


def preset(name="black"):
    """The complete configuration of a CPS700 preset ("black" or "color")."""
    return Config.preset(name)


def preset_names():
    return list(_nipdem.preset_names())


def load_config(path):
    return Config.load(path)


def _as_config(config):
    if isinstance(config, Config):
        return config
    if isinstance(config, str) and config in _nipdem.preset_names():
        return Config.preset(config)
    return Config.load(config)


# ---------------------------------------------------------------- simulation

class _Arrays:
    """Named arrays of one store (bodies or discs), fetched on access."""

    def __init__(self, get, names):
        self._get, self._names = get, names

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return self._get(name)

    def __getitem__(self, name):
        return self._get(name)

    def keys(self):
        return list(self._names)

    def to_dict(self, copy=True):
        return {n: (self._get(n).copy() if copy else self._get(n)) for n in self._names}

    def __dir__(self):
        return list(self._names)

    def __repr__(self):
        return f"<arrays {', '.join(self._names)}>"


_BODY_ARRAYS = ("x", "y", "vx", "vy", "theta", "omega", "fx", "fy", "torque", "mass", "inertia", "id",
                "first_disc", "n_discs", "tag", "size")
_DISC_ARRAYS = ("x", "y", "r", "body", "ox", "oy", "fx", "fy", "torque", "fx_adhesion", "fy_adhesion")


class Simulation:
    """A nip simulation of a Config (or a config file / preset name), as `nipdem run` makes it.

    advance/advance_to/step release the GIL; while one runs, any other call on the same
    Simulation from another thread raises RuntimeError (busy) instead of racing. Ctrl-C stops
    a simulation advancing in the main thread (KeyboardInterrupt, at an insert-interval
    boundary; the run can go on).

    Arrays: ``sim.bodies.<name>`` and ``sim.discs.<name>`` are read-only NumPy *views* of the
    engine's arrays (no copy); each keeps the simulation alive, but is valid only until the
    next advance/advance_to/step/restore (the engine inserts and removes bodies, which
    reallocates its arrays). ``positions()``, ``velocities()``, ``charges()``, ``voltages()``
    and ``removals()`` return copies.
    """

    def __init__(self, config):
        self.config = _as_config(config).copy()
        self._sim = _nipdem.Simulation(self.config._text, self.config._file, self.config.overrides)
        self.bodies = _Arrays(self._sim.body_array, _BODY_ARRAYS)
        self.discs = _Arrays(self._sim.disc_array, _DISC_ARRAYS)

    # -- running
    def advance(self, time_s):
        """Advances by `time_s` of simulated time [s] (to the step nearest the target)."""
        self._sim.advance_to(self._sim.time + float(time_s))

    def advance_to(self, t_s):
        """Advances to simulated time `t_s` [s]; `nipdem run` with run.end_time_s = t_s stops
        at the same step with the same state, bit for bit."""
        self._sim.advance_to(float(t_s))

    def step(self, n=1):
        """Exactly `n` time steps (with the inflow/outflow passes due among them)."""
        self._sim.step(int(n))

    # -- state
    time = property(lambda self: self._sim.time, doc="simulated time [s]")
    step_count = property(lambda self: self._sim.step_count)
    dt = property(lambda self: self._sim.dt, doc="time step [s]")
    dt_bound = property(lambda self: self._sim.dt_bound, doc="stability bound of the integrator [s]")
    insert_interval = property(lambda self: self._sim.insert_interval, doc="steps between inflow/outflow passes")
    n_bodies = property(lambda self: self._sim.n_bodies, doc="toner particles (clusters) in the window")
    n_discs = property(lambda self: self._sim.n_discs)
    contacts = property(lambda self: self._sim.contacts, doc="contacts in the last force evaluation")
    inserted = property(lambda self: self._sim.inserted)
    removed = property(lambda self: self._sim.removed, doc="{'developed', 'returned', 'lost'} counts")

    def energy(self):
        """{'kinetic_J', 'elastic_J', 'gravity_J', 'total_J'} of the current state."""
        return self._sim.energy()

    @property
    def cluster_ids(self):
        """Stable id of each body (view); bodies are clusters of discs, discs.body maps a disc
        to its body's index."""
        return self._sim.body_array("id")

    def positions(self):
        """(n_bodies, 2) centres of mass [m] (copy)."""
        return _np.column_stack((self._sim.body_array("x"), self._sim.body_array("y")))

    def velocities(self):
        """(n_bodies, 2) centre-of-mass velocities [m/s] (copy)."""
        return _np.column_stack((self._sim.body_array("vx"), self._sim.body_array("vy")))

    def voltages(self):
        """Capacitor voltage u [V] of each body (copy; §2.5.5), zeros' length without [electric]
        is 0; NaN after a restore until the next step."""
        return self._sim.voltages()

    def charges(self):
        """Charge q = C_td u [C] of each body on its capacitor to the drum (copy)."""
        return self._sim.voltages() * self._sim.drum_capacity_F

    def forces(self):
        """Force per kind [N] from the last evaluation: 'total' (fx, fy) per body, one entry per
        body-force provider ('magnetic', 'electric', ...) per body, and 'adhesion' (fx, fy) per
        disc (the adhesive part of the disc forces). Views, valid as the body arrays."""
        out = {"total": (self._sim.body_array("fx"), self._sim.body_array("fy"))}
        for k, name in enumerate(self._sim.provider_names()):
            out[name] = self._sim.provider_force(k)
        out["adhesion"] = (self._sim.disc_array("fx_adhesion"), self._sim.disc_array("fy_adhesion"))
        return out

    def assembly_x(self, max_height, min_height=-1.0):
        """x [m] of the bodies resting on the roller between the heights (front/back, §5.1)."""
        return self._sim.assembly_x(max_height, min_height)

    def removals(self):
        """Every body that left the window: arrays time_s, exit (0 developed, 1 returned,
        2 lost), x_m, y_m, diameter_m, body_id (copies)."""
        return self._sim.removals()

    def describe(self):
        """Geometry and parameters, as summary.json's "geometry"."""
        return _json.loads(self._sim.describe())

    # -- checkpoints
    def checkpoint(self):
        """The whole run state as bytes (the format of a run folder's checkpoint.bin)."""
        return self._sim.checkpoint()

    def restore(self, blob, where="checkpoint"):
        """Restores a checkpoint of a run of the same configuration; a refused one raises
        ValueError naming `where` and leaves the simulation unchanged."""
        self._sim.restore(bytes(blob), where)

    def save_checkpoint(self, path):
        """Writes checkpoint() to `path` atomically."""
        _write_atomic(path, self._sim.checkpoint())

    def load_checkpoint(self, path):
        path = _os.fspath(path)
        self._sim.restore(_nipdem.read_file(path, _nipdem.max_checkpoint_bytes), path)

    def __repr__(self):
        return f"<nipdem.Simulation t={self.time:.6g} s, {self.n_bodies} bodies, {self.config.file}>"


# ---------------------------------------------------------------- run folders

def _read_csv(path):
    """A CSV of nipdem (header row, '#' comments) as {column: array}."""
    with open(path, encoding="utf-8") as f:
        lines = [ln for ln in f.read().splitlines() if ln and not ln.startswith("#")]
    if not lines:
        return {}
    names = lines[0].split(",")
    rows = [ln.split(",") for ln in lines[1:]]
    out = {}
    for j, name in enumerate(names):
        col = [r[j] if j < len(r) else "" for r in rows]
        out[name] = _column(col)
    return out


def _column(col):
    """Integers (counts, ids, 64-bit seeds) stay exact integers; other numbers are floats
    (empty = NaN); anything else stays text."""
    try:
        ints = [int(v) for v in col]
        if all(-2**63 <= v < 2**63 for v in ints):
            return _np.array(ints, dtype=_np.int64)
        if all(0 <= v < 2**64 for v in ints):
            return _np.array(ints, dtype=_np.uint64)
    except ValueError:
        pass
    try:
        return _np.array([float(v) if v != "" else _math.nan for v in col])
    except ValueError:
        return _np.array(col)


def read_run(folder):
    """A run folder of `nipdem run` (or Python): summary, config, time series, removals,
    coverage (print runs) as {column: array}, and the path of its checkpoint."""
    folder = _os.fspath(folder)
    out = {"folder": folder}
    p = _os.path.join(folder, "summary.json")
    out["summary"] = _json.loads(_nipdem.read_file(p).decode()) if _os.path.exists(p) else None
    out["config"] = Config.load(_os.path.join(folder, "config.toml"))
    for name in ("timeseries", "removals", "coverage"):
        p = _os.path.join(folder, name + ".csv")
        out[name] = _read_csv(p) if _os.path.exists(p) else None
    p = _os.path.join(folder, "checkpoint.bin")
    out["checkpoint"] = p if _os.path.exists(p) else None
    return out


# ---------------------------------------------------------------- the CLI's functions

def _j(text):
    return _json.loads(text)


def collision_params(config="black"):
    """`nipdem params collision --json` for a Config, a preset name or a config file."""
    c = _as_config(config)
    return _j(_nipdem.collision_params(c._text, c._file, c.overrides))


def force_electric(radius, voltage, gap, model="exact", approx_coefficient=None, dielectric_layer=False,
                   layer_thickness=None, layer_permittivity=None):
    """`nipdem force electric --json`: force on a grounded conducting sphere [N]."""
    kw = {}
    if approx_coefficient is not None:
        kw["approx_coefficient"] = approx_coefficient
    if layer_thickness is not None:
        kw["layer_thickness"] = layer_thickness
    if layer_permittivity is not None:
        kw["layer_permittivity"] = layer_permittivity
    return _j(_nipdem.force_electric(radius, voltage, gap, model=model, dielectric_layer=dielectric_layer, **kw))


def force_dipole(moment, distance, angle, radius=6e-6, pigments=1, samples=1000, seed=1):
    """`nipdem force dipole --json` (angle in degrees)."""
    if int(seed) < 0:
        raise ValueError(f"force dipole: key 'seed' = {seed}: must be >= 0")
    return _j(_nipdem.force_dipole(moment, distance, angle, radius, int(pigments), int(samples), int(seed)))


def field_probe(x, y, preset="black", map=None, radius=None, tip_depth=None, br=None):
    """`nipdem field probe --json`: B, grad B and the magnet force on a toner at (x, y)."""
    return _j(_nipdem.field_probe(x, y, preset, _os.fspath(map) if map else "", radius, tip_depth, br))


def export_field_map(out, preset="black", tip_depth=None, br=None, x0=-500e-6, x1=500e-6, nx=51, y0=0.0, y1=400e-6, ny=21):
    """Samples the preset's magnet (knife or colour pole, with `tip_depth` [m] / `br` [T]
    changed as `field probe --tip-depth/--br` does) on a grid and writes the field-map CSV that
    `magnet.field = "map"`, `magnet.map_file = OUT` reads (`nipdem field export` with the
    probe's magnet options). Atomic write."""
    return _j(_nipdem.field_export(_os.fspath(out), preset, tip_depth, br, x0, x1, int(nx), y0, y1, int(ny)))


def rc_response(R, Rd, C, voltage, freq, Rm=None):
    """`nipdem rc response --json`; `freq` is "F1:F2:STEP" or a tuple (f1, f2, step) [Hz]."""
    if not isinstance(freq, str):
        freq = ":".join(repr(float(f)) for f in freq)
    return _j(_nipdem.rc_response(R, Rd, C, _nipdem.rc_default_Rm if Rm is None else Rm, voltage, freq))


def ldc_verify():
    """`nipdem ldc verify --json`: the LDC verification tables of thesis §3.8-3.10."""
    return _j(_nipdem.ldc_verify())


class ExperimentResult(dict):
    """The experiment's JSON (the dict `nipdem experiment ... --json` prints) with the CSV
    files it names read into ``.series``: {json key path: {column: array}}."""

    series = None


def _csv_files(node, path=""):
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _csv_files(v, f"{path}.{k}" if path else k)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _csv_files(v, f"{path}[{i}]")
    elif isinstance(node, str) and node.endswith(".csv") and _os.path.isfile(node):
        yield path, node


def _experiment(name, config, out, seed, jobs, progress, **options):
    out = _os.fspath(out) if out is not None else _os.path.join("runs", name)
    if int(seed) < 0:
        raise ValueError(f"experiment: key '--seed' = {seed}: must be >= 0")
    preset_name, path, sets = _as_config(config)._experiment_source(out)
    opts = {"preset": preset_name, "config": path, "sets": sets, "seed": int(seed), "jobs": int(jobs),
            "out": out, "progress": bool(progress)}
    def finite(x):  # JSON has no NaN/inf: sent as strings the C++ side reads back
        if isinstance(x, float) and not _math.isfinite(x):
            return "nan" if _math.isnan(x) else ("inf" if x > 0 else "-inf")
        return x
    for k, v in options.items():
        if v is not None:
            opts[k] = [finite(float(x)) for x in v] if isinstance(v, (list, tuple, _np.ndarray)) else finite(v)
    res = ExperimentResult(_j(_nipdem.run_experiment(name, _json.dumps(opts))))
    res.series = {key: _read_csv(p) for key, p in _csv_files(res)}
    return res


def front_position(config="black", gaps_m=(150e-6,), sleeve_speeds_m_per_min=None, max_time_s=None, min_time_s=None,
                   seed=1, jobs=1, out=None, progress=False):
    """`nipdem experiment front-position --json` (§5.1); config overrides apply to every point."""
    return _experiment("front-position", config, out, seed, jobs, progress, gaps_m=[float(g) for g in gaps_m],
                       sleeve_speeds_m_per_min=sleeve_speeds_m_per_min, max_time_s=max_time_s, min_time_s=min_time_s)


def reduction(config="black", cohesion_ratios=(1.0,), time_s=None, pile_width_m=None, pile_height_m=None, pits=None,
              seed=1, jobs=1, out=None, progress=False):
    """`nipdem experiment reduction --json` (§4.6)."""
    return _experiment("reduction", config, out, seed, jobs, progress, cohesion_ratios=[float(r) for r in cohesion_ratios],
                       time_s=time_s, pile_width_m=pile_width_m, pile_height_m=pile_height_m, pits=pits)


def vo_level(config="black", step_V=None, coarse_step_V=None, v0_V=None, v_max_V=None, seeds=None, line_length_m=None,
             line_start_m=None, extra_time_s=None, seed=1, jobs=1, out=None, progress=False):
    """`nipdem experiment vo-level --json` (§5.2)."""
    return _experiment("vo-level", config, out, seed, jobs, progress, step_V=step_V, coarse_step_V=coarse_step_V, v0_V=v0_V,
                       v_max_V=v_max_V, seeds=seeds, line_length_m=line_length_m, line_start_m=line_start_m,
                       extra_time_s=extra_time_s)


def edge_sharpness(config="black", realizations=None, line_length_m=None, line_start_m=None, extra_time_s=None,
                   margin_m=None, bootstrap=None, seed=1, jobs=1, out=None, progress=False):
    """`nipdem experiment edge-sharpness --json` (§1.4, §5.3)."""
    return _experiment("edge-sharpness", config, out, seed, jobs, progress, realizations=realizations,
                       line_length_m=line_length_m, line_start_m=line_start_m, extra_time_s=extra_time_s,
                       margin_m=margin_m, bootstrap=bootstrap)
