#include "functions.hpp"

#include <cmath>
#include <limits>
#include <type_traits>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/experiments/calibrate_rc.hpp"
#include "nipdem/experiments/edge_sharpness.hpp"
#include "nipdem/experiments/front_position.hpp"
#include "nipdem/experiments/reduction.hpp"
#include "nipdem/experiments/vo_level.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/dipole.hpp"
#include "nipdem/models/dipole_pigments.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/models/probe_circuit.hpp"
#include "nipdem/solvers/ldc/verify.hpp"

namespace nipdem::python {

using nlohmann::json;

std::string collision_params(const std::string& text, const std::string& file, const std::vector<std::string>& overrides) {
  return nip::collision_json(nip::parse_nip_config(text, file, overrides)).dump();
}

std::string force_electric(const ElectricArgs& a) {
  // the checks and the computation of `nipdem force electric` (apps/cli/cmd_force_electric.cpp)
  const electric::ForceAnswer r = electric::force_query(a);
  json j;
  j["force_N"] = r.force_N;
  j["model"] = to_string(r.params.model);
  j["radius_m"] = a.radius_m;
  j["voltage_V"] = a.voltage_V;
  j["gap_m"] = a.gap_m;
  j["effective_gap_m"] = r.effective_gap_m;
  j["gap_over_radius"] = r.effective_gap_m / a.radius_m;
  j["force_exact_N"] = r.force_exact_N;
  j["force_small_gap_limit_N"] = r.force_small_gap_limit_N;
  j["capacitance_F"] = r.capacitance_F;
  return j.dump();
}

std::string force_dipole(const DipoleArgs& q) {
  // the checks and the computation of `nipdem force dipole` (apps/cli/cmd_force_dipole.cpp)
  const dipole::DipoleAnswer ans = dipole::force_dipole_query(q);
  const dipole::PigmentStudyResult& r = ans.study;
  const double cherry = ans.cherry_pit_force_N;
  json j{{"moment_Am2", q.moment_Am2},
         {"distance_m", q.distance_m},
         {"angle_deg", q.angle_deg},
         {"radius_m", q.radius_m},
         {"pigments", q.pigments},
         {"samples", r.samples},
         {"seed", q.seed},
         {"force_N", r.force_mean_vec_abs_N},
         {"force_mean_abs_N", r.force_mean_abs_N},
         {"force_mean_vector_N", {r.force_mean_N.x, r.force_mean_N.y, r.force_mean_N.z}},
         {"force_mean_vector_abs_N", r.force_mean_vec_abs_N},
         {"cherry_pit_force_N", cherry}};
  if (q.pigments > 1) {
    j["force_std_N"] = r.force_std_N;
    j["force_vector_std_N"] = {r.force_vec_std_N.x, r.force_vec_std_N.y, r.force_vec_std_N.z};
    j["force_sem_N"] = std::hypot(r.force_vec_std_N.x, r.force_vec_std_N.y, r.force_vec_std_N.z) / std::sqrt(static_cast<double>(r.samples));
  }
  return j.dump();
}

std::string field_probe(const FieldArgs& f, double x, double y) { return nip::field_probe(f, x, y).dump(); }

std::string field_export(const FieldArgs& f, double x0, double x1, int nx, double y0, double y1, int ny, const std::string& out) {
  // the checks of `nipdem field export`, plus those of the probe's magnet options
  require_range("field export", "--nx", nx, 5, 1e5);
  require_range("field export", "--ny", ny, 5, 1e5);
  nip::check_field_options(f, "field export");
  if (!f.map.empty()) throw_input("field export", "--map", f.map, "export samples a preset magnet, not a map");
  require_range("field export", "--x0", x0, -1.0, 1.0);
  require_range("field export", "--x1", x1, -1.0, 1.0);
  require_range("field export", "--y0", y0, -1.0, 1.0);
  require_range("field export", "--y1", y1, -1.0, 1.0);
  if (static_cast<double>(nx) * ny > 1e7)
    throw_input("field export", "--nx, --ny", fmt::format("{} x {}", nx, ny), "too many nodes for a map nipdem reads", "nx * ny <= 1e7");
  if (!(x1 > x0)) throw_input("field export", "--x1", fmt::format("{:g}", x1), "must exceed x0", "> x0");
  if (!(y1 > y0)) throw_input("field export", "--y1", fmt::format("{:g}", y1), "must exceed y0", "> y0");
  const nip::FieldSetup s = nip::make_field_setup(f);
  io::write_file_atomic(out, io::field_to_csv(*s.field, x0, x1, nx, y0, y1, ny, s.field->describe() + ", magnet frame (see docs/magnetic.md)"));
  return json{{"out", out}, {"source", s.field->describe()}, {"nx", nx}, {"ny", ny}}.dump();
}

double rc_default_Rm() { return probe::ProbeCircuitParams{}.Rm_ohm; }

std::string rc_response(double R, double Rd, double C, double Rm, double voltage, const std::string& freq) {
  probe::ProbeCircuitParams p;
  p.R_ohm = R;
  p.Rd_ohm = Rd;
  p.C_F = C;
  p.Rm_ohm = Rm;
  // the checks and the table of `nipdem rc response` (apps/cli/cmd_rc.cpp)
  const auto table = probe::rc_response_table(p, voltage, freq);
  json rows = json::array();
  for (const auto& r : table)
    rows.push_back({{"frequency_Hz", r.frequency_Hz}, {"amplitude_V", r.amplitude_V}, {"phase_deg", r.phase_deg()}});
  json j;
  j["rows"] = rows;
  j["R_ohm"] = p.R_ohm;
  j["Rd_ohm"] = p.Rd_ohm;
  j["C_F"] = p.C_F;
  j["Rm_ohm"] = p.Rm_ohm;
  j["voltage_V"] = voltage;
  return j.dump();
}

std::string ldc_verify() { return ldc::verify::to_json(ldc::verify::run_all()).dump(); }

namespace {
// Reads the option object of run_experiment: every key must be consumed.
class Options {
 public:
  Options(const std::string& text, std::string where) : where_(std::move(where)) {
    try {
      j_ = json::parse(text);
    } catch (const json::exception& e) {
      throw InputError(where_ + ": options are not a JSON object (" + e.what() + ")");
    }
    if (!j_.is_object()) throw InputError(where_ + ": options are not a JSON object");
  }
  template <class T>
  void get(const char* key, T& v) {
    if (!j_.contains(key) || j_[key].is_null()) return;
    try {
      if constexpr (std::is_same_v<T, double>) {
        v = number(j_[key]);
      } else if constexpr (std::is_same_v<T, std::vector<double>>) {
        if (!j_[key].is_array()) throw json::type_error::create(302, "not an array", nullptr);
        v.clear();
        for (const auto& x : j_[key]) v.push_back(number(x));
      } else {
        v = j_[key].get<T>();
      }
    } catch (const json::exception&) {
      throw_input(where_, key, j_[key].dump(), "wrong type");
    }
    used_.insert(key);
  }
  // JSON has no NaN or infinity: the package sends them as the strings "nan", "inf", "-inf",
  // so that the experiment's own range check reports them as the CLI does.
  static double number(const json& x) {
    if (x.is_string()) {
      const auto& t = x.get_ref<const std::string&>();
      if (t == "nan") return std::numeric_limits<double>::quiet_NaN();
      if (t == "inf") return std::numeric_limits<double>::infinity();
      if (t == "-inf") return -std::numeric_limits<double>::infinity();
    }
    return x.get<double>();
  }
  void finish() const {
    for (const auto& [k, v] : j_.items())
      if (!used_.count(k) && !v.is_null()) throw_input(where_, k, v.dump(), "unknown option of this experiment");
  }

 private:
  std::string where_;
  json j_;
  std::set<std::string> used_;
};

// The printed line of vo-level and edge-sharpness (experiments/print_line.hpp).
void get_print(Options& op, experiments::PrintOptions& p) {
  op.get("line_length_m", p.line_length_m);
  op.get("line_start_m", p.line_start_m);
  op.get("extra_time_s", p.extra_time_s);
}
// The CLI checks --extra-time while parsing (CLI::Range(0.0, 1.0)); the same range, after finish().
void check_extra_time(const std::string& where, const experiments::PrintOptions& p) {
  if (!(p.extra_time_s >= 0.0 && p.extra_time_s <= 1.0))
    throw_input(where, "--extra-time", fmt::format("{:g}", p.extra_time_s), "out of range", "[0, 1]");
}
}  // namespace

std::string run_experiment(const std::string& name, const std::string& options) {
  using namespace experiments;
  using namespace nip;
  Options op(options, "experiment " + name);
  ExperimentOptions o;
  std::string out;
  op.get("preset", o.preset);
  op.get("config", o.config);
  op.get("sets", o.sets);
  op.get("seed", o.seed);
  op.get("jobs", o.jobs);
  op.get("progress", o.progress);
  op.get("out", out);
  if (o.jobs < 1 || o.jobs > 256) throw_input("experiment " + name, "--jobs", std::to_string(o.jobs), "out of range", "[1, 256]");
  o.out = out.empty() ? "runs/" + name : out;  // the CLI's default
  json j;
  if (name == "front-position") {
    FrontPositionOptions f;
    op.get("gaps_m", f.gaps_m);
    op.get("sleeve_speeds_m_per_min", f.sleeve_speeds_m_per_min);
    op.get("max_time_s", f.max_time_s);
    op.get("min_time_s", f.min_time_s);
    op.finish();
    j = front_position(o, f);
  } else if (name == "reduction") {
    ReductionOptions r;
    op.get("cohesion_ratios", r.cohesion_ratios);
    op.get("time_s", r.time_s);
    op.get("pile_width_m", r.pile_width_m);
    op.get("pile_height_m", r.pile_height_m);
    op.get("pits", r.pits);
    op.finish();
    j = reduction(o, r);
  } else if (name == "vo-level") {
    VoOptions v;
    op.get("step_V", v.step_V);
    op.get("coarse_step_V", v.coarse_step_V);
    op.get("v0_V", v.v0_V);
    op.get("v_max_V", v.v_max_V);
    op.get("seeds", v.seeds);
    get_print(op, v.print);
    op.finish();
    check_extra_time("experiment vo-level", v.print);
    j = vo_level(o, v);
  } else if (name == "edge-sharpness") {
    EdgeOptions e;
    op.get("realizations", e.realizations);
    get_print(op, e.print);
    op.get("margin_m", e.margin_m);
    op.get("bootstrap", e.bootstrap);
    op.finish();
    check_extra_time("experiment edge-sharpness", e.print);
    j = edge_sharpness(o, e);
  } else {
    throw_input("experiment", "name", name, "unknown experiment", "front-position, reduction, vo-level, edge-sharpness");
  }
  // apps/cli/cmd_experiment.cpp finish(): the JSON next to the data, then the same failures
  io::write_file_atomic(o.out / (name + ".json"), j.dump(2));
  if (j.contains("bracketed") && !j["bracketed"].get<bool>())
    throw std::runtime_error("the target was not bracketed (" + j.value("hint", std::string()) + "); see " + (o.out / (name + ".json")).string());
  if (j.value("n_failed", 0) > 0)
    throw std::runtime_error(std::to_string(j["n_failed"].get<int>()) + " point(s) failed; see \"failed\" in " + (o.out / (name + ".json")).string());
  return j.dump();
}

}  // namespace nipdem::python
