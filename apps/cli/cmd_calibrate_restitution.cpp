// `nipdem calibrate restitution`: normal restitution coefficient from a drop test with Stokes
// drag (thesis §4.2.1, eqs. 4.2.1–4.2.6). See src/nipdem/experiments/calibrate_restitution.hpp.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "nipdem/experiments/calibrate_restitution.hpp"
#include "nipdem/core/error.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  nipdem::calibrate::DropTestParams p;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* cal = nipdem::cli::group(app, "calibrate");
  auto* sub = cal->add_subcommand("restitution", "Normal restitution coefficient from a drop test with Stokes drag (thesis 4.2.1)");
  auto o = std::make_shared<Opts>();
  sub->add_option("--y0", o->p.y0_m, "drop height [m]")->required();
  sub->add_option("--y1", o->p.y1_m, "maximum rebound height [m], 1e-9 <= y1 <= y0")->required();
  sub->add_option("--radius", o->p.radius_m, "sphere radius [m]")->required();
  sub->add_option("--density", o->p.density_kg_per_m3, "sphere density [kg/m^3]")->required();
  sub->add_option("--viscosity", o->p.viscosity_Pa_s, "air dynamic viscosity [Pa s]")->required();
  sub->add_option("--gravity", o->p.gravity_m_per_s2, "gravitational acceleration [m/s^2]")->capture_default_str();
  sub->add_option("--air-density", o->p.air_density_kg_per_m3, "air density, for the Reynolds number and the Schiller-Naumann check [kg/m^3], 0 .. 1000")
      ->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o] {
    // Physical ranges (a drop test of a particle), so that no result overflows into null.
    const char* w = "calibrate restitution";
    nipdem::require_range(w, "--y0", o->p.y0_m, 1e-9, 100.0);
    nipdem::require_range(w, "--y1", o->p.y1_m, 1e-9, 100.0);  // and <= y0 (checked with its own message)
    nipdem::require_range(w, "--radius", o->p.radius_m, 1e-9, 1e-1);
    nipdem::require_range(w, "--density", o->p.density_kg_per_m3, 1e-3, 1e5);
    nipdem::require_range(w, "--viscosity", o->p.viscosity_Pa_s, 1e-9, 1e3);
    nipdem::require_range(w, "--gravity", o->p.gravity_m_per_s2, 1e-3, 1e3);
    nipdem::require_range(w, "--air-density", o->p.air_density_kg_per_m3, 0.0, 1e3);  // 0: vacuum
    const auto r = nipdem::calibrate::drop_test_restitution(o->p);
    // Every printed number must be finite (JSON would print null).
    for (double v : {r.restitution, r.restitution_no_drag, r.reynolds_at_impact, r.restitution_schiller_naumann,
                     r.impact_speed_m_per_s, r.impact_speed_no_drag_m_per_s, r.rebound_speed_m_per_s, r.fall_time_s,
                     r.rise_time_s, r.beta_s, r.terminal_speed_m_per_s, r.mass_kg})
      if (!std::isfinite(v))
        nipdem::throw_input(w, "--y0, --y1, --radius, --density, --viscosity, --gravity, --air-density", "",
                            "the drop test is not computable for these inputs");
    if (o->json) {
      nlohmann::json j{{"restitution", r.restitution},
                       {"restitution_no_drag", r.restitution_no_drag},
                       {"reynolds_at_impact", r.reynolds_at_impact},
                       {"restitution_schiller_naumann", r.restitution_schiller_naumann},
                       {"impact_speed_m_per_s", r.impact_speed_m_per_s},
                       {"impact_speed_no_drag_m_per_s", r.impact_speed_no_drag_m_per_s},
                       {"rebound_speed_m_per_s", r.rebound_speed_m_per_s},
                       {"fall_time_s", r.fall_time_s},
                       {"rise_time_s", r.rise_time_s},
                       {"beta_s", r.beta_s},
                       {"terminal_speed_m_per_s", r.terminal_speed_m_per_s},
                       {"mass_kg", r.mass_kg},
                       {"inputs",
                        {{"y0_m", o->p.y0_m},
                         {"y1_m", o->p.y1_m},
                         {"radius_m", o->p.radius_m},
                         {"density_kg_per_m3", o->p.density_kg_per_m3},
                         {"viscosity_Pa_s", o->p.viscosity_Pa_s},
                         {"gravity_m_per_s2", o->p.gravity_m_per_s2},
                         {"air_density_kg_per_m3", o->p.air_density_kg_per_m3}}}};
      nipdem::cli::print_json(j.dump());
    } else {
      std::printf("drop test (thesis 4.2.1): y0 = %g m, y1 = %g m, R = %g m, rho = %g kg/m^3, eta = %g Pa s\n",
                  o->p.y0_m, o->p.y1_m, o->p.radius_m, o->p.density_kg_per_m3, o->p.viscosity_Pa_s);
      std::printf("  restitution (Stokes drag, eq. 4.2.4-4.2.6) %.6f\n", r.restitution);
      std::printf("  restitution (no drag, eq. 4.2.2)           %.6f\n", r.restitution_no_drag);
      std::printf("  restitution (Schiller-Naumann drag, check)  %.6f\n", r.restitution_schiller_naumann);
      std::printf("  impact speed                                %.6g m/s (no drag %.6g m/s)\n", r.impact_speed_m_per_s,
                  r.impact_speed_no_drag_m_per_s);
      std::printf("  rebound speed                               %.6g m/s\n", r.rebound_speed_m_per_s);
      std::printf("  relaxation time beta (eq. 4.2.5)            %.6g s\n", r.beta_s);
      std::printf("  Reynolds number at impact                   %.4g (Stokes drag assumes Re << 1)\n",
                  r.reynolds_at_impact);
    }
  });
});

}  // namespace
