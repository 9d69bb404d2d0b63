#include "nipdem/models/magnet_field.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::magnet {

namespace {

double signed_area(const std::vector<Vec2>& v) {
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) a += cross(v[i], v[(i + 1) % v.size()]);
  return 0.5 * a;
}

// True when the closed segments [p1,p2] and [q1,q2] share a point.
bool segments_touch(Vec2 p1, Vec2 p2, Vec2 q1, Vec2 q2) {
  auto orient = [](Vec2 a, Vec2 b, Vec2 c) {
    const double v = cross(b - a, c - a);
    return (v > 0) - (v < 0);
  };
  auto on_seg = [](Vec2 a, Vec2 b, Vec2 c) {  // c collinear with a-b: within the box?
    return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
           c.y <= std::max(a.y, b.y);
  };
  const int o1 = orient(p1, p2, q1), o2 = orient(p1, p2, q2), o3 = orient(q1, q2, p1), o4 = orient(q1, q2, p2);
  if (o1 != o2 && o3 != o4) return true;
  if (o1 == 0 && on_seg(p1, p2, q1)) return true;
  if (o2 == 0 && on_seg(p1, p2, q2)) return true;
  if (o3 == 0 && on_seg(q1, q2, p1)) return true;
  if (o4 == 0 && on_seg(q1, q2, p2)) return true;
  return false;
}

void validate_block(const MagnetBlock& b, std::size_t k) {
  const std::string where = fmt::format("magnet.block[{}]", k);
  const auto& v = b.vertices_m;
  if (v.size() < 3) throw_input(where, "vertices_m", fmt::format("{} vertices", v.size()), "a polygon needs at least 3 vertices");
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i].x) || !std::isfinite(v[i].y) || std::abs(v[i].x) > 1.0 || std::abs(v[i].y) > 1.0)
      throw_input(where, fmt::format("vertices_m[{}]", i), fmt::format("({:g}, {:g})", v[i].x, v[i].y),
                  "vertex must be finite and within 1 m of the origin", "|x|, |y| <= 1 m");
  }
  double size = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) size = std::max(size, norm(v[(i + 1) % v.size()] - v[i]));
  if (std::abs(signed_area(v)) <= 1e-12 * size * size)
    throw_input(where, "vertices_m", "", "polygon has (nearly) zero area");
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (norm(v[(i + 1) % n] - v[i]) == 0.0) throw_input(where, fmt::format("vertices_m[{}]", i), "", "repeated vertex");
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_touch(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]))
        throw_input(where, "vertices_m", fmt::format("edges {} and {}", i, j), "polygon is self-intersecting");
    }
  }
  const Vec2 M = b.magnetisation_A_per_m;
  if (!std::isfinite(M.x) || !std::isfinite(M.y) || norm(M) > 1e7)
    throw_input(where, "magnetisation_A_per_m", fmt::format("({:g}, {:g})", M.x, M.y), "out of range",
                "finite, |M| <= 1e7 A/m (|B_r| <= 12.6 T)");
}

}  // namespace

MagnetBlock MagnetBlock::from_remanence(std::vector<Vec2> vertices_m, Vec2 Br_T) {
  return {std::move(vertices_m), Br_T / constants::mu0};
}

BlockAssembly::BlockAssembly(std::vector<MagnetBlock> blocks, std::string name)
    : blocks_(std::move(blocks)), name_(std::move(name)) {
  if (blocks_.empty()) throw_input("magnet", "blocks", "[]", "a magnet assembly needs at least one block");
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    validate_block(blocks_[k], k);
    std::vector<Vec2> v = blocks_[k].vertices_m;
    const double sign = signed_area(v) > 0 ? 1.0 : -1.0;  // make the outward normal n = -i t (CCW)
    const Vec2 M = blocks_[k].magnetisation_A_per_m;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const Vec2 a = v[i], b = v[(i + 1) % v.size()];
      const Vec2 t = (b - a) / norm(b - a);
      const Vec2 n = sign * Vec2{t.y, -t.x};
      const double K = cross(M, n);  // (M x n)_z [A/m]
      if (K == 0.0) continue;        // edge parallel to M carries no current
      // c = -i mu0 K/(2 pi) * conj(t) = mu0 K/(2 pi) * (-t.y - i t.x)
      const double s = constants::mu0 * K / (2.0 * constants::pi);
      edges_.push_back({a.x, a.y, b.x, b.y, -s * t.y, -s * t.x});
    }
  }
}

Sample BlockAssembly::at(Vec2 p) const {
  double fr = 0.0, fi = 0.0, gr = 0.0, gi = 0.0;
  for (const Edge& e : edges_) {
    const double px = p.x - e.ax, py = p.y - e.ay;  // z - a
    const double qx = p.x - e.bx, qy = p.y - e.by;  // z - b
    const double p2 = px * px + py * py, q2 = qx * qx + qy * qy;
    // Log((z-a)/(z-b)) = 0.5 ln(|z-a|^2/|z-b|^2) + i arg((z-a) conj(z-b))
    const double lr = 0.5 * std::log(p2 / q2);
    const double li = std::atan2(py * qx - px * qy, px * qx + py * qy);
    fr += e.cr * lr - e.ci * li;
    fi += e.cr * li + e.ci * lr;
    // 1/(z-a) - 1/(z-b) = conj(z-a)/|z-a|^2 - conj(z-b)/|z-b|^2
    const double dr = px / p2 - qx / q2, di = -py / p2 + qy / q2;
    gr += e.cr * dr - e.ci * di;
    gi += e.cr * di + e.ci * dr;
  }
  Sample s;
  s.B = {fr, -fi};
  s.dB.xx = gr;
  s.dB.yx = -gi;
  s.dB.xy = -gi;
  s.dB.yy = -gr;
  return s;
}

namespace {
// Does the segment a-b meet the closed box [lo, hi]? (Liang-Barsky clipping.)
bool segment_meets_box(Vec2 a, Vec2 b, Vec2 lo, Vec2 hi) {
  double t0 = 0.0, t1 = 1.0;
  const double d[2] = {b.x - a.x, b.y - a.y}, p0[2] = {a.x, a.y}, l[2] = {lo.x, lo.y}, h[2] = {hi.x, hi.y};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (p0[k] < l[k] || p0[k] > h[k]) return false;
      continue;
    }
    double ta = (l[k] - p0[k]) / d[k], tb = (h[k] - p0[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}
}  // namespace

// Inside a uniformly magnetised block and outside all blocks the field is analytic; it jumps only
// across the edges (the current sheets), so a box no edge touches holds a smooth field.
bool BlockAssembly::smooth_in(Vec2 lo, Vec2 hi) const {
  for (const auto& b : blocks_) {
    const auto& v = b.vertices_m;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (segment_meets_box(v[i], v[(i + 1) % v.size()], lo, hi)) return false;
  }
  return true;
}

std::vector<std::vector<Vec2>> BlockAssembly::material() const {
  std::vector<std::vector<Vec2>> m;
  for (const auto& b : blocks_) m.push_back(b.vertices_m);
  return m;
}

std::string BlockAssembly::describe() const {
  return fmt::format("{} ({} blocks, analytic 2D prism field)", name_, blocks_.size());
}

void validate(const KnifeParams& k) {
  const std::string w = "magnet.knife";
  require_range(w, "tip_depth_m", k.tip_depth_m, 1e-6, 0.02);
  require_range(w, "blade_width_m", k.blade_width_m, 10e-6, 0.05);
  require_range(w, "bevel_deg", k.bevel_deg, 0.0, 80.0);
  require_range(w, "height_m", k.height_m, 10e-6, 0.1);
  if (k.blade_width_m * std::tan(k.bevel_deg * constants::pi / 180.0) >= k.height_m)
    throw_input(w, "bevel_deg", fmt::format("{:g}", k.bevel_deg),
                "bevel reaches the bottom of the blade", "blade_width*tan(bevel) < height");
  require_range(w, "blade_Br_T", k.blade_Br_T, -3.0, 3.0);
  require_range(w, "return_width_m", k.return_width_m, 0.0, 0.05);
  require_range(w, "return_recess_m", k.return_recess_m, 0.0, 0.02);
  if (k.return_width_m > 0 && k.return_recess_m >= k.height_m)
    throw_input(w, "return_recess_m", fmt::format("{:g}", k.return_recess_m), "return magnet has no height",
                "return_recess < height");
  require_range(w, "return_Br_T", k.return_Br_T, -3.0, 3.0);
}

void validate(const ColorPoleParams& c) {
  const std::string w = "magnet.color_pole";
  require_range(w, "tip_depth_m", c.tip_depth_m, 1e-6, 0.02);
  require_range(w, "pole_width_m", c.pole_width_m, 10e-6, 0.05);
  require_range(w, "height_m", c.height_m, 10e-6, 0.1);
  require_range(w, "Br_T", c.Br_T, -3.0, 3.0);
}

BlockAssembly make_knife(const KnifeParams& k) {
  validate(k);
  const double d = k.tip_depth_m, W = k.blade_width_m, H = k.height_m;
  const double drop = W * std::tan(k.bevel_deg * constants::pi / 180.0);
  std::vector<MagnetBlock> blocks;
  blocks.push_back(MagnetBlock::from_remanence({{0, -d}, {-W, -d - drop}, {-W, -d - H}, {0, -d - H}}, {0, k.blade_Br_T}));
  if (k.return_width_m > 0 && k.return_Br_T != 0) {
    const double top = -d - k.return_recess_m;
    blocks.push_back(MagnetBlock::from_remanence({{0, top}, {0, -d - H}, {k.return_width_m, -d - H}, {k.return_width_m, top}},
                                                 {-k.return_Br_T, 0}));
  }
  return BlockAssembly(std::move(blocks), "black magnetic knife");
}

BlockAssembly make_color_pole(const ColorPoleParams& c) {
  validate(c);
  const double d = c.tip_depth_m, W = c.pole_width_m, H = c.height_m;
  return BlockAssembly({MagnetBlock::from_remanence({{0, -d}, {-W, -d}, {-W, -d - H}, {0, -d - H}}, {0, c.Br_T})},
                       "colour magnet pole");
}

PlacedField::PlacedField(std::shared_ptr<const MagnetField> inner, Vec2 origin_m, double angle_rad)
    : inner_(std::move(inner)), origin_(origin_m), c_(std::cos(angle_rad)), s_(std::sin(angle_rad)) {
  if (!inner_) throw_input("magnet.placed", "inner", "null", "no field source given");
  if (!std::isfinite(origin_m.x) || !std::isfinite(origin_m.y) || !std::isfinite(angle_rad))
    throw_input("magnet.placed", "origin/angle", "", "must be finite");
}

Sample PlacedField::at(Vec2 p) const {
  const Vec2 d = p - origin_;
  const Vec2 local{c_ * d.x + s_ * d.y, -s_ * d.x + c_ * d.y};  // R^T d
  const Sample l = inner_->at(local);
  Sample g;
  g.B = {c_ * l.B.x - s_ * l.B.y, s_ * l.B.x + c_ * l.B.y};
  // dB' = R dB R^T
  const double axx = c_ * l.dB.xx - s_ * l.dB.yx, axy = c_ * l.dB.xy - s_ * l.dB.yy;  // (R dB) row x
  const double ayx = s_ * l.dB.xx + c_ * l.dB.yx, ayy = s_ * l.dB.xy + c_ * l.dB.yy;  // (R dB) row y
  g.dB.xx = axx * c_ - axy * s_;
  g.dB.xy = axx * s_ + axy * c_;
  g.dB.yx = ayx * c_ - ayy * s_;
  g.dB.yy = ayx * s_ + ayy * c_;
  return g;
}

std::string PlacedField::describe() const { return inner_->describe() + " (placed)"; }

bool PlacedField::smooth_in(Vec2 lo, Vec2 hi) const {
  // bounding box of the engine-frame box in the inner frame (conservative for a rotation)
  Vec2 a{1e300, 1e300}, b{-1e300, -1e300};
  for (Vec2 c : {lo, hi, Vec2{lo.x, hi.y}, Vec2{hi.x, lo.y}}) {
    const Vec2 d = c - origin_;
    const Vec2 l{c_ * d.x + s_ * d.y, -s_ * d.x + c_ * d.y};
    a = {std::min(a.x, l.x), std::min(a.y, l.y)};
    b = {std::max(b.x, l.x), std::max(b.y, l.y)};
  }
  return inner_->smooth_in(a, b);
}

std::vector<std::vector<Vec2>> PlacedField::material() const {
  auto m = inner_->material();
  for (auto& poly : m)
    for (auto& v : poly) v = origin_ + Vec2{c_ * v.x - s_ * v.y, s_ * v.x + c_ * v.y};
  return m;
}

}  // namespace nipdem::magnet
