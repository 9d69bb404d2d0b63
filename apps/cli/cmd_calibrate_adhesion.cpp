// `nipdem calibrate adhesion`: log-normal adhesion-force distribution from a centrifugal
// detachment record or from AFM pull-off forces (thesis §4.4), and the config value it gives.
// See src/nipdem/experiments/calibrate_adhesion.hpp and docs/calibration.md.
#include <fmt/format.h>
#include <memory>
#include <utility>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_adhesion.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  std::string data, method = "centrifugal", out;
  nipdem::calibrate::AdhesionOptions o;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* cal = nipdem::cli::group(app, "calibrate");
  auto* sub = cal->add_subcommand("adhesion", "Adhesion-force distribution (log-normal) from centrifugal or AFM data (§4.4)");
  auto c = std::make_shared<Opts>();
  sub->add_option("--data", c->data,
                  "CSV: centrifugal omega_rad_per_s (increasing),fraction_remaining; afm force_N")->required();
  sub->add_option("--method", c->method, "centrifugal (fig. 4.17) or afm (fig. 4.16)")->capture_default_str();
  sub->add_option("--particle-mass-kg", c->o.particle_mass_kg, "centrifugal: measured particle mass [kg] (F = m omega^2 r)");
  sub->add_option("--rotor-radius-m", c->o.rotor_radius_m, "centrifugal: distance of the substrate from the axis [m]");
  sub->add_option("--initial-count", c->o.initial_count, "centrifugal: particles counted before spinning (weights and bootstrap)");
  sub->add_option("--bootstrap", c->o.bootstrap, "centrifugal: parametric bootstrap resamples for the standard errors")->capture_default_str();
  sub->add_option("--seed", c->o.seed, "centrifugal: bootstrap seed (same seed, same result)")->capture_default_str();
  sub->add_option("--measured-diameter-m", c->o.measured_diameter_m, "diameter of the measured particles [m] (with --d50-m: scale F ∝ R to d50)");
  sub->add_option("--d50-m", c->o.d50_m, "toner d50 the config value is for [m]");
  sub->add_option("--substrate", c->o.substrate, "drum (-> adhesion.drum_force_N) or roller (-> adhesion.roller_force_N)")->capture_default_str();
  sub->add_option("--level", c->o.level, "interval level of the median")->capture_default_str();
  sub->add_option("--out", c->out, "output folder (default runs/calibrate_adhesion)");
  sub->add_flag("--json", c->json, "print one JSON object on stdout");
  sub->callback([c, sub] {
    using namespace nipdem::calibrate;
    if (c->method == "centrifugal") c->o.method = AdhesionMethod::centrifugal;
    else if (c->method == "afm") c->o.method = AdhesionMethod::afm;
    else nipdem::throw_input("calibrate adhesion", "--method", "\"" + c->method + "\"", "unknown method", "centrifugal or afm");
    // Options given explicitly are checked even where "not given" has a meaning, and an option
    // the method does not use is refused rather than ignored silently.
    const char* w = "calibrate adhesion";
    if (c->o.method == AdhesionMethod::afm)
      for (const char* opt : {"--particle-mass-kg", "--rotor-radius-m", "--initial-count", "--bootstrap", "--seed"})
        if (sub->count(opt) > 0)
          nipdem::throw_input(w, opt, "", "only the centrifugal method uses it (afm: the forces are measured directly)",
                              "--method centrifugal");
    for (const auto& [opt, v] : {std::pair{"--measured-diameter-m", c->o.measured_diameter_m}, std::pair{"--d50-m", c->o.d50_m}})
      if (sub->count(opt) > 0) nipdem::require_range(w, opt, v, 1e-7, 1e-2);  // 0.1 um .. 1 cm
    c->o.validate();
    const Record r = read_adhesion_record(c->data, c->o.method);
    const AdhesionResult a = calibrate_adhesion(r, c->o);
    const std::string out = c->out.empty() ? "runs/calibrate_adhesion" : c->out;
    const auto j = adhesion_report(r, c->o, a, out);
    nipdem::cli::finish_report(j, out, "adhesion", c->json,
                               fmt::format("adhesion ({}, §4.4): log-normal, median {:.4g} N ({:.0f} %: {:.4g} .. {:.4g} N), "
                                           "s = {:.3f} +- {:.3f}\n  10-90 %: {:.3g} .. {:.3g} N, mean {:.3g} N\n"
                                           "  {} = {:.4g} N ({:.4g} .. {:.4g} N)\n",
                                           to_string(c->o.method), a.median_N, 100 * c->o.level, a.median_lo_N,
                                           a.median_hi_N, a.dist.sigma_ln, a.sigma_ln_std, a.q10_N, a.q90_N, a.mean_N,
                                           a.config_key, a.config_value_N, a.config_lo_N, a.config_hi_N));
  });
});

}  // namespace
