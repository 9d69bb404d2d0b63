// `nipdem force electric`: force on a grounded conducting sphere at a gap from a plate on
// voltage V (thesis §2.5.3). See docs/electric.md.
#include <cmath>
#include <fmt/format.h>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "nipdem/core/constants.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/core/error.hpp"
#include "registry.hpp"

namespace {
struct Opts {
  double radius = 0.0, voltage = 0.0, gap = 0.0;
  std::string model = "exact";
  double approx_coefficient = nipdem::electric::kThesisApproxCoefficient;
  bool layer = false;
  double layer_thickness = nipdem::electric::kSiOxThickness_m;
  double layer_eps = nipdem::electric::kSiOxPermittivity;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* grp = nipdem::cli::group(app, "force");
  auto* sub = grp->add_subcommand("electric", "Force on a grounded conducting sphere at a gap from a plate on voltage V");
  auto o = std::make_shared<Opts>();
  sub->add_option("--radius", o->radius, "sphere radius [m]")->required();
  sub->add_option("--voltage", o->voltage, "plate voltage relative to the sphere [V]")->required();
  sub->add_option("--gap", o->gap, "gap between sphere surface and plate [m] (use an effective gap d = l + d_l/eps_r for a coated drum)")
      ->required();
  sub->add_option("--model", o->model, "exact (capacitance series) | series (thesis eq. 2.5.31, corrected) | approx (eq. 2.5.42)")
      ->capture_default_str();
  auto* coef_opt = sub->add_option("--approx-coefficient", o->approx_coefficient, "coefficient a of eq. 2.5.42 [-] (only with --model approx)")
                       ->capture_default_str();
  sub->add_flag("--dielectric-layer", o->layer,
                "treat --gap as the distance l to the coated drum surface and use d = l + d_l/eps_r (eq. 2.5.43)");
  auto* thick_opt = sub->add_option("--layer-thickness", o->layer_thickness, "SiOx layer thickness d_l [m] (only with --dielectric-layer)")
                        ->capture_default_str();
  auto* eps_opt = sub->add_option("--layer-permittivity", o->layer_eps, "SiOx relative permittivity eps_r [-] (only with --dielectric-layer)")
                      ->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o, coef_opt, thick_opt, eps_opt] {
    using namespace nipdem::electric;
    // The checks and the computation are those of Python's nipdem.force_electric (one library
    // function); an option given where it has no effect is refused there.
    ForceQuery q;
    q.radius_m = o->radius;
    q.voltage_V = o->voltage;
    q.gap_m = o->gap;
    q.model = o->model;
    if (coef_opt->count() > 0) q.approx_coefficient = o->approx_coefficient;
    q.dielectric_layer = o->layer;
    if (thick_opt->count() > 0) q.layer_thickness_m = o->layer_thickness, q.layer_thickness_text = thick_opt->as<std::string>();
    if (eps_opt->count() > 0) q.layer_permittivity = o->layer_eps, q.layer_permittivity_text = eps_opt->as<std::string>();
    const ForceAnswer r = force_query(q);
    const double F = r.force_N, Fexact = r.force_exact_N, d = r.effective_gap_m;
    if (o->json) {
      nlohmann::json j;
      j["force_N"] = F;
      j["model"] = to_string(r.params.model);
      j["radius_m"] = o->radius;
      j["voltage_V"] = o->voltage;
      j["gap_m"] = o->gap;
      j["effective_gap_m"] = d;
      j["gap_over_radius"] = d / o->radius;
      j["force_exact_N"] = Fexact;
      j["force_small_gap_limit_N"] = r.force_small_gap_limit_N;
      j["capacitance_F"] = r.capacitance_F;
      nipdem::cli::print_json(j.dump());
    } else {
      std::printf("model            %s\n", to_string(r.params.model));
      std::printf("force            %.6e N\n", F);
      std::printf("force (exact)    %.6e N\n", Fexact);
      std::printf("effective gap    %.6e m\n", d);
      std::printf("gap / radius     %.6g\n", d / o->radius);
      std::printf("capacitance      %.6e F\n", r.capacitance_F);
    }
  });
});
}  // namespace
