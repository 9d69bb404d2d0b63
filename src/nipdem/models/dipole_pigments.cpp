#include "nipdem/models/dipole_pigments.hpp"

#include <cmath>
#include <fmt/format.h>
#include <vector>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"

namespace nipdem::dipole {

namespace {
// Uniform point in the ball of radius R by rejection from the cube (portable, exact distribution).
Vec3 in_ball(Rng& rng, double R) {
  for (;;) {
    const double x = rng.uniform(-1, 1), y = rng.uniform(-1, 1), z = rng.uniform(-1, 1);
    if (x * x + y * y + z * z <= 1.0) return {R * x, R * y, R * z};
  }
}
}  // namespace

PigmentStudyResult pigment_study(const PigmentStudyParams& p) {
  const std::string w = "force dipole";
  require_positive(w, "moment_Am2", p.moment_Am2);
  require_positive(w, "radius_m", p.radius_m);
  require_positive(w, "distance_m", p.distance_m);
  if (!(p.distance_m > 2.0 * p.radius_m))
    throw_input(w, "distance_m", fmt::format("{:g}", p.distance_m), "spheres would overlap", "distance > 2 radius");
  require_range(w, "angle_rad", p.angle_rad, -1e3, 1e3);
  if (p.pigments < 1 || p.pigments > 1000000)
    throw_input(w, "pigments", fmt::format("{}", p.pigments), "out of range", "1..1000000");
  const int samples = p.pigments == 1 ? 1 : p.samples;
  if (samples < 1 || samples > 10000000) throw_input(w, "samples", fmt::format("{}", p.samples), "out of range", "1..1e7");
  const double work = static_cast<double>(p.pigments) * p.pigments * samples;
  if (work > 1e11)
    throw_input(w, "pigments*pigments*samples", fmt::format("{:g}", work), "too much work", "<= 1e11 pair evaluations");

  const int n = p.pigments;
  const double mp = p.moment_Am2 / n;
  const Vec3 m{mp * std::cos(p.angle_rad), mp * std::sin(p.angle_rad), 0.0};
  std::vector<Vec3> a(static_cast<std::size_t>(n)), b(static_cast<std::size_t>(n));
  double s1 = 0, s2 = 0;
  double vx = 0, vy = 0, vz = 0, vx2 = 0, vy2 = 0, vz2 = 0;
  for (int k = 0; k < samples; ++k) {
    Rng rng = Rng::stream(p.seed, static_cast<std::uint64_t>(k));
    if (n == 1) {
      a[0] = {0, 0, 0};
      b[0] = {p.distance_m, 0, 0};
    } else {
      for (auto& q : a) q = in_ball(rng, p.radius_m);
      for (auto& q : b) {
        q = in_ball(rng, p.radius_m);
        q.x += p.distance_m;
      }
    }
    double fx = 0, fy = 0, fz = 0;
    for (const Vec3& qb : b) {
      for (const Vec3& qa : a) {
        const Vec3 f = dipole_force3(m, m, {qb.x - qa.x, qb.y - qa.y, qb.z - qa.z});
        fx += f.x;
        fy += f.y;
        fz += f.z;
      }
    }
    const double fa = std::sqrt(fx * fx + fy * fy + fz * fz);
    s1 += fa;
    s2 += fa * fa;
    vx += fx; vy += fy; vz += fz;
    vx2 += fx * fx; vy2 += fy * fy; vz2 += fz * fz;
  }
  PigmentStudyResult r;
  const double N = samples;
  r.samples = samples;
  r.force_mean_abs_N = s1 / N;
  auto sd = [N](double s, double ss) { return N > 1 ? std::sqrt(std::max(0.0, (ss - s * s / N) / (N - 1))) : 0.0; };
  r.force_std_N = sd(s1, s2);
  r.force_mean_N = {vx / N, vy / N, vz / N};
  r.force_mean_vec_abs_N = std::sqrt(vx * vx + vy * vy + vz * vz) / N;
  r.force_vec_std_N = {sd(vx, vx2), sd(vy, vy2), sd(vz, vz2)};
  return r;
}

DipoleAnswer force_dipole_query(const DipoleQuery& q) {
  const std::string w = "force dipole";
  // Physical ranges (far beyond toner's: m ~ 4e-11 A m^2, d ~ 13 um), so no result overflows;
  // named by option (pigment_study names its fields).
  if (!(q.moment_Am2 > 0.0 && q.moment_Am2 <= 1e-3))
    throw_input(w, "--moment", fmt::format("{:g}", q.moment_Am2), "out of range (the moment's size: its direction is --angle)",
                "(0, 0.001] A m^2");
  require_range(w, "--distance", q.distance_m, 1e-9, 1.0);
  require_range(w, "--radius", q.radius_m, 1e-9, 1e-2);
  if (!(q.distance_m > 2.0 * q.radius_m))
    throw_input(w, "--distance", fmt::format("{:g}", q.distance_m), fmt::format("the spheres would overlap (--radius {:g})", q.radius_m),
                "> 2 x --radius");
  require_range(w, "--angle", q.angle_deg, -5e4, 5e4);
  if (q.pigments < 1 || q.pigments > 1000000) throw_input(w, "--pigments", fmt::format("{}", q.pigments), "out of range", "[1, 1000000]");
  // --samples is validated even with --pigments 1 (one placement; the result reports samples = 1).
  if (q.samples < 1 || q.samples > 10000000) throw_input(w, "--samples", fmt::format("{}", q.samples), "out of range", "[1, 1e7]");
  // The cost is pigments^2 x samples pair forces at ~1e8 per second (1000 pigments x 1000
  // samples: 8 s), with no progress shown: more than kMaxPairs (~10 s) is refused.
  constexpr double kMaxPairs = 1e9;
  const double pairs = static_cast<double>(q.pigments) * q.pigments * (q.pigments == 1 ? 1 : q.samples);
  if (pairs > kMaxPairs)
    throw_input(w, "--pigments, --samples", fmt::format("{}, {}", q.pigments, q.samples),
                fmt::format("{:g} pigment-pair forces (pigments^2 x samples) would take about {:.0f} s at ~1e8 per second", pairs,
                            pairs / 1e8),
                fmt::format("pigments^2 x samples <= {:g} (about 10 s)", kMaxPairs));
  PigmentStudyParams p;
  p.moment_Am2 = q.moment_Am2;
  p.distance_m = q.distance_m;
  p.angle_rad = q.angle_deg * constants::pi / 180.0;
  p.radius_m = q.radius_m;
  p.pigments = q.pigments;
  p.samples = q.samples;
  p.seed = q.seed;
  DipoleAnswer a;
  a.study = pigment_study(p);
  // Cherry-pit reference (eq. 2.4.39 with both moments at the centres), for comparison.
  const Vec2 m{q.moment_Am2 * std::cos(p.angle_rad), q.moment_Am2 * std::sin(p.angle_rad)};
  a.cherry_pit_force_N = norm(dipole_force(m, m, {q.distance_m, 0.0}));
  if (!std::isfinite(a.cherry_pit_force_N) || !std::isfinite(a.study.force_mean_vec_abs_N))
    throw_input(w, "--moment, --distance", fmt::format("{:g} A m^2, {:g} m", q.moment_Am2, q.distance_m),
                "the force is not representable for these inputs");
  return a;
}

}  // namespace nipdem::dipole
