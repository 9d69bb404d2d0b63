#include "nipdem/models/electric_screening.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "nipdem/core/error.hpp"

namespace nipdem::electric {

DrumSurface DrumSurface::circle(Vec2 centre, double radius) {
  require_positive("electric screening", "drum radius", radius);
  DrumSurface d;
  d.kind = Kind::circle;
  d.point = centre;
  d.radius = radius;
  return d;
}

DrumSurface DrumSurface::plane(Vec2 point, Vec2 normal_into_toner) {
  const double len = norm(normal_into_toner);
  if (!(len > 0.0) || !std::isfinite(len))
    throw_input("electric screening", "drum normal", fmt::format("({:g}, {:g})", normal_into_toner.x, normal_into_toner.y),
                "must be a non-zero vector");
  DrumSurface d;
  d.kind = Kind::plane;
  d.point = point;
  d.normal = normal_into_toner / len;
  return d;
}

void ScreeningParams::validate() const {
  require_range("electric screening", "range_m", range_m, 0.0, std::numeric_limits<double>::infinity());
  require_range("electric screening", "corridor_fraction", corridor_fraction, 0.0, 0.999);
}

bool blocks_corridor(const Disc& particle, Vec2 foot, const Disc& d, double half_width) {
  const Vec2 axis = foot - particle.centre;
  const double L = norm(axis);
  if (!(L > 0.0)) return false;
  const Vec2 n = axis / L;
  const Vec2 rel = d.centre - particle.centre;
  const double s = dot(rel, n);
  const double t = std::fabs(cross(n, rel));
  // Distance from the disc centre to the rectangle [0, L] x [-w, w] (local coordinates).
  const double ds = s < 0.0 ? -s : (s > L ? s - L : 0.0);
  const double dt = std::max(t - half_width, 0.0);
  return ds * ds + dt * dt < d.radius * d.radius;
}

double screening_reach(const ScreeningParams& p, double r_max_m) {
  // |s| < L + r_d and |t| < w + r_d for a blocking disc (blocks_corridor), so its centre is
  // within (L + r_d) + (w + r_d) <= range + r_max + r_max + 2 r_max
  return p.range_m + 4.0 * r_max_m;
}

ScreeningResult screening(const Disc& particle, const DrumSurface& drum, std::span<const Disc> others,
                          const ScreeningParams& p, int self_index) {
  ScreeningResult r;
  if (drum.kind == DrumSurface::Kind::circle) {
    const Vec2 rel = particle.centre - drum.point;
    const double dist = norm(rel);
    const Vec2 out = dist > 0.0 ? rel / dist : Vec2{0.0, 1.0};
    r.foot = drum.point + drum.radius * out;
    r.normal = -out;
    r.gap_m = dist - drum.radius - particle.radius;
  } else {
    const double h = dot(particle.centre - drum.point, drum.normal);
    r.foot = particle.centre - h * drum.normal;
    r.normal = -drum.normal;
    r.gap_m = h - particle.radius;
  }
  r.within_range = r.gap_m <= p.range_m;
  if (!r.within_range) return r;
  const double w = p.corridor_fraction * particle.radius;
  for (std::size_t k = 0; k < others.size(); ++k) {
    if (static_cast<int>(k) == self_index) continue;
    if (blocks_corridor(particle, r.foot, others[k], w)) {
      r.screened = true;
      r.screened_by = static_cast<int>(k);
      break;
    }
  }
  return r;
}

}  // namespace nipdem::electric
