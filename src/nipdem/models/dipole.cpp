#include "nipdem/models/dipole.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"

namespace nipdem::dipole {

namespace {
constexpr double k_mu0_4pi = constants::mu0 / (4.0 * constants::pi);
}

Vec2 dipole_force(Vec2 mi, Vec2 mj, Vec2 r) {
  const double r2 = norm2(r);
  const double rn = std::sqrt(r2);
  const Vec2 e = r / rn;
  const double a = dot(mi, e), b = dot(mj, e), c = dot(mi, mj);
  const double pre = 3.0 * k_mu0_4pi / (r2 * r2);
  return pre * (a * mj + b * mi + (c - 5.0 * a * b) * e);
}

double dipole_energy(Vec2 mi, Vec2 mj, Vec2 r) {
  const double r2 = norm2(r);
  const double rn = std::sqrt(r2);
  const Vec2 e = r / rn;
  return k_mu0_4pi / (r2 * rn) * (dot(mi, mj) - 3.0 * dot(mi, e) * dot(mj, e));
}

magnet::Sample dipole_field(Vec2 m, Vec2 r) {
  // B_i = k (3 r_i (m.r)/r^5 - m_i/r^3)
  // dB_i/dx_j = k [3 (delta_ij (m.r) + r_i m_j + m_i r_j)/r^5 - 15 r_i r_j (m.r)/r^7]
  const double r2 = norm2(r);
  const double r1 = std::sqrt(r2);
  const double ir3 = 1.0 / (r2 * r1), ir5 = ir3 / r2, ir7 = ir5 / r2;
  const double mr = dot(m, r);
  magnet::Sample s;
  s.B = k_mu0_4pi * (3.0 * mr * ir5 * r - ir3 * m);
  auto g = [&](double ri, double rj, double mi, double mj, double delta) {
    return k_mu0_4pi * (3.0 * (delta * mr + ri * mj + mi * rj) * ir5 - 15.0 * ri * rj * mr * ir7);
  };
  s.dB.xx = g(r.x, r.x, m.x, m.x, 1.0);
  s.dB.xy = g(r.x, r.y, m.x, m.y, 0.0);
  s.dB.yx = g(r.y, r.x, m.y, m.x, 0.0);
  s.dB.yy = g(r.y, r.y, m.y, m.y, 1.0);
  return s;
}

Vec3 dipole_force3(Vec3 mi, Vec3 mj, Vec3 r) {
  const double r2 = r.x * r.x + r.y * r.y + r.z * r.z;
  const double rn = std::sqrt(r2);
  const double ex = r.x / rn, ey = r.y / rn, ez = r.z / rn;
  const double a = mi.x * ex + mi.y * ey + mi.z * ez;
  const double b = mj.x * ex + mj.y * ey + mj.z * ez;
  const double c = mi.x * mj.x + mi.y * mj.y + mi.z * mj.z;
  const double pre = 3.0 * k_mu0_4pi / (r2 * r2);
  const double d = c - 5.0 * a * b;
  return {pre * (a * mj.x + b * mi.x + d * ex), pre * (a * mj.y + b * mi.y + d * ey), pre * (a * mj.z + b * mi.z + d * ez)};
}

double cutoff_radius(double radius_m, double packing_fraction, double rel_tol) {
  require_positive("dipole.cutoff", "radius_m", radius_m);
  require_range("dipole.cutoff", "packing_fraction", packing_fraction, 1e-6, 0.907);
  require_range("dipole.cutoff", "rel_tol", rel_tol, 1e-9, 1.0);
  return 4.0 * radius_m * std::sqrt(packing_fraction / rel_tol);
}

std::vector<Vec2> random_dense_packing(double R, double phi, double L, std::uint64_t seed) {
  const std::string w = "dipole.packing";
  require_positive(w, "radius_m", R);
  require_range(w, "packing_fraction", phi, 0.01, 0.85);
  require_positive(w, "box_m", L);
  const auto n = static_cast<std::size_t>(phi * L * L / (constants::pi * R * R));
  if (n < 2 || n > 200000) throw_input(w, "box_m", fmt::format("{:g}", L), "gives an unusable particle count",
                                       "2..200000 particles");
  Rng rng(seed);
  std::vector<Vec2> p(n);
  for (auto& q : p) q = {rng.uniform(0, L), rng.uniform(0, L)};
  // Cell list with cell >= 2R, periodic.
  const int nc = std::max(1, static_cast<int>(L / (2.0 * R)));
  const double cs = L / nc;
  std::vector<int> head(static_cast<std::size_t>(nc * nc)), next(n);
  auto wrap = [L](double x) { return x - L * std::floor(x / L); };
  for (int sweep = 0; sweep < 400; ++sweep) {
    std::fill(head.begin(), head.end(), -1);
    for (std::size_t i = 0; i < n; ++i) {
      const int cx = std::min(nc - 1, static_cast<int>(p[i].x / cs)), cy = std::min(nc - 1, static_cast<int>(p[i].y / cs));
      next[i] = head[static_cast<std::size_t>(cy * nc + cx)];
      head[static_cast<std::size_t>(cy * nc + cx)] = static_cast<int>(i);
    }
    double worst = 0.0;
    std::vector<Vec2> disp(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int cx = std::min(nc - 1, static_cast<int>(p[i].x / cs)), cy = std::min(nc - 1, static_cast<int>(p[i].y / cs));
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int ox = (cx + dx + nc) % nc, oy = (cy + dy + nc) % nc;
          for (int j = head[static_cast<std::size_t>(oy * nc + ox)]; j >= 0; j = next[static_cast<std::size_t>(j)]) {
            if (static_cast<std::size_t>(j) <= i) continue;
            Vec2 d = p[i] - p[static_cast<std::size_t>(j)];
            d.x -= L * std::round(d.x / L);
            d.y -= L * std::round(d.y / L);
            const double dist = norm(d);
            const double ov = 2.0 * R - dist;
            if (ov > 0) {
              worst = std::max(worst, ov);
              const Vec2 e = dist > 0 ? d / dist : Vec2{1, 0};
              disp[i] += 0.5 * ov * e;
              disp[static_cast<std::size_t>(j)] -= 0.5 * ov * e;
            }
          }
        }
    }
    for (std::size_t i = 0; i < n; ++i) p[i] = {wrap(p[i].x + disp[i].x), wrap(p[i].y + disp[i].y)};
    if (worst < 0.01 * R) break;
  }
  return p;
}

std::vector<TruncationStats> measure_cutoff_truncation(const TruncationSetup& s, const std::vector<double>& cutoffs) {
  const std::string w = "dipole.truncation";
  require_positive(w, "reference_cutoff_m", s.reference_cutoff_m);
  require_positive(w, "probe_radius_m", s.probe_radius_m);
  if (s.probe_radius_m + s.reference_cutoff_m > 0.5 * s.box_m)
    throw_input(w, "box_m", fmt::format("{:g}", s.box_m), "box too small for probe region + reference cut-off",
                "box_m >= 2 (probe_radius_m + reference_cutoff_m)");
  for (double rc : cutoffs) require_range(w, "cutoff_m", rc, 2.0 * s.radius_m, s.reference_cutoff_m);
  const auto p = random_dense_packing(s.radius_m, s.packing_fraction, s.box_m, s.seed);
  const Vec2 m{std::cos(s.field_angle_rad), std::sin(s.field_angle_rad)};  // unit moment: errors are relative
  const Vec2 c{0.5 * s.box_m, 0.5 * s.box_m};
  const double f_contact = 6.0 * k_mu0_4pi / std::pow(2.0 * s.radius_m, 4);
  std::vector<std::vector<double>> rel(cutoffs.size()), abs_c(cutoffs.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (norm(p[i] - c) > s.probe_radius_m) continue;
    Vec2 ref{};
    std::vector<Vec2> trunc(cutoffs.size());
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (j == i) continue;
      const Vec2 d = p[i] - p[j];  // no periodic images: the reference is the finite sum to r_ref
      const double r = norm(d);
      if (r > s.reference_cutoff_m || r < 1e-3 * s.radius_m) continue;
      const Vec2 f = dipole_force(m, m, d);
      ref += f;
      for (std::size_t k = 0; k < cutoffs.size(); ++k)
        if (r <= cutoffs[k]) trunc[k] += f;
    }
    for (std::size_t k = 0; k < cutoffs.size(); ++k) {
      const double err = norm(trunc[k] - ref);
      rel[k].push_back(err / std::max(norm(ref), 1e-300));
      abs_c[k].push_back(err / f_contact);
    }
  }
  std::vector<TruncationStats> out;
  for (std::size_t k = 0; k < cutoffs.size(); ++k) {
    TruncationStats t;
    t.cutoff_m = cutoffs[k];
    t.probes = static_cast<int>(rel[k].size());
    if (t.probes == 0) throw_input(w, "probe_radius_m", fmt::format("{:g}", s.probe_radius_m), "no probe particle");
    double sum = 0, sumc = 0;
    for (double v : rel[k]) sum += v;
    for (double v : abs_c[k]) sumc += v;
    t.mean_rel_error = sum / t.probes;
    t.mean_rel_to_contact = sumc / t.probes;
    std::vector<double> sorted = rel[k];
    std::sort(sorted.begin(), sorted.end());
    t.max_rel_error = sorted.back();
    t.p95_rel_error = sorted[static_cast<std::size_t>(0.95 * (sorted.size() - 1))];
    out.push_back(t);
  }
  return out;
}

}  // namespace nipdem::dipole
