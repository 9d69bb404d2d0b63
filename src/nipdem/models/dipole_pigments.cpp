#include "nipdem/models/dipole_pigments.hpp"

#include <cmath>
#include <fmt/format.h>
#include <vector>

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

}  // namespace nipdem::dipole
