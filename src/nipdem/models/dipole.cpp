#include "nipdem/models/dipole.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <exception>
#include <limits>
#include <tuple>
#include <fmt/format.h>
#include <omp.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/core/target_clones.hpp"

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

// ---- PairSum --------------------------------------------------------------------------------

PairSum::PairSum(PairSumParams p) : p_(p) {
  require_positive("dipole.pair_sum", "cutoff_m", p_.cutoff_m);
  require_range("dipole.pair_sum", "skin_m", p_.skin_m, 0.0, p_.cutoff_m);
  if (p_.threads < 1) throw_input("dipole.pair_sum", "threads", fmt::format("{}", p_.threads), "must be >= 1", ">= 1");
}

bool PairSum::moved(std::span<const double> x, std::span<const double> y) const {
  // Rebuild once the two largest displacements since the build add up to more than the skin
  // (a little less, so that rounding in this test can never let a pair closer than r_c be
  // missing from the list): no pair can then have closed the skin between them. A plain
  // "any particle moved more than skin/2" rebuilds up to twice as often when a few move fast.
  const std::size_t n = x.size();
  double d1 = 0.0, d2 = 0.0;  // the two largest squared displacements, d1 >= d2
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - x0_[i], dy = y[i] - y0_[i];
    double d = dx * dx + dy * dy;
    if (d != d) d = std::numeric_limits<double>::infinity();  // NaN counts as moved
    if (d > d2) {
      if (d > d1) { d2 = d1; d1 = d; } else { d2 = d; }
    }
  }
  return std::sqrt(d1) + std::sqrt(d2) > 0.98 * p_.skin_m;
}

void sort_row(int* c, int m, int row, RowSortBits& bits) {
  constexpr int kSpan = 64 * static_cast<int>(std::tuple_size_v<RowSortBits>);
  const int base = row - kSpan / 2;
  bool near = true;
  for (int k = 0; k < m; ++k) near &= static_cast<unsigned>(c[k] - base) < static_cast<unsigned>(kSpan);
  if (!near) {
    std::sort(c, c + m);
    return;
  }
  int w_lo = kSpan / 64, w_hi = -1;
  for (int k = 0; k < m; ++k) {
    const int o = c[k] - base;
    bits[static_cast<std::size_t>(o >> 6)] |= std::uint64_t{1} << (o & 63);
    w_lo = std::min(w_lo, o >> 6);
    w_hi = std::max(w_hi, o >> 6);
  }
  int out = 0;
  for (int w = w_lo; w <= w_hi; ++w) {
    std::uint64_t v = bits[static_cast<std::size_t>(w)];
    bits[static_cast<std::size_t>(w)] = 0;
    while (v != 0) {
      c[out++] = base + 64 * w + std::countr_zero(v);
      v &= v - 1;
    }
  }
}

void PairSum::rebuild(std::span<const double> x, std::span<const double> y, int run) {
  const std::size_t n = x.size();
  const double reach = p_.cutoff_m + p_.skin_m, reach2 = reach * reach;
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  bool first = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    if (first) { xmin = xmax = x[i]; ymin = ymax = y[i]; first = false; }
    xmin = std::min(xmin, x[i]); xmax = std::max(xmax, x[i]);
    ymin = std::min(ymin, y[i]); ymax = std::max(ymax, y[i]);
  }
  // Cells at least reach/2 wide (a 5 x 5 block of them holds every partner: about 2x the pair
  // circle's area instead of 2.9x for 3 x 3 cells of `reach`); coarser if a stray particle
  // would make the grid huge. Particles are binned by a counting sort, so each cell's particles
  // (index order) and their coordinates lie together for the search.
  double cs = 0.5 * reach;
  auto count = [&](double c) { return (std::floor((xmax - xmin) / c) + 1.0) * (std::floor((ymax - ymin) / c) + 1.0); };
  while (count(cs) > 4.0 * static_cast<double>(n) + 64.0) cs *= 2.0;
  const int nx = static_cast<int>((xmax - xmin) / cs) + 1, ny = static_cast<int>((ymax - ymin) / cs) + 1;
  const std::size_t ncell = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  cell_start_.assign(ncell + 1, 0);
  cell_of_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;  // such a particle gets no partners
    const int cx = std::min(nx - 1, static_cast<int>((x[i] - xmin) / cs));
    const int cy = std::min(ny - 1, static_cast<int>((y[i] - ymin) / cs));
    cell_of_[i] = cy * nx + cx;
    ++cell_start_[static_cast<std::size_t>(cell_of_[i]) + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  binned_.resize(static_cast<std::size_t>(cell_start_[ncell]));
  for (std::size_t i = 0; i < n; ++i)
    if (cell_of_[i] >= 0)
      binned_[static_cast<std::size_t>(cell_fill_[static_cast<std::size_t>(cell_of_[i])]++)] = {x[i], y[i], static_cast<int>(i)};
  // Rows are searched in parts of consecutive rows, on up to `run` threads, each into its own
  // buffer (row lengths into row_start_[i + 1]), then joined in row order: the list is the same
  // for any number of parts. Nothing that can throw leaves the region (the buffers grow inside
  // it: a bad_alloc is carried out and rethrown).
  row_start_.assign(n + 1, 0);
  const int parts = std::max(1, run);
  if (static_cast<int>(parts_.size()) < parts) parts_.resize(static_cast<std::size_t>(parts));
  std::vector<std::exception_ptr> failure(static_cast<std::size_t>(parts));
#pragma omp parallel num_threads(parts) if (parts > 1)
  {
    const int team = omp_get_num_threads();
    for (int u = omp_get_thread_num(); u < parts; u += team) {
      BuildPart& P = parts_[static_cast<std::size_t>(u)];
      try {
        P.nbr.clear();
        P.max_row = 0;
        const std::size_t i_lo = n * static_cast<std::size_t>(u) / static_cast<std::size_t>(parts);
        const std::size_t i_hi = n * static_cast<std::size_t>(u + 1) / static_cast<std::size_t>(parts);
        for (std::size_t i = i_lo; i < i_hi; ++i) {
          if (cell_of_[i] < 0) continue;
          const int cx = cell_of_[i] % nx, cy = cell_of_[i] / nx;
          const int ii = static_cast<int>(i);
          const double xi = x[i], yi = y[i];
          // Each candidate is written and the count moves on only if it is kept: no branch on the
          // owner or distance test (outcomes a predictor cannot learn).
          int m = 0;
          for (int oy = std::max(0, cy - 2); oy <= std::min(ny - 1, cy + 2); ++oy) {
            // the cells ox = cx-2 .. cx+2 of one grid row are consecutive: one run of particles
            const std::size_t c0 = static_cast<std::size_t>(oy) * nx + std::max(0, cx - 2);
            const std::size_t c1 = static_cast<std::size_t>(oy) * nx + std::min(nx - 1, cx + 2) + 1;
            const int k0 = cell_start_[c0], k1 = cell_start_[c1];
            if (P.cand.size() < static_cast<std::size_t>(m + (k1 - k0))) P.cand.resize(2 * static_cast<std::size_t>(m + (k1 - k0)));
            int* out = P.cand.data();
            for (int k = k0; k < k1; ++k) {
              const Binned& q = binned_[static_cast<std::size_t>(k)];
              const int j = q.index;
              // owner of the pair (a < b): a if a + b is even, else b
              const int a = std::min(ii, j), bb = std::max(ii, j);
              const int owner = ((a + bb) & 1) == 0 ? a : bb;
              const double dx = xi - q.x, dy = yi - q.y;
              out[m] = j;
              m += static_cast<int>((j != ii) & (owner == ii) & (dx * dx + dy * dy < reach2));
            }
          }
          sort_row(P.cand.data(), m, ii, P.bits);
          P.nbr.insert(P.nbr.end(), P.cand.begin(), P.cand.begin() + m);
          row_start_[i + 1] = m;
          P.max_row = std::max(P.max_row, m);
        }
      } catch (...) {
        failure[static_cast<std::size_t>(u)] = std::current_exception();
      }
    }
  }
  for (const auto& e : failure)
    if (e) {
      built_n_ = -1;  // (the list is half built: the next compute() builds it again)
      std::rethrow_exception(e);
    }
  for (std::size_t i = 0; i < n; ++i) row_start_[i + 1] += row_start_[i];
  max_row_ = 0;
  if (parts == 1) {
    nbr_.swap(parts_[0].nbr);  // one part: its buffer is the list
    max_row_ = parts_[0].max_row;
  } else {
    nbr_.resize(static_cast<std::size_t>(row_start_[n]));
    for (int u = 0, at = 0; u < parts; ++u) {
      const BuildPart& P = parts_[static_cast<std::size_t>(u)];
      std::copy(P.nbr.begin(), P.nbr.end(), nbr_.begin() + at);
      at += static_cast<int>(P.nbr.size());
      max_row_ = std::max(max_row_, P.max_row);
    }
  }
  x0_.assign(x.begin(), x.end());
  y0_.assign(y.begin(), y.end());
  built_n_ = static_cast<long>(n);
  ++builds_;
}

// One row's pair forces, eq. 2.4.39, for its n partners within r_c at once: the arithmetic of
// the scalar law (F_i = 3k/r^5 [a m_j + b m_i + (c - 5 a b / r^2) r], a = m_i.r, b = m_j.r,
// c = m_i.m_j; one sqrt, one division), the same operations in the same order in every lane, so
// each lane rounds as the scalar loop did. Compiled for AVX-512, AVX2 and generic x86-64 (GCC
// target_clones via NIPDEM_TARGET_CLONES, chosen at load time) with -ffp-contract=off (src/CMakeLists.txt): no clone
// fuses a multiply-add, so every machine gets the same bits.
NIPDEM_TARGET_CLONES
void dipole_row_forces(int n, double k3, double mix, double miy, const double* __restrict dxs, const double* __restrict dys,
                       const double* __restrict mjxs, const double* __restrict mjys, double* __restrict gxs,
                       double* __restrict gys) {
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const double dx = dxs[k], dy = dys[k], mjx = mjxs[k], mjy = mjys[k];
    const double r2 = dx * dx + dy * dy;
    const double ir2 = 1.0 / r2;
    const double ir = std::sqrt(ir2);
    const double a = mix * dx + miy * dy;
    const double b = mjx * dx + mjy * dy;
    const double c = mix * mjx + miy * mjy;
    const double pre = k3 * ir2 * ir2 * ir;
    const double s = c - 5.0 * a * b * ir2;
    gxs[k] = pre * (a * mjx + b * mix + s * dx);
    gys[k] = pre * (a * mjy + b * miy + s * dy);
  }
}

void PairSum::compute(std::span<const double> x, std::span<const double> y, std::span<const Vec2> m, bool same_set,
                      std::vector<double>& fx, std::vector<double>& fy, int run_threads) {
  const std::size_t n = x.size();
  if (n < 2) {
    fx.assign(n, 0.0);
    fy.assign(n, 0.0);
    return;
  }
  // Every value of fx, fy, pk_ and of the parts' buffers where they are read is written in the
  // region below, by the thread that reads it next where it can be: a line written by the other
  // core costs a transfer between the caches (two threads ran this pass at ~1.7x, not 2x).
  fx.resize(n);
  fy.resize(n);
  const int run = run_threads > 0 ? std::min(run_threads, p_.threads) : p_.threads;
  if (!same_set || built_n_ != static_cast<long>(n) || moved(x, y)) rebuild(x, y, run);
  pk_.resize(n);
  const int nt = p_.threads;
  // The rows each part writes to: its own and their partners (found again after a list build).
  const bool find_reach = reach_builds_ != builds_ || reach_n_ != static_cast<long>(n) || static_cast<int>(part_lo_.size()) != nt;
  part_lo_.resize(static_cast<std::size_t>(nt));
  part_hi_.resize(static_cast<std::size_t>(nt));
  buf_.resize(static_cast<std::size_t>(nt));
  rows_.resize(static_cast<std::size_t>(nt));
  for (auto& bv : buf_)  // sized here: nothing may allocate (and throw) inside the region
    if (bv.size() < 2 * n) bv.resize(2 * n);
  const auto row_len = static_cast<std::size_t>(max_row_);
  for (auto& r : rows_) {
    if (r.j.size() >= row_len) continue;
    for (auto* v : {&r.dx, &r.dy, &r.mx, &r.my, &r.gx, &r.gy}) v->resize(row_len);
    r.j.resize(row_len);
  }
  const double rc2 = p_.cutoff_m * p_.cutoff_m;
  const double k3 = 3.0 * k_mu0_4pi;
  const Packed* pk = pk_.data();
  const int* rs = row_start_.data();
  const int* nb = nbr_.data();
  const int n_entries = rs[n];
  Packed* pkw = pk_.data();
#pragma omp parallel num_threads(run)
  {
    const int t = omp_get_thread_num();
    // Row chunk u (of nt) goes to thread u mod T: the same sums if fewer threads run them.
    const int team = omp_get_num_threads();
    for (int u = t; u < nt; u += team) {  // the particles of the parts' own rows
      const std::size_t i0 = n * static_cast<std::size_t>(u) / static_cast<std::size_t>(nt);
      const std::size_t i1 = n * static_cast<std::size_t>(u + 1) / static_cast<std::size_t>(nt);
      for (std::size_t i = i0; i < i1; ++i) pkw[i] = {x[i], y[i], m[i].x, m[i].y};
    }
#pragma omp barrier
    for (int u = t; u < nt; u += team) {
      double* f = buf_[static_cast<std::size_t>(u)].data();
      RowScratch& S = rows_[static_cast<std::size_t>(u)];
      double *sdx = S.dx.data(), *sdy = S.dy.data(), *smx = S.mx.data(), *smy = S.my.data();
      double *gx = S.gx.data(), *gy = S.gy.data();
      int* sj = S.j.data();
      // rows split by index, so the summation order does not depend on the list content
      const std::size_t i0 = n * static_cast<std::size_t>(u) / static_cast<std::size_t>(nt);
      const std::size_t i1 = n * static_cast<std::size_t>(u + 1) / static_cast<std::size_t>(nt);
      if (find_reach) {  // [lo, hi): the part's rows and every listed partner of them
        int lo = static_cast<int>(i0), hi = static_cast<int>(i1);
        for (int e = rs[i0]; e < rs[i1]; ++e) { lo = std::min(lo, nb[e]); hi = std::max(hi, nb[e] + 1); }
        part_lo_[static_cast<std::size_t>(u)] = lo;
        part_hi_[static_cast<std::size_t>(u)] = hi;
      }
      std::fill(f + 2 * part_lo_[static_cast<std::size_t>(u)], f + 2 * part_hi_[static_cast<std::size_t>(u)], 0.0);
      for (std::size_t i = i0; i < i1; ++i) {
        const Packed pi = pk[i];
        // The partners within r_c, in list order, kept without a branch (about 3 in 4 of the
        // listed pairs are, at the presets' cut-off and skin): always written, counted if in.
        int cnt = 0;
        for (int e = rs[i]; e < rs[i + 1]; ++e) {
          if (e + 8 < n_entries) __builtin_prefetch(&pk[nb[e + 8]]);  // (a partner 8 ahead: bench_nip 1.015x)
          const int j = nb[e];
          const Packed& pj = pk[j];
          const double dx = pi.x - pj.x, dy = pi.y - pj.y;
          sdx[cnt] = dx; sdy[cnt] = dy; smx[cnt] = pj.mx; smy[cnt] = pj.my; sj[cnt] = j;
          cnt += (dx * dx + dy * dy < rc2) ? 1 : 0;  // NaN: left out
        }
        dipole_row_forces(cnt, k3, pi.mx, pi.my, sdx, sdy, smx, smy, gx, gy);
        double fxi = 0.0, fyi = 0.0;
        for (int k = 0; k < cnt; ++k) {  // in list order: the same sums as one loop over the row
          const int j = sj[k];
          fxi += gx[k];
          fyi += gy[k];
          f[2 * j] -= gx[k];
          f[2 * j + 1] -= gy[k];
        }
        f[2 * i] += fxi;
        f[2 * i + 1] += fyi;
      }
    }
#pragma omp barrier
    // Each part's rows' particles summed by the thread that ran the part (fixed part order:
    // reproducible for a given part count). A part that cannot have written particle i holds
    // +0 for it, and a sum that starts at +0 is never -0, so leaving it out changes no bit.
    for (int u = t; u < nt; u += team) {
      const std::size_t i0 = n * static_cast<std::size_t>(u) / static_cast<std::size_t>(nt);
      const std::size_t i1 = n * static_cast<std::size_t>(u + 1) / static_cast<std::size_t>(nt);
      for (std::size_t i = i0; i < i1; ++i) {
        double sx = 0.0, sy = 0.0;
        for (int q = 0; q < nt; ++q) {
          if (static_cast<int>(i) < part_lo_[static_cast<std::size_t>(q)] || static_cast<int>(i) >= part_hi_[static_cast<std::size_t>(q)]) continue;
          sx += buf_[static_cast<std::size_t>(q)][2 * i];
          sy += buf_[static_cast<std::size_t>(q)][2 * i + 1];
        }
        fx[i] = sx;
        fy[i] = sy;
      }
    }
  }
  reach_builds_ = builds_;
  reach_n_ = static_cast<long>(n);
}

void brute_force_pair_sum(std::span<const double> x, std::span<const double> y, std::span<const Vec2> m, double cutoff_m,
                          std::vector<double>& fx, std::vector<double>& fy) {
  const std::size_t n = x.size();
  fx.assign(n, 0.0);
  fy.assign(n, 0.0);
  const double rc2 = cutoff_m * cutoff_m;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const Vec2 r{x[i] - x[j], y[i] - y[j]};
      if (!(norm2(r) < rc2)) continue;
      const Vec2 f = dipole_force(m[i], m[j], r);
      fx[i] += f.x;
      fy[i] += f.y;
    }
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
