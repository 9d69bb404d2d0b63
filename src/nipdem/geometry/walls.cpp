#include "nipdem/geometry/walls.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::geometry {

double Wall::period() const { return profile.empty() ? 0.0 : profile.back().x; }

Vec2 Wall::profile_point(int k, Vec2 sd) const {
  const double s = k * period() + sd.x + phase;
  const double phi = s / radius + angle;
  const double rr = radius - sd.y;
  return centre + Vec2{rr * std::cos(phi), rr * std::sin(phi)};
}

void Wall::query(Vec2 c, double r, double reach, std::vector<WallHit>& hits, int* hint) const {
  if (kind == Kind::plane) {
    const double dist = dot(c - point, normal);
    const double gap = dist - r;
    if (gap <= reach) hits.push_back({0, c - dist * normal, normal, gap, surface_velocity});
    return;
  }
  const Vec2 d = c - centre;
  const double dist = norm(d);
  if (!rough()) {
    if (dist <= 0.0) return;
    const Vec2 u = d / dist;
    const double gap = inside ? (radius - dist - r) : (dist - radius - r);
    if (gap > reach) return;
    const Vec2 n = inside ? -u : u;
    const Vec2 q = centre + radius * u;
    hits.push_back({0, q, n, gap, cross(omega, q - centre)});
    return;
  }
  // Rough cylinder (discs outside). Quick reject on the base circle.
  if (dist - radius - r > reach) return;
  const double P = period();
  const int m = static_cast<int>(profile.size()) - 1;  // segments per period
  const bool fast = unit_offsets_.size() == profile.size() && prepared_radius_ == radius && prepared_period_ == P &&
                    prepared_phase_ == phase && static_cast<int>(period_units_.size()) == n_periods;
  const bool fast_angle = fast && prepared_angle_ == angle;
  // Only the periods whose features can lie within a = r + reach of the centre: a feature at
  // distance rho >= rho_min from the axis and polar angle dphi from the centre's is at least
  // 2 sqrt(dist rho) sin(|dphi|/2) away, so |dphi| <= 2 asin(x) <= 2 x (1 + x^2) with
  // x = a / (2 sqrt(dist rho_min)), x <= 1/2. rho_min = radius - max depth - P also covers
  // the chords between vertices. Period k0 - 1 ends (and k0 + 1 begins) at arc length
  // k0 P (and (k0 + 1) P); skipping a period that cannot touch changes no result.
  const double rho_min = radius - max_depth_ - P;
  double w = -1.0;  // (w < 0: look at all three periods)
  if (rho_min > 0.0) {
    const double x = (r + reach) / (2.0 * std::sqrt(dist * rho_min));
    if (x <= 0.5) w = radius * 2.0 * x * (1.0 + x * x) * (1.0 + 1e-9) + 1e-12 * P;
  }
  // The period k0 the centre lies in, and bounds s_lo <= s_in <= s_hi on its arc position within
  // it. With a hint (the period found for this disc last time, engine-kept) that still holds,
  // by two cross products: no atan2, fmod or division. Then the test below looks at the same
  // periods or more, where the periods' reach is under half a period (w < P / 2): the same hits,
  // in the same order, as without the hint (a period that cannot touch adds none).
  int k0 = -1;
  double s_lo = 0.0, s_hi = 0.0;
  const double theta_p = P / radius;  // a period's angle
  if (hint && fast_angle && w >= 0.0 && w < 0.5 * P && theta_p <= 0.1 && *hint >= 0 && *hint < n_periods) {
    const int k = *hint, kn = k + 1 == n_periods ? 0 : k + 1;
    const Vec2 a = angle_rotation_, q0 = period_units_[k], q1 = period_units_[kn];
    const Vec2 u0{a.x * q0.x - a.y * q0.y, a.x * q0.y + a.y * q0.x}, u1{a.x * q1.x - a.y * q1.y, a.x * q1.y + a.y * q1.x};
    const double c0 = cross(u0, d), c1 = cross(d, u1);
    if (c0 >= 0.0 && c1 > 0.0 && dot(u0, d) > 0.0) {
      // s_in = radius theta with sin theta = c0 / dist, 0 <= theta <= theta_p (+ rounding):
      // sin theta <= theta <= sin theta (1 + theta_p^2)
      const double sr = radius * (c0 / dist);
      s_lo = sr - 1e-12 * P;
      s_hi = sr * (1.0 + theta_p * theta_p) + 1e-12 * P;
      k0 = k;
    }
  }
  if (k0 < 0) {
    const double circumference = P * n_periods;
    double phi = std::atan2(d.y, d.x) - angle;
    double s = phi * radius - phase;
    s = std::fmod(s, circumference);
    if (s < 0) s += circumference;
    if (s != s) return;  // a NaN centre touches nothing (and k0 below must be a number)
    k0 = static_cast<int>(std::floor(s / P));
    s_lo = s_hi = s - k0 * P;
    if (hint) *hint = k0 < n_periods ? k0 : k0 - n_periods;
  }
  const bool need_prev = w < 0.0 || s_lo <= w;
  const bool need_next = w < 0.0 || P - s_hi <= w;
  const double lim = r + reach;
  // One period in its own frame (period start on +x, origin at the centre): the centre cl, the
  // vertices, segment vectors, 1/|segment|^2 and convexity; u turns that frame into the world.
  // Segment interiors and convex vertices within reach become hits (concave vertices are covered
  // by the interiors of their two faces).
  auto test_period = [&](int k, Vec2 u, Vec2 cl, const Vec2* vert, const Vec2* edge, const double* inv_len2,
                         const std::uint8_t* convex) {
    auto to_world = [&](Vec2 v) { return Vec2{u.x * v.x - u.y * v.y, u.x * v.y + u.y * v.x}; };
    for (int j = 0; j < m; ++j) {
      const Vec2 a = vert[j], ab = edge[j];
      const double t = dot(cl - a, ab) * inv_len2[j];
      if (!(t > 0.0 && t < 1.0)) continue;  // (a NaN projection is no hit)
      const Vec2 dq = cl - (a + t * ab);
      const double dd2 = norm2(dq);
      if (dd2 > lim * lim || dd2 <= 0.0) continue;  // cheap reject before the square root
      const double dd = std::sqrt(dd2);
      const double gap = dd - r;
      if (gap > reach) continue;
      const Vec2 q = centre + to_world(a + t * ab);
      hits.push_back({static_cast<std::int64_t>(k) * 2 * m + j, q, to_world(dq / dd), gap, cross(omega, q - centre)});
    }
    for (int j = 0; j < m; ++j) {
      if (!convex[j]) continue;
      const Vec2 dq = cl - vert[j];
      const double dd2 = norm2(dq);
      if (dd2 > lim * lim || dd2 <= 0.0) continue;
      const double dd = std::sqrt(dd2);
      const double gap = dd - r;
      if (gap > reach) continue;
      const Vec2 v = centre + to_world(vert[j]);
      hits.push_back({static_cast<std::int64_t>(k) * 2 * m + m + j, v, to_world(dq / dd), gap, cross(omega, v - centre)});
    }
  };
  // (bitwise equal: the tables were made from this very profile; cheaper than comparing doubles)
  const bool prepared = fast && prepared_profile_.size() == profile.size() &&
                        std::memcmp(prepared_profile_.data(), profile.data(), profile.size() * sizeof(Vec2)) == 0;
  // Direct path (no prepared tables): each period's vertices by trigonometry, in the world frame
  // relative to the centre (u = identity). Scratch grows once per thread.
  thread_local std::vector<Vec2> vert, edge;
  thread_local std::vector<double> inv_len2;
  thread_local std::vector<std::uint8_t> convex;
  if (!prepared) {
    vert.resize(profile.size()); edge.resize(m); inv_len2.resize(m); convex.resize(m);
    for (int j = 0; j < m; ++j) {
      const Vec2 prev = j == 0 ? Vec2{profile[m - 1].x - P, profile[m - 1].y} : profile[j - 1];
      convex[j] = cross(profile[j] - prev, profile[j + 1] - profile[j]) > 0.0 ? 1 : 0;
    }
  }
  for (int dk = -1; dk <= 1; ++dk) {
    if ((dk == -1 && !need_prev) || (dk == 1 && !need_next)) continue;
    // k0 + dk lies in [-1, n_periods + 1] (s in [0, circumference], k0 = floor(s / P)): wrapped
    // by one add or subtract instead of two integer divisions
    int k = k0 + dk;
    k = k < 0 ? k + n_periods : k;
    k = k >= n_periods ? k - n_periods : k;
    if (prepared) {
      Vec2 u;  // (cos, sin) of the polar angle of period k's s = 0 (no trigonometry when prepare_angle() saw this angle)
      if (fast_angle) {
        const Vec2 q = period_units_[k], a = angle_rotation_;
        u = {a.x * q.x - a.y * q.y, a.x * q.y + a.y * q.x};
      } else {
        const double base = (k * P + phase) / radius + angle;
        u = {std::cos(base), std::sin(base)};
      }
      const Vec2 cl{u.x * d.x + u.y * d.y, u.x * d.y - u.y * d.x};  // d turned by -angle(u)
      test_period(k, u, cl, local_vertex_.data(), local_edge_.data(), local_inv_len2_.data(), convex_.data());
    } else {
      for (int j = 0; j <= m; ++j) vert[j] = profile_point(k, profile[j]) - centre;
      for (int j = 0; j < m; ++j) {
        edge[j] = vert[j + 1] - vert[j];
        const double l2 = norm2(edge[j]);
        inv_len2[j] = l2 > 0.0 ? 1.0 / l2 : 0.0;
      }
      test_period(k, {1.0, 0.0}, d, vert.data(), edge.data(), inv_len2.data(), convex.data());
    }
  }
}

void Wall::prepare() {
  unit_offsets_.clear();
  if (kind != Kind::cylinder || !rough() || !(radius > 0.0)) return;
  for (const auto& v : profile) unit_offsets_.push_back({std::cos(v.x / radius), std::sin(v.x / radius)});
  period_rotation_ = {std::cos(period() / radius), std::sin(period() / radius)};
  period_units_.resize(static_cast<std::size_t>(std::max(n_periods, 0)));
  for (int k = 0; k < n_periods; ++k) {
    const double base = (k * period() + phase) / radius;
    period_units_[k] = {std::cos(base), std::sin(base)};
  }
  max_depth_ = 0.0;
  for (const auto& v : profile) max_depth_ = std::max(max_depth_, v.y);
  const std::size_t nv = profile.size(), m = nv - 1;
  local_vertex_.resize(nv);
  for (std::size_t j = 0; j < nv; ++j) local_vertex_[j] = (radius - profile[j].y) * unit_offsets_[j];
  local_edge_.resize(m);
  local_inv_len2_.resize(m);
  convex_.assign(m, 0);
  for (std::size_t j = 0; j < m; ++j) {
    local_edge_[j] = local_vertex_[j + 1] - local_vertex_[j];
    const double l2 = norm2(local_edge_[j]);
    local_inv_len2_[j] = l2 > 0.0 ? 1.0 / l2 : 0.0;
    // Vertex j is convex (seen from outside) if the profile turns towards the axis there:
    // depth increases on the following segment relative to the straight continuation.
    const Vec2 prev = j == 0 ? Vec2{profile[m - 1].x - period(), profile[m - 1].y} : profile[j - 1];
    convex_[j] = cross(profile[j] - prev, profile[j + 1] - profile[j]) > 0.0 ? 1 : 0;
  }
  prepared_profile_ = profile;
  prepared_radius_ = radius;
  prepared_period_ = period();
  prepared_phase_ = phase;
  prepare_angle();
}

void Wall::prepare_angle() {
  if (prepared_angle_ == angle) return;
  angle_rotation_ = {std::cos(angle), std::sin(angle)};
  prepared_angle_ = angle;
}

double Wall::surface_radius(Vec2 p) const {
  if (kind != Kind::cylinder || !rough()) return radius;
  const double P = period();
  const Vec2 d = p - centre;
  double s = (std::atan2(d.y, d.x) - angle) * radius - phase;
  s = std::fmod(s, P);
  if (s < 0) s += P;
  for (std::size_t j = 1; j < profile.size(); ++j) {
    if (s <= profile[j].x) {
      const double t = (s - profile[j - 1].x) / (profile[j].x - profile[j - 1].x);
      return radius - (profile[j - 1].y + t * (profile[j].y - profile[j - 1].y));
    }
  }
  return radius - profile.back().y;
}

void Wall::validate() const {
  const std::string where = "wall '" + name + "'";
  if (kind == Kind::plane) {
    if (std::fabs(norm(normal) - 1.0) > 1e-9) throw_input(where, "normal", "", "must be a unit vector");
    return;
  }
  require_positive(where, "radius_m", radius);
  if (!profile.empty()) {
    if (inside) throw_input(where, "roughness", "", "roughness is only supported on the outside of a cylinder");
    if (profile.size() < 2 || profile.front().x != 0.0) throw_input(where, "profile", "", "must start at s = 0 with >= 2 vertices");
    if (profile.front().y != profile.back().y) throw_input(where, "profile", "", "first and last depth must be equal (periodic)");
    for (std::size_t i = 1; i < profile.size(); ++i) {
      if (!(profile[i].x > profile[i - 1].x)) throw_input(where, "profile", "", "arc length s must increase");
      if (profile[i].y < 0.0) throw_input(where, "profile", "", "depth must be >= 0");
    }
    if (n_periods < 3) throw_input(where, "n_periods", std::to_string(n_periods), "too few periods", ">= 3");
    if (std::fabs(period() * n_periods - 2.0 * constants::pi * radius) > 1e-9 * radius)
      throw_input(where, "profile", "", "period * n_periods must equal the circumference");
  }
}

void set_pyramid_roughness(Wall& w, double height, double base, double spacing) {
  const double nominal = spacing + base;
  const double circumference = 2.0 * constants::pi * w.radius;
  w.n_periods = static_cast<int>(std::lround(circumference / nominal));
  if (w.n_periods < 3) throw_input("wall '" + w.name + "'", "roughness", "", "period longer than a third of the circumference");
  const double scale = circumference / (w.n_periods * nominal);  // stretch to fit exactly
  const double L = spacing * scale, B = base * scale;
  // spacing 0: pyramids side by side, no flat between them (one point fewer: the profile's arc
  // length must increase)
  if (L > 0.0) w.profile = {{0.0, 0.0}, {L, 0.0}, {L + 0.5 * B, height}, {L + B, 0.0}};
  else w.profile = {{0.0, 0.0}, {0.5 * B, height}, {B, 0.0}};
  w.prepare();
}

}  // namespace nipdem::geometry
