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
    ElectricForceParams p;
    p.model = parse_force_model(o->model, "force electric", "--model");
    // An option that would have no effect is refused rather than silently ignored.
    if (coef_opt->count() > 0 && p.model != ForceModel::approx)
      nipdem::throw_input("force electric", "--approx-coefficient", fmt::format("{:g}", o->approx_coefficient),
                          fmt::format("has no effect with --model {}", to_string(p.model)), "--approx-coefficient with --model approx");
    for (const auto* opt : {thick_opt, eps_opt})
      if (opt->count() > 0 && !o->layer)
        nipdem::throw_input("force electric", opt->get_name(), opt->as<std::string>(), "has no effect without --dielectric-layer",
                            opt->get_name() + " together with --dielectric-layer");
    // Physical ranges (far beyond toner's: R ~ 5 um, l ~ 1 um, 40 V, a = 0.45, SiOx 600 nm with
    // eps_r = 5), so that no result overflows into null (issue 21); named by option.
    nipdem::require_range("force electric", "--radius", o->radius, 1e-9, 1e-2);
    nipdem::require_range("force electric", "--gap", o->gap, 1e-12, 1.0);
    nipdem::require_range("force electric", "--voltage", o->voltage, -1e6, 1e6);
    nipdem::require_range("force electric", "--approx-coefficient", o->approx_coefficient, 1e-3, 100.0);
    if (o->layer) {
      nipdem::require_range("force electric", "--layer-thickness", o->layer_thickness, 0.0, 1e-2);
      nipdem::require_range("force electric", "--layer-permittivity", o->layer_eps, 1.0, 1e5);
    }
    p.approx_coefficient = o->approx_coefficient;
    p.validate();
    const double d = o->layer ? effective_gap(o->gap, o->layer_thickness, o->layer_eps) : o->gap;
    const double F = force(p, o->radius, o->voltage, d);
    const double Fexact = force_exact(o->radius, o->voltage, d);
    if (!std::isfinite(F) || !std::isfinite(Fexact))  // not reached within the ranges above
      nipdem::throw_input("force electric", "--radius, --gap, --voltage, --approx-coefficient, --layer-thickness, --layer-permittivity",
                          fmt::format("{:g} m, {:g} m, {:g} V, {:g}, {:g} m, {:g}", o->radius, o->gap, o->voltage,
                                      o->approx_coefficient, o->layer_thickness, o->layer_eps),
                          "the force is not representable for these inputs");
    if (o->json) {
      nlohmann::json j;
      j["force_N"] = F;
      j["model"] = to_string(p.model);
      j["radius_m"] = o->radius;
      j["voltage_V"] = o->voltage;
      j["gap_m"] = o->gap;
      j["effective_gap_m"] = d;
      j["gap_over_radius"] = d / o->radius;
      j["force_exact_N"] = Fexact;
      j["force_small_gap_limit_N"] = force_small_gap_asymptote(o->radius, o->voltage, d, true);
      j["capacitance_F"] = sphere_plane_capacitance(o->radius, d);
      nipdem::cli::print_json(j.dump());
    } else {
      std::printf("model            %s\n", to_string(p.model));
      std::printf("force            %.6e N\n", F);
      std::printf("force (exact)    %.6e N\n", Fexact);
      std::printf("effective gap    %.6e m\n", d);
      std::printf("gap / radius     %.6g\n", d / o->radius);
      std::printf("capacitance      %.6e F\n", sphere_plane_capacitance(o->radius, d));
    }
  });
});
}  // namespace
