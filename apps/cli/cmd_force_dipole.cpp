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
    // Physical ranges (far beyond toner's: m ~ 4e-11 A m^2, d ~ 13 um), so no result overflows;
    // checked here so that a message names the option (pigment_study names its fields).
    if (!(o->moment > 0.0 && o->moment <= 1e-3))
      throw_input("force dipole", "--moment", fmt::format("{:g}", o->moment),
                  "out of range (the moment's size: its direction is --angle)", "(0, 0.001] A m^2");
    require_range("force dipole", "--distance", o->distance, 1e-9, 1.0);
    require_range("force dipole", "--radius", o->radius, 1e-9, 1e-2);
    if (!(o->distance > 2.0 * o->radius))
      throw_input("force dipole", "--distance", fmt::format("{:g}", o->distance),
                  fmt::format("the spheres would overlap (--radius {:g})", o->radius), "> 2 x --radius");
    require_range("force dipole", "--angle", o->angle_deg, -5e4, 5e4);
    if (o->pigments < 1 || o->pigments > 1000000)
      throw_input("force dipole", "--pigments", fmt::format("{}", o->pigments), "out of range", "[1, 1000000]");
    // --samples is validated even with --pigments 1 (one placement; the JSON reports samples = 1).
    if (o->samples < 1 || o->samples > 10000000)
      throw_input("force dipole", "--samples", fmt::format("{}", o->samples), "out of range", "[1, 1e7]");
    // The cost is pigments^2 x samples pair forces at ~1e8 per second (1000 pigments x 1000
    // samples: 8 s), with no progress shown: more than kMaxPairs (~10 s) is refused.
    constexpr double kMaxPairs = 1e9;
    const double pairs = static_cast<double>(o->pigments) * o->pigments * (o->pigments == 1 ? 1 : o->samples);
    if (pairs > kMaxPairs)
      throw_input("force dipole", "--pigments, --samples", fmt::format("{}, {}", o->pigments, o->samples),
                  fmt::format("{:g} pigment-pair forces (pigments^2 x samples) would take about {:.0f} s at ~1e8 per second", pairs,
                              pairs / 1e8),
                  fmt::format("pigments^2 x samples <= {:g} (about 10 s)", kMaxPairs));
    dipole::PigmentStudyParams p;
    p.moment_Am2 = o->moment;
    p.distance_m = o->distance;
    p.angle_rad = o->angle_deg * constants::pi / 180.0;
    p.radius_m = o->radius;
    p.pigments = o->pigments;
    p.samples = o->samples;
    p.seed = o->seed;
    const auto r = dipole::pigment_study(p);
    // Cherry-pit reference (eq. 2.4.39 with both moments at the centres), for comparison.
    const Vec2 m{o->moment * std::cos(p.angle_rad), o->moment * std::sin(p.angle_rad)};
    const double cherry = norm(dipole::dipole_force(m, m, {o->distance, 0.0}));
    if (!std::isfinite(cherry) || !std::isfinite(r.force_mean_vec_abs_N))
      throw_input("force dipole", "--moment, --distance", fmt::format("{:g} A m^2, {:g} m", o->moment, o->distance),
                  "the force is not representable for these inputs");
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
