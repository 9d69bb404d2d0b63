// pybind11 bindings of the module `nipdem._nipdem` (the package nipdem/__init__.py wraps it;
// docs/python.md is the user's view). The only pybind11 translation unit: they compile slowly.
//
// Errors: nipdem::InputError -> ValueError, any other C++ exception -> RuntimeError, both with
// the library's message (the CLI prints the same text and exits 2 or 1).
// Long calls (simulation, experiments, LDC verification) release the GIL; the simulation polls
// for Ctrl-C between insert intervals (python/src/simulation.hpp) and stops with
// KeyboardInterrupt, leaving the run at a consistent state between steps.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <exception>
#include <new>

#include "functions.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/version.hpp"
#include "simulation.hpp"

namespace py = pybind11;
using nipdem::python::Simulation;

namespace {

// Checks for a pending signal (Ctrl-C) at most every 50 ms of wall time, taking the GIL only
// then: a check per insert interval would cost a GIL round trip every few steps.
class InterruptPoll {
 public:
  void operator()() {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(50)) return;
    last_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// A read-only NumPy view of an engine array; `owner` (the Python Simulation) is kept alive by
// the view. The engine may reallocate the vector when it inserts or removes bodies, so the view
// is valid until the next advance/step/restore (docs/python.md).
template <class T>
py::array view(const std::vector<T>& v, py::handle owner) {
  if (v.empty()) return py::array_t<T>(0);
  py::array a(py::dtype::of<T>(), {static_cast<py::ssize_t>(v.size())}, {static_cast<py::ssize_t>(sizeof(T))}, v.data(), owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

template <class T>
py::array copy(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

py::array body_array(const Simulation& s, const std::string& name, py::handle owner) {
  const auto& b = s.run().sim().bodies();
  if (name == "x") return view(b.x, owner);
  if (name == "y") return view(b.y, owner);
  if (name == "vx") return view(b.vx, owner);
  if (name == "vy") return view(b.vy, owner);
  if (name == "theta") return view(b.theta, owner);
  if (name == "omega") return view(b.omega, owner);
  if (name == "fx") return view(b.fx, owner);
  if (name == "fy") return view(b.fy, owner);
  if (name == "torque") return view(b.torque, owner);
  if (name == "mass") return view(b.mass, owner);
  if (name == "inertia") return view(b.inertia, owner);
  if (name == "id") return view(b.id, owner);
  if (name == "first_disc") return view(b.first_disc, owner);
  if (name == "n_discs") return view(b.n_discs, owner);
  if (name == "tag") return view(b.tag, owner);
  if (name == "size") return view(b.size, owner);
  throw nipdem::InputError("Simulation.bodies: no body array '" + name +
                           "' (allowed: x, y, vx, vy, theta, omega, fx, fy, torque, mass, inertia, id, first_disc, n_discs, tag, size)");
}

py::array disc_array(const Simulation& s, const std::string& name, py::handle owner) {
  const auto& d = s.run().sim().discs();
  if (name == "x") return view(d.x, owner);
  if (name == "y") return view(d.y, owner);
  if (name == "r") return view(d.r, owner);
  if (name == "body") return view(d.body, owner);
  if (name == "ox") return view(d.ox, owner);
  if (name == "oy") return view(d.oy, owner);
  if (name == "fx") return view(d.fx, owner);
  if (name == "fy") return view(d.fy, owner);
  if (name == "torque") return view(d.tq, owner);
  if (name == "fx_adhesion") return view(d.fax, owner);
  if (name == "fy_adhesion") return view(d.fay, owner);
  throw nipdem::InputError("Simulation.discs: no disc array '" + name +
                           "' (allowed: x, y, r, body, ox, oy, fx, fy, torque, fx_adhesion, fy_adhesion)");
}

// One Simulation must not run in two threads at once, nor be read while it runs (its arrays
// change under the reader): calls that release the GIL hold its busy flag, and every other
// call checks it, raising RuntimeError instead of racing.
class Busy {
 public:
  explicit Busy(const Simulation& s) : flag_(s.busy()) {
    if (flag_.exchange(true)) throw std::runtime_error(kMessage);
  }
  ~Busy() { flag_ = false; }
  Busy(const Busy&) = delete;
  Busy& operator=(const Busy&) = delete;
  static const Simulation& check(const Simulation& s) {
    if (s.busy()) throw std::runtime_error(kMessage);
    return s;
  }

 private:
  static constexpr const char* kMessage = "nipdem.Simulation: busy in another thread (advance, step, checkpoint or restore)";
  std::atomic<bool>& flag_;
};

const char* exit_name(nipdem::nip::Exit e) {
  using nipdem::nip::Exit;
  return e == Exit::developed ? "developed" : e == Exit::returned ? "returned" : "lost";
}

}  // namespace

PYBIND11_MODULE(_nipdem, m) {
  m.doc() = "nipdem C++ core (use the package `nipdem`, docs/python.md)";
  m.attr("version") = nipdem::kVersion;
  m.attr("git_hash") = nipdem::kGitHash;

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::error_already_set&) {
      throw;  // a Python error (KeyboardInterrupt from the poll): pybind11 restores it
    } catch (const py::builtin_exception&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const nipdem::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::exception& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });

  // ---- configuration
  m.def("preset_names", &nipdem::nip::preset_names);
  m.def("preset_text", &nipdem::nip::preset_text, py::arg("name"));
  m.def(
      "resolve_config",
      [](const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
        const auto c = nipdem::nip::parse_nip_config(text, file, overrides);
        return py::make_tuple(c.resolved_toml, c.preset);
      },
      py::arg("text"), py::arg("file"), py::arg("overrides"),
      "Validates a configuration exactly as `nipdem run FILE --set ...`; returns (resolved TOML, preset).");
  m.def(
      "read_file",
      [](const std::string& path, std::uintmax_t max_bytes) {
        std::string s;
        {
          py::gil_scoped_release release;
          s = nipdem::io::read_file(path, max_bytes);
        }
        return py::bytes(s);
      },
      py::arg("path"), py::arg("max_bytes") = nipdem::io::kMaxInputBytes,
      "Reads a file as nipdem reads its inputs (refuses folders, devices, oversized files).");
  m.attr("max_checkpoint_bytes") = nipdem::io::kMaxCheckpointBytes;
  m.def(
      "write_file_atomic",
      [](const std::string& path, py::bytes content) {
        const std::string s = content;
        py::gil_scoped_release release;
        nipdem::io::write_file_atomic(path, s);
      },
      py::arg("path"), py::arg("content"), "Temp file in the same folder, fsync, rename: never a half-written file.");

  // ---- simulation
  py::class_<Simulation>(m, "Simulation")
      .def(py::init<const std::string&, const std::string&, const std::vector<std::string>&>(), py::arg("text"),
           py::arg("file"), py::arg("overrides"), py::call_guard<py::gil_scoped_release>())
      .def(
          "advance_to",
          [](Simulation& s, double t_end) {
            Busy busy(s);
            InterruptPoll poll;
            py::gil_scoped_release release;
            s.advance_to(t_end, std::ref(poll));
          },
          py::arg("t_end"))
      .def(
          "step",
          [](Simulation& s, std::int64_t n) {
            if (n < 0) throw nipdem::InputError("Simulation.step: n = " + std::to_string(n) + ": must be >= 0");
            Busy busy(s);
            InterruptPoll poll;
            py::gil_scoped_release release;
            s.step(n, std::ref(poll));
          },
          py::arg("n"))
      .def_property_readonly("time", [](const Simulation& s) { return Busy::check(s).run().sim().time(); })
      .def_property_readonly("step_count", [](const Simulation& s) { return Busy::check(s).run().sim().step_count(); })
      .def_property_readonly("dt", [](const Simulation& s) { return Busy::check(s).run().time_step().dt; })
      .def_property_readonly("dt_bound", [](const Simulation& s) { return Busy::check(s).run().time_step().bound; })
      .def_property_readonly("insert_interval", [](const Simulation& s) { return Busy::check(s).run().config().insert_interval; })
      .def_property_readonly("n_bodies", [](const Simulation& s) { return Busy::check(s).run().sim().bodies().x.size(); })
      .def_property_readonly("n_discs", [](const Simulation& s) { return Busy::check(s).run().sim().discs().x.size(); })
      .def_property_readonly("contacts", [](const Simulation& s) { return Busy::check(s).run().sim().contacts(); })
      .def_property_readonly("inserted", [](const Simulation& s) { return Busy::check(s).run().inserted(); })
      .def_property_readonly("inserted_in_roller_pits", [](const Simulation& s) { return Busy::check(s).run().inserted_on_roller(); })
      .def_property_readonly("removed",
                             [](const Simulation& s) {
                               using nipdem::nip::Exit;
                               py::dict d;
                               for (Exit e : {Exit::developed, Exit::returned, Exit::lost}) d[exit_name(e)] = Busy::check(s).run().removed(e);
                               return d;
                             })
      .def("energy",
           [](const Simulation& s) {
             const auto e = Busy::check(s).run().sim().energy();
             py::dict d;
             d["kinetic_J"] = e.kinetic;
             d["elastic_J"] = e.elastic;
             d["gravity_J"] = e.gravity;
             d["total_J"] = e.total();
             return d;
           })
      .def(
          "body_array", [](py::object self, const std::string& name) { return body_array(Busy::check(self.cast<const Simulation&>()), name, self); },
          py::arg("name"))
      .def(
          "disc_array",
          [](py::object self, const std::string& name) {
            auto& s = self.cast<Simulation&>();
            Busy::check(s);
            // the adhesive part is filled when read (the engine's step does not keep it)
            if (name == "fx_adhesion" || name == "fy_adhesion") s.run().sim().update_adhesive_parts();
            return disc_array(s, name, self);
          },
          py::arg("name"))
      .def("provider_names",
           [](const Simulation& s) {
             std::vector<std::string> n;
             for (const auto& f : Busy::check(s).run().sim().forces()) n.push_back(f->name());
             return n;
           })
      .def(
          "provider_force",
          [](py::object self, std::size_t k) {
            const auto& sim = Busy::check(self.cast<const Simulation&>()).run().sim();
            if (k >= sim.forces().size())
              throw nipdem::InputError("Simulation.provider_force: index " + std::to_string(k) + " out of range [0, " +
                                       std::to_string(sim.forces().size()) + ")");
            return py::make_tuple(view(sim.provider_fx(k), self), view(sim.provider_fy(k), self));
          },
          py::arg("k"))
      .def("voltages", [](const Simulation& s) { return copy(Busy::check(s).voltages()); })
      // the charge model's own vector, in the order of its last evaluation (tests only)
      .def("_voltages_as_stored",
           [](const Simulation& s) {
             const auto* e = Busy::check(s).run().electric();
             return e ? copy(e->voltage()) : copy(std::vector<double>{});
           })
      .def_property_readonly("drum_capacity_F",
                             [](const Simulation& s) { return Busy::check(s).run().config().electric.rc.C_td_F; })
      .def_property_readonly("electric_enabled", [](const Simulation& s) { return Busy::check(s).run().electric() != nullptr; })
      .def(
          "assembly_x", [](const Simulation& s, double max_h, double min_h) { return copy(Busy::check(s).run().assembly_x(max_h, min_h)); },
          py::arg("max_height"), py::arg("min_height") = -1.0)
      .def("removals",
           [](const Simulation& s) {
             const auto& r = Busy::check(s).run().removals();
             std::vector<double> t, x, y, size;
             std::vector<std::int64_t> id;
             std::vector<std::int32_t> where;
             for (const auto& e : r) {
               t.push_back(e.time); x.push_back(e.x); y.push_back(e.y); size.push_back(e.size);
               id.push_back(e.id); where.push_back(static_cast<std::int32_t>(e.where));
             }
             py::dict d;
             d["time_s"] = copy(t);
             d["exit"] = copy(where);
             d["x_m"] = copy(x);
             d["y_m"] = copy(y);
             d["diameter_m"] = copy(size);
             d["body_id"] = copy(id);
             return d;
           })
      .def("describe", [](const Simulation& s) { return Busy::check(s).run().describe().dump(); })
      .def("resolved_toml", [](const Simulation& s) { return Busy::check(s).run().config().resolved_toml; })
      .def("checkpoint",
           [](const Simulation& s) {
             Busy busy(s);
             std::string blob;
             {
               py::gil_scoped_release release;
               blob = s.checkpoint();
             }
             return py::bytes(blob);
           })
      .def(
          "restore",
          [](Simulation& s, py::bytes blob, const std::string& where) {
            Busy busy(s);
            std::string b = blob;
            py::gil_scoped_release release;
            s.restore(b, where);
          },
          py::arg("blob"), py::arg("where") = "checkpoint");

  // ---- the CLI's functions (JSON text; the package parses it)
  m.def("collision_params", &nipdem::python::collision_params, py::arg("text"), py::arg("file"), py::arg("overrides"));
  // approx_coefficient, layer_thickness, layer_permittivity: None is "not given" (the CLI's
  // default applies); a value given where it has no effect is refused, as by the CLI.
  m.def(
      "force_electric",
      [](double radius, double voltage, double gap, const std::string& model, std::optional<double> a, bool layer,
         std::optional<double> lt, std::optional<double> le) {
        nipdem::python::ElectricArgs e;
        e.radius_m = radius; e.voltage_V = voltage; e.gap_m = gap; e.model = model; e.approx_coefficient = a;
        e.dielectric_layer = layer; e.layer_thickness_m = lt; e.layer_permittivity = le;
        return nipdem::python::force_electric(e);
      },
      py::arg("radius"), py::arg("voltage"), py::arg("gap"), py::arg("model") = "exact", py::arg("approx_coefficient") = py::none(),
      py::arg("dielectric_layer") = false, py::arg("layer_thickness") = py::none(), py::arg("layer_permittivity") = py::none());
  {
    const nipdem::python::DipoleArgs d;
    m.def(
        "force_dipole",
        [](double moment, double distance, double angle, double radius, int pigments, int samples, std::uint64_t seed) {
          nipdem::python::DipoleArgs a{moment, distance, angle, radius, pigments, samples, seed};
          py::gil_scoped_release release;
          return nipdem::python::force_dipole(a);
        },
        py::arg("moment"), py::arg("distance"), py::arg("angle"), py::arg("radius") = d.radius_m, py::arg("pigments") = d.pigments,
        py::arg("samples") = d.samples, py::arg("seed") = d.seed);
  }
  m.def(
      "field_probe",
      [](double x, double y, const std::string& preset, const std::string& map, std::optional<double> radius,
         std::optional<double> tip_depth, std::optional<double> br) {
        return nipdem::python::field_probe({preset, map, radius, tip_depth, br}, x, y);
      },
      py::arg("x"), py::arg("y"), py::arg("preset"), py::arg("map"), py::arg("radius"), py::arg("tip_depth"), py::arg("br"));
  m.def(
      "field_export",
      [](const std::string& out, const std::string& preset, std::optional<double> tip_depth, std::optional<double> br, double x0,
         double x1, int nx, double y0, double y1, int ny) {
        py::gil_scoped_release release;
        return nipdem::python::field_export({preset, "", std::nullopt, tip_depth, br}, x0, x1, nx, y0, y1, ny, out);
      },
      py::arg("out"), py::arg("preset"), py::arg("tip_depth"), py::arg("br"), py::arg("x0"), py::arg("x1"), py::arg("nx"),
      py::arg("y0"), py::arg("y1"), py::arg("ny"));
  m.def("rc_response", &nipdem::python::rc_response, py::arg("R"), py::arg("Rd"), py::arg("C"), py::arg("Rm"), py::arg("voltage"),
        py::arg("freq"));
  m.attr("rc_default_Rm") = nipdem::python::rc_default_Rm();
  m.def("ldc_verify", &nipdem::python::ldc_verify, py::call_guard<py::gil_scoped_release>());
  m.def("run_experiment", &nipdem::python::run_experiment, py::arg("name"), py::arg("options"),
        py::call_guard<py::gil_scoped_release>());
}
