// `nipdem force dipole`: the pigment study of thesis §2.4.2 (figs. 2.14-2.15) -- dipole-dipole force
// between two magnetised toner spheres whose moment sits in one central pigment ("cherry pit") or in
// N random point pigments. See src/nipdem/models/dipole_pigments.hpp and docs/magnetic.md.
#include <cmath>
#include <fmt/format.h>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "nipdem/core/constants.hpp"
#include "nipdem/models/dipole_pigments.hpp"
#include "nipdem/core/error.hpp"
#include "registry.hpp"

namespace {
struct Opts {
  double moment = 3.7e-11, distance = 13e-6, angle_deg = 0.0, radius = 6e-6;
  int pigments = 1, samples = 1000;
  std::uint64_t seed = 1;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* force = nipdem::cli::group(app, "force");
  auto* sub = force->add_subcommand(
      "dipole", "Dipole-dipole force between two magnetised toner spheres (thesis 2.4.2, figs 2.14-2.15)");
  auto o = std::make_shared<Opts>();
  sub->add_option("--moment", o->moment, "total magnetic moment of one toner [A m^2] (thesis: 3.7e-11)")->required();
  sub->add_option("--distance", o->distance, "centre distance of the two toner spheres [m] (thesis: 13e-6)")->required();
  sub->add_option("--angle", o->angle_deg, "angle of the external field to the line of centres [deg]")->required();
  sub->add_option("--radius", o->radius, "toner sphere radius [m]")->capture_default_str();
  sub->add_option("--pigments", o->pigments,
                  "pigments per toner; 1 = cherry pit at the centre, >1 = random uniform in the sphere volume")
      ->capture_default_str();
  sub->add_option("--samples", o->samples, "random pigment placements averaged (pigments > 1)")->capture_default_str();
  sub->add_option("--seed", o->seed, "random seed")->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o] {
    using namespace nipdem;
    // The checks and the computation are those of Python's nipdem.force_dipole (one library function).
    const dipole::DipoleAnswer a =
        dipole::force_dipole_query({o->moment, o->distance, o->angle_deg, o->radius, o->pigments, o->samples, o->seed});
    const dipole::PigmentStudyResult& r = a.study;
    const double cherry = a.cherry_pit_force_N;
    if (o->json) {
      nlohmann::json j{{"moment_Am2", o->moment},
                       {"distance_m", o->distance},
                       {"angle_deg", o->angle_deg},
                       {"radius_m", o->radius},
                       {"pigments", o->pigments},
                       {"samples", r.samples},
                       {"seed", o->seed},
                       // force_N: magnitude of the mean force vector over placements (the quantity that
                       // equals the cherry-pit force, fig. 2.14); force_mean_abs_N: mean of |F|, which
                       // exceeds it when the spread is large (docs/magnetic.md).
                       {"force_N", r.force_mean_vec_abs_N},
                       {"force_mean_abs_N", r.force_mean_abs_N},
                       {"force_mean_vector_N", {r.force_mean_N.x, r.force_mean_N.y, r.force_mean_N.z}},
                       {"force_mean_vector_abs_N", r.force_mean_vec_abs_N},
                       {"cherry_pit_force_N", cherry}};
      if (o->pigments > 1) {
        j["force_std_N"] = r.force_std_N;  // standard deviation of |F| over placements (fig. 2.15)
        j["force_vector_std_N"] = {r.force_vec_std_N.x, r.force_vec_std_N.y, r.force_vec_std_N.z};
        j["force_sem_N"] = std::hypot(r.force_vec_std_N.x, r.force_vec_std_N.y, r.force_vec_std_N.z) /
                           std::sqrt(static_cast<double>(r.samples));  // standard error of the mean vector
      }
      cli::print_json(j.dump());
    } else {
      std::printf("dipole-dipole force, m = %g A m^2, d = %g m, R = %g m, theta = %g deg\n", o->moment, o->distance,
                  o->radius, o->angle_deg);
      std::printf("  pigments per toner   %d (%s)\n", o->pigments, o->pigments == 1 ? "cherry pit" : "random");
      std::printf("  samples              %d\n", r.samples);
      std::printf("  mean |F|             %.6g N\n", r.force_mean_abs_N);
      if (o->pigments > 1) std::printf("  std  |F|             %.6g N\n", r.force_std_N);
      std::printf("  |mean F|             %.6g N\n", r.force_mean_vec_abs_N);
      std::printf("  cherry-pit |F|       %.6g N\n", cherry);
    }
  });
});
}  // namespace
