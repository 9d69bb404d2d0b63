// `nipdem calibrate friction`: static and dynamic friction coefficients from a force-displacement
// record of the plate-pull (eqs. 4.3.1-4.3.2) or capstan (eq. 4.3.3) set-up, thesis §4.3.1.
// See src/nipdem/experiments/calibrate_friction.hpp and docs/calibration.md.
#include <fmt/format.h>
#include <memory>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/calibrate_friction.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  std::string data, setup = "plate", out;
  nipdem::calibrate::FrictionOptions o;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* cal = nipdem::cli::group(app, "calibrate");
  auto* sub = cal->add_subcommand("friction", "Static and dynamic friction coefficients from a pull record (§4.3.1, eqs. 4.3.1-4.3.3)");
  auto c = std::make_shared<Opts>();
  sub->add_option("--data", c->data, "CSV with columns x_m (increasing), force_N (> 0)")->required();
  sub->add_option("--setup", c->setup, "plate (fig. 4.7, eqs. 4.3.1-4.3.2) or capstan (fig. 4.10, eq. 4.3.3)")->capture_default_str();
  sub->add_option("--sample-mass-kg", c->o.sample_mass_kg, "plate: mass of the sample plate [kg] (thesis 0.026 or 0.034)")->capture_default_str();
  sub->add_option("--weight-mass-kg", c->o.weight_mass_kg, "plate: weight on the sample; capstan: hanging weight [kg]")->capture_default_str();
  sub->add_option("--mass-std-kg", c->o.mass_std_kg, "standard uncertainty of the total mass [kg]")->capture_default_str();
  sub->add_option("--gravity-m-per-s2", c->o.gravity_m_per_s2, "gravitational acceleration [m/s^2]")->capture_default_str();
  sub->add_option("--stick-end-m", c->o.stick_end_m, "end of the slow stick-slip part [m] (thesis: 5 mm)")->capture_default_str();
  sub->add_option("--transition-m", c->o.transition_m, "length skipped after the stick end before the plateau [m]")->capture_default_str();
  sub->add_option("--wrap-angle-rad", c->o.wrap_angle_rad, "capstan wrap angle [rad] (eq. 4.3.3: pi/2)")->capture_default_str();
  sub->add_option("--min-drop-N", c->o.min_drop_N, "slip detection threshold [N] (0: 6 x the noise estimate)")->capture_default_str();
  sub->add_option("--window", c->o.window, "samples on each side of a stick-slip peak")->capture_default_str();
  sub->add_option("--blocks", c->o.blocks, "batch means for the plateau's standard error")->capture_default_str();
  sub->add_option("--out", c->out, "output folder (default runs/calibrate_friction)");
  sub->add_flag("--json", c->json, "print one JSON object on stdout");
  sub->callback([c, sub] {
    using namespace nipdem::calibrate;
    c->o.setup = parse_friction_setup(c->setup);
    // An option of the other set-up given explicitly would be ignored silently: refused.
    if (c->o.setup == FrictionSetup::capstan && sub->count("--sample-mass-kg") > 0)
      nipdem::throw_input("calibrate friction", "--sample-mass-kg", fmt::format("{:g}", c->o.sample_mass_kg),
                          "only the plate set-up has a sample plate (capstan: the load is --weight-mass-kg alone)",
                          "--setup plate");
    if (c->o.setup == FrictionSetup::plate && sub->count("--wrap-angle-rad") > 0)
      nipdem::throw_input("calibrate friction", "--wrap-angle-rad", fmt::format("{:g}", c->o.wrap_angle_rad),
                          "only the capstan set-up has a wrap angle", "--setup capstan");
    c->o.validate();
    const Record r = read_friction_record(c->data);
    const FrictionResult f = calibrate_friction(r, c->o);
    const std::string out = c->out.empty() ? "runs/calibrate_friction" : c->out;
    const auto j = friction_report(r, c->o, f, out);
    nipdem::cli::finish_report(j, out, "friction", c->json,
                               fmt::format("friction ({} set-up, §4.3.1): {} stick peaks\n"
                                           "  mu_s = {:.4f} +- {:.4f}   (F_s = {:.4g} +- {:.2g} N)\n"
                                           "  mu_d = {:.4f} +- {:.4f}   (F_d = {:.4g} +- {:.2g} N)\n"
                                           "  load force {:.4g} N, noise {:.2g} N\n",
                                           to_string(c->o.setup), f.peaks.size(), f.mu_s, f.mu_s_std, f.static_force_N,
                                           f.static_force_std_N, f.mu_d, f.mu_d_std, f.dynamic_force_N,
                                           f.dynamic_force_std_N, f.load_force_N, f.noise_N));
  });
});

}  // namespace
