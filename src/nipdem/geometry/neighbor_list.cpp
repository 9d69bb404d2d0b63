#include "nipdem/geometry/neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>

#include <fmt/format.h>
#include <omp.h>

namespace nipdem::geometry {

bool NeighborList::needs_rebuild(std::span<const double> x, std::span<const double> y) const {
  if (x.size() != x0_.size()) return true;
  double d1 = 0.0, d2 = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) track(i, x[i], y[i], d1, d2);
  return exceeds(d1, d2);
}

void NeighborList::rebuild(std::span<const double> x, std::span<const double> y, std::span<const double> r,
                           std::span<const int> body, std::span<const int> old_of_new,
                           const NeighborListParams& p, std::span<const double> half_skin) {
  const std::size_t n = x.size();
  const bool per_disc = !half_skin.empty();
  double h_lo = 0.5 * p.skin, h_hi = h_lo;
  if (per_disc) {
    if (half_skin.size() != n) throw std::invalid_argument(fmt::format("neighbour list: {} skins for {} discs", half_skin.size(), n));
    for (std::size_t i = 0; i < n; ++i)
      if (!(half_skin[i] >= 0.0 && std::isfinite(half_skin[i])))
        throw std::invalid_argument(fmt::format("neighbour list: skin {} of disc {} is not finite and >= 0", half_skin[i], i));
    if (n > 0) {
      const auto [lo, hi] = std::minmax_element(half_skin.begin(), half_skin.end());
      h_lo = *lo;
      h_hi = *hi;
    }
  }
  params_ = p;
  skin_ = p.skin;
  new_start_.assign(n + 1, 0);
  new_nbr_.clear();
  new_eta_.clear();
  new_slide_.clear();
  if (n == 0) {
    ++builds_;
    row_start_ = new_start_;
    nbr_.clear(); eta_.clear(); slide_.clear();
    x0_.clear(); y0_.clear(); h_.clear(); inv_h2_.clear();
    wide_ = 0;
    return;
  }
  double rmax = 0.0, xmin = x[0], xmax = x[0], ymin = y[0], ymax = y[0];
  bool finite = true;
  for (std::size_t i = 0; i < n; ++i) {
    rmax = std::max(rmax, r[i]);
    xmin = std::min(xmin, x[i]); xmax = std::max(xmax, x[i]);
    ymin = std::min(ymin, y[i]); ymax = std::max(ymax, y[i]);
    finite = finite & std::isfinite(x[i]) & std::isfinite(y[i]);
  }
  // Within reach of each other: r_i + r_j + reach (+ h_i + h_j with skins per disc). The cells
  // are as wide as the farthest pair of discs with the smallest skins can reach; a disc whose
  // skin reaches farther is searched beyond its 3 x 3 cells (the wide search below).
  const double reach = per_disc ? p.extra_range : p.skin + p.extra_range;
  double cell = 2.0 * rmax + (per_disc ? p.extra_range + 2.0 * h_lo : reach);
  const double L = p.x_hi - p.x_lo;
  // Refuse what cannot be binned before anything depends on it (nothing has changed yet except
  // the scratch start array and the parameters, which the next build sets again).
  if (!finite || !(std::max(xmax - xmin, ymax - ymin) <= kMaxCellsPerAxis * cell)) {
    std::size_t bad = 0;
    if (!finite) {
      while (std::isfinite(x[bad]) && std::isfinite(y[bad])) ++bad;
    } else {  // the disc farthest from the median position is the one flung away
      std::vector<double> xs(x.begin(), x.end()), ys(y.begin(), y.end());
      std::nth_element(xs.begin(), xs.begin() + n / 2, xs.end());
      std::nth_element(ys.begin(), ys.begin() + n / 2, ys.end());
      const double cx = xs[n / 2], cy = ys[n / 2];
      double far = -1.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double d = std::max(std::abs(x[i] - cx), std::abs(y[i] - cy));
        if (d > far) { far = d; bad = i; }
      }
    }
    throw BadPositionError(bad, x[bad], y[bad],
                           fmt::format("neighbour list: disc {} at ({}, {}) m: {}", bad, x[bad], y[bad],
                                       finite ? "so far from the other discs that it cannot be binned (more than 2^30 cells)"
                                              : "position is not finite"));
  }
  ++builds_;
  int nx, ny;
  if (p.periodic_x) {
    xmin = p.x_lo;
    nx = std::max(1, static_cast<int>(std::floor(L / cell)));
  } else {
    nx = std::max(1, static_cast<int>((xmax - xmin) / cell) + 1);
  }
  ny = std::max(1, static_cast<int>((ymax - ymin) / cell) + 1);
  // Guard against absurd grids (e.g. one disc flung far away): cap the cell count.
  while (static_cast<double>(nx) * ny > 8.0 * static_cast<double>(n) + 1024.0) {
    cell *= 1.5;
    nx = p.periodic_x ? std::max(1, static_cast<int>(std::floor(L / cell))) : std::max(1, static_cast<int>((xmax - xmin) / cell) + 1);
    ny = std::max(1, static_cast<int>((ymax - ymin) / cell) + 1);
  }
  const double cwx = p.periodic_x ? L / nx : cell;
  auto cell_x = [&](double xi) {
    int c = static_cast<int>(std::floor((xi - xmin) / cwx));
    if (p.periodic_x) { c %= nx; if (c < 0) c += nx; }
    return std::clamp(c, 0, nx - 1);
  };
  auto cell_y = [&](double yi) { return std::clamp(static_cast<int>((yi - ymin) / cell), 0, ny - 1); };
  // Bin by a counting sort: each cell's discs lie together (index order within a cell) with
  // their coordinates, radius and body beside them, so the row search reads candidates from
  // consecutive memory instead of chasing a linked list through the disc arrays.
  const std::size_t ncell = static_cast<std::size_t>(nx) * ny;
  cell_start_.assign(ncell + 1, 0);
  cell_of_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int c = cell_y(y[i]) * nx + cell_x(x[i]);
    cell_of_[i] = c;
    ++cell_start_[static_cast<std::size_t>(c) + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  binned_.resize(n);
  if (per_disc) binned_h_.resize(n);
  cell_last_.assign(ncell, -1);  // each cell's largest disc index (its last), -1 if empty
  for (std::size_t i = 0; i < n; ++i) {
    cell_last_[static_cast<std::size_t>(cell_of_[i])] = static_cast<int>(i);
    const int k = cell_fill_[static_cast<std::size_t>(cell_of_[i])]++;
    binned_[static_cast<std::size_t>(k)] = {x[i], y[i], r[i], static_cast<int>(i), body[i]};
    if (per_disc) binned_h_[static_cast<std::size_t>(k)] = half_skin[i];
  }
  // The wide search: a pair farther apart than a cell may be within r_i + r_j + extra + h_i + h_j
  // only if one of its discs has a skin that reaches beyond the cells around it; that disc, f,
  // with the larger skin of the two (h_j <= h_f), finds it: each disc whose reach
  // r_f + r_max + extra + 2 h_f exceeds a cell searches the cells that far around it for
  // partners with h_j <= h_f farther than a cell (the nearer ones the row search finds). The
  // pairs join their rows below. Serial: such discs are the few fast ones.
  wide_ = 0;
  wide_pairs_.clear();
  if (per_disc && h_hi > h_lo) {
    const double cell2 = cell * cell;
    for (std::size_t f = 0; f < n; ++f) {
      const double hf = half_skin[f];
      const double reach_f = r[f] + rmax + p.extra_range + 2.0 * hf;
      if (!(reach_f > cell)) continue;
      ++wide_;
      const int k = static_cast<int>(std::ceil(reach_f / cell));
      const int cx = cell_of_[f] % nx, cy = cell_of_[f] / nx;
      for (int yy = std::max(0, cy - k); yy <= std::min(ny - 1, cy + k); ++yy) {
        const int xa = p.periodic_x ? cx - k : std::max(0, cx - k), xb = p.periodic_x ? cx + k : std::min(nx - 1, cx + k);
        for (int xc = xa; xc <= xb; ++xc) {
          const int xx = p.periodic_x ? ((xc % nx) + nx) % nx : xc;  // (a narrow box: repeats, removed below)
          const std::size_t c = static_cast<std::size_t>(yy) * nx + static_cast<std::size_t>(xx);
          for (int q = cell_start_[c]; q < cell_start_[c + 1]; ++q) {
            const Binned& d = binned_[static_cast<std::size_t>(q)];
            const double hj = binned_h_[static_cast<std::size_t>(q)];
            if (d.index == static_cast<int>(f) || d.body == body[f] || hj > hf) continue;
            double dx = d.x - x[f];
            const double dy = d.y - y[f];
            if (p.periodic_x) dx -= L * std::nearbyint(dx / L);
            const double rc = r[f] + d.r + p.extra_range + hf + hj;
            const double d2 = dx * dx + dy * dy;
            if (d2 < rc * rc && d2 > cell2)
              wide_pairs_.emplace_back(std::min(static_cast<int>(f), d.index), std::max(static_cast<int>(f), d.index));
          }
        }
      }
    }
    std::sort(wide_pairs_.begin(), wide_pairs_.end());
    wide_pairs_.erase(std::unique(wide_pairs_.begin(), wide_pairs_.end()), wide_pairs_.end());
  }
  wide_start_.assign(n + 1, 0);
  wide_nbr_.resize(wide_pairs_.size());
  for (const auto& [a, b] : wide_pairs_) ++wide_start_[static_cast<std::size_t>(a) + 1];
  for (std::size_t i = 0; i < n; ++i) wide_start_[i + 1] += wide_start_[i];
  for (std::size_t q = 0; q < wide_pairs_.size(); ++q) wide_nbr_[q] = wide_pairs_[q].second;  // (sorted by row)
  // Rows are searched in parallel, each thread over one contiguous range of rows into its own
  // buffers, then concatenated in order: the list is the same for any thread count.
  const int nt = std::max(1, std::min(p.threads, static_cast<int>(n / 1024) + 1));
  if (static_cast<int>(rows_.size()) < nt) rows_.resize(nt);
  const bool has_old = !old_of_new.empty();
  const bool has_prev = !row_start_.empty();
  for (int t = 0; t < nt; ++t) { rows_[t].nbr.clear(); rows_[t].eta.clear(); rows_[t].slide.clear(); }
  // The rows grow inside the region: a bad_alloc there must not cross it (std::terminate).
  // Each thread keeps its own and the lowest thread's is rethrown after the region.
  std::vector<std::exception_ptr> failure(static_cast<std::size_t>(nt));
#pragma omp parallel num_threads(nt) if (nt > 1)
  {
  try {
    const int T = omp_get_num_threads(), t = omp_get_thread_num();
    const std::size_t i_lo = n * t / T, i_hi = n * (t + 1) / T;
    Rows& out = rows_[t];
    std::vector<int>& row = out.row;
    // The candidates of row i: the discs of the 3 x 3 cells around it with a larger index, of
    // another body, within reach. Tested without a branch (the outcome is what a predictor
    // cannot learn) into a buffer whose count moves on only for a pair that is kept.
    int m = 0;
    for (std::size_t i = i_lo; i < i_hi; ++i) {
      const int cx = cell_of_[i] % nx, cy = cell_of_[i] / nx;
      const double xi = x[i], yi = y[i], ri = r[i];
      const int bi = body[i], ii = static_cast<int>(i);
      m = 0;
      const double hi = per_disc ? half_skin[i] : 0.0;
      auto scan = [&](int k, int k1) __attribute__((always_inline)) {
        if (static_cast<std::size_t>(m + (k1 - k)) > row.size()) row.resize(static_cast<std::size_t>(2 * (m + (k1 - k))));
        int* out = row.data();
        if (per_disc) {
          for (; k < k1; ++k) {
            const Binned& d = binned_[static_cast<std::size_t>(k)];
            double dx = d.x - xi;
            const double dy = d.y - yi;
            if (p.periodic_x) dx -= L * std::nearbyint(dx / L);
            const double rc = ri + d.r + reach + hi + binned_h_[static_cast<std::size_t>(k)];
            out[m] = d.index;
            m += static_cast<int>((d.index > ii) & (d.body != bi) & (dx * dx + dy * dy < rc * rc));
          }
          return;
        }
        for (; k < k1; ++k) {
          const Binned& d = binned_[static_cast<std::size_t>(k)];
          double dx = d.x - xi;
          const double dy = d.y - yi;
          if (p.periodic_x) dx -= L * std::nearbyint(dx / L);
          const double rc = ri + d.r + reach;
          out[m] = d.index;
          m += static_cast<int>((d.index > ii) & (d.body != bi) & (dx * dx + dy * dy < rc * rc));
        }
      };
      // Cells c0..c1 (consecutive): a row keeps only larger indices, and a cell holds its discs
      // in index order, so leading cells whose last index is <= i are skipped without a test of
      // their discs. In the spatial order the engine keeps bodies in, that is about a third of
      // the stencil's discs; the row is the same set either way (the skipped ones fail the
      // test). Without a branch: whether a cell is skipped is what a predictor cannot learn.
      auto scan_cells = [&](std::size_t c0, std::size_t c1) __attribute__((always_inline)) {
        int k = cell_start_[c0];
        bool skip = true;
        for (std::size_t c = c0; c <= c1; ++c) {
          skip = skip & (cell_last_[c] <= ii);
          k = skip ? cell_start_[c + 1] : k;
        }
        scan(k, cell_start_[c1 + 1]);
      };
      for (int dyc = -1; dyc <= 1; ++dyc) {
        const int yy = cy + dyc;
        if (yy < 0 || yy >= ny) continue;
        const std::size_t c_row = static_cast<std::size_t>(yy) * nx;
        if (!p.periodic_x || (cx >= 1 && cx + 1 < nx)) {
          // the (up to) three cells of this row of the stencil lie together in cell order
          const std::size_t c0 = c_row + static_cast<std::size_t>(std::max(cx - 1, 0));
          const std::size_t c1 = c_row + static_cast<std::size_t>(std::min(cx + 1, nx - 1));
          scan_cells(c0, c1);
        } else {
          for (int dxc = -1; dxc <= 1; ++dxc) {
            const int xx = ((cx + dxc) % nx + nx) % nx;  // tiny boxes (nx < 3) give duplicates, removed below
            const std::size_t c = c_row + static_cast<std::size_t>(xx);
            scan_cells(c, c);
          }
        }
      }
      if (const int w0 = wide_start_[i], w1 = wide_start_[i + 1]; w1 > w0) {
        if (static_cast<std::size_t>(m + (w1 - w0)) > row.size()) row.resize(static_cast<std::size_t>(2 * (m + (w1 - w0))));
        for (int q = w0; q < w1; ++q) row[static_cast<std::size_t>(m++)] = wide_nbr_[static_cast<std::size_t>(q)];
      }
      std::sort(row.begin(), row.begin() + m);
      m = static_cast<int>(std::unique(row.begin(), row.begin() + m) - row.begin());
      for (int q = 0; q < m; ++q) {
        const int j = row[static_cast<std::size_t>(q)];
        out.nbr.push_back(j);
        double eta = 0.0;
        std::uint8_t sl = 0;
        // Carry history over: find the pair in the old list (row min(oi,oj), sorted).
        int oi = static_cast<int>(i), oj = j;
        if (has_old) { oi = old_of_new[i]; oj = old_of_new[j]; }
        if (oi >= 0 && oj >= 0 && has_prev) {
          const int a = std::min(oi, oj), b = std::max(oi, oj);
          if (static_cast<std::size_t>(a) + 1 < row_start_.size()) {
            auto first = nbr_.begin() + row_start_[a], last = nbr_.begin() + row_start_[a + 1];
            auto it = std::lower_bound(first, last, b);
            if (it != last && *it == b) {
              const auto k = static_cast<std::size_t>(it - nbr_.begin());
              eta = eta_[k];
              sl = slide_[k];
            }
          }
        }
        out.eta.push_back(eta);
        out.slide.push_back(sl);
      }
      new_start_[i + 1] = m;  // count now, offset below
    }
  } catch (...) {
    failure[static_cast<std::size_t>(omp_get_thread_num())] = std::current_exception();
  }
  // Joined in the region: the arrays sized by one thread, then each thread writes its own rows'
  // offsets, entries and reference positions (one thread doing it after the region was time
  // the others waited, at every list build). Nothing is written unless every part succeeded.
#pragma omp barrier
#pragma omp single
  {
    try {
      join_ok_ = true;
      for (const auto& e : failure) join_ok_ = join_ok_ && !e;
      if (join_ok_) {
        const int T = omp_get_num_threads();
        part_off_.assign(static_cast<std::size_t>(T) + 1, 0);
        for (int t = 0; t < T; ++t) part_off_[t + 1] = part_off_[t] + static_cast<int>(rows_[t].nbr.size());
        const auto total = static_cast<std::size_t>(part_off_[T]);
        new_nbr_.resize(total);
        new_eta_.resize(total);
        new_slide_.resize(total);
        x0_.resize(n);
        y0_.resize(n);
        h_.resize(half_skin.size());
        inv_h2_.resize(half_skin.size());
      }
    } catch (...) {
      join_ok_ = false;
      failure[0] = std::current_exception();
    }
  }  // (implicit barrier)
  if (join_ok_) {
    const int T = omp_get_num_threads(), t = omp_get_thread_num();
    const std::size_t i_lo = n * t / T, i_hi = n * (t + 1) / T;
    const Rows& part = rows_[t];
    const int off = part_off_[t];
    std::copy(part.nbr.begin(), part.nbr.end(), new_nbr_.begin() + off);
    std::copy(part.eta.begin(), part.eta.end(), new_eta_.begin() + off);
    std::copy(part.slide.begin(), part.slide.end(), new_slide_.begin() + off);
    for (std::size_t i = i_lo, at = static_cast<std::size_t>(off); i < i_hi; ++i) {
      at += static_cast<std::size_t>(new_start_[i + 1]);
      new_start_[i + 1] = static_cast<int>(at);
    }
    std::copy(x.begin() + i_lo, x.begin() + i_hi, x0_.begin() + i_lo);
    std::copy(y.begin() + i_lo, y.begin() + i_hi, y0_.begin() + i_lo);
    if (per_disc)
      for (std::size_t i = i_lo; i < i_hi; ++i) {
        h_[i] = half_skin[i];
        inv_h2_[i] = 1.0 / (h_[i] * h_[i]);  // (h = 0: inf, rebuilt at every check)
      }
  }
  }
  for (const auto& e : failure)
    if (e) std::rethrow_exception(e);
  row_start_.swap(new_start_);
  nbr_.swap(new_nbr_);
  eta_.swap(new_eta_);
  slide_.swap(new_slide_);
}

}  // namespace nipdem::geometry
