#include "nipdem/experiments/nip_forces.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "nipdem/core/error.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/dipole.hpp"

namespace nipdem::experiments {

std::shared_ptr<const magnet::MagnetField> make_magnet_field(const MagnetConfig& c) {
  if (c.field == "none") return nullptr;
  if (c.field == "knife") return std::make_shared<magnet::BlockAssembly>(magnet::make_knife());
  if (c.field == "color_pole") return std::make_shared<magnet::BlockAssembly>(magnet::make_color_pole());
  if (c.field == "map") return std::make_shared<io::FieldMap>(io::FieldMap::from_file(c.map_file));
  throw_input("magnet", "magnet.field", c.field, "unknown field source", "knife, color_pole, map, none");
}

MagnetForce::MagnetForce(std::shared_ptr<const magnet::MagnetField> field, MagnetConfig cfg)
    : field_(std::move(field)), cfg_(std::move(cfg)) {
  // A map is already a table; anything else (the analytic knife/pole) is tabulated in tiles.
  tabulate_ = field_ && dynamic_cast<const io::FieldMap*>(field_.get()) == nullptr;
  if (tabulate_) tiles_.resize(static_cast<std::size_t>(kTilesX) * kTilesY);
}

// Field at p: from the tile containing p (built on first use), or from the source itself
// outside the tiled region (|x| > 12.8 mm or |y| > 6.4 mm) or for a field map.
magnet::Sample MagnetForce::field_at(Vec2 p) {
  const magnet::MagnetField* t = tile_for(p);
  return t ? t->at(p) : field_->at(p);
}

const magnet::MagnetField* MagnetForce::tile_for(Vec2 p) {
  if (!tabulate_) return nullptr;
  constexpr double T = kTileH * kTileCells;
  const double fx = std::floor(p.x / T) + kTilesX / 2, fy = std::floor(p.y / T) + kTilesY / 2;
  if (!(fx >= 0.0 && fx < kTilesX && fy >= 0.0 && fy < kTilesY)) return nullptr;  // also NaN
  const int tx = static_cast<int>(fx), ty = static_cast<int>(fy);
  auto& tile = tiles_[static_cast<std::size_t>(ty) * kTilesX + tx];
  if (!tile) {
    // Nodes at integer multiples of h, two beyond the tile on each side so every node used
    // inside the tile has central 4th-order derivatives: the tile's values depend only on
    // (tx, ty), not on which tiles exist.
    const int n = kTileCells + 1 + 4;
    const long gx0 = static_cast<long>(tx - kTilesX / 2) * kTileCells - 2;
    const long gy0 = static_cast<long>(ty - kTilesY / 2) * kTileCells - 2;
    std::vector<double> bx, by;
    bx.reserve(static_cast<std::size_t>(n) * n);
    by.reserve(static_cast<std::size_t>(n) * n);
    bool finite = true;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const magnet::Sample s = field_->at({static_cast<double>(gx0 + i) * kTileH, static_cast<double>(gy0 + j) * kTileH});
        bx.push_back(s.B.x);
        by.push_back(s.B.y);
        finite = finite && std::isfinite(s.B.x) && std::isfinite(s.B.y);
      }
    // A node on a magnet corner (log singularity, inside the roller): keep the exact source there.
    if (!finite) tile = field_;
    else tile = std::make_shared<io::FieldMap>(static_cast<double>(gx0) * kTileH, static_cast<double>(gy0) * kTileH, kTileH,
                                          kTileH, n, n, std::move(bx), std::move(by), "tile of " + field_->describe());
  }
  return tile.get();
}

void MagnetForce::add(const BodyStore& b, const DiscStore&, double, std::span<double> fx, std::span<double> fy,
                      std::span<double>) {
  const std::size_t n = b.x.size();
  moment_.resize(n);
  const int nt = std::max(1, cfg_.threads);
  if (nt == 1) {
    for (std::size_t i = 0; i < n; ++i) {
      const double R = 0.5 * b.size[i];
      const magnet::Sample s = field_at({b.x[i], b.y[i]});
      moment_[i] = magnet::induced_moment(cfg_.toner, R, s.B);  // eq. 4.5.1
      const Vec2 f = magnet::dipole_force(moment_[i], s);         // eq. 2.4.34: (m . grad) B
      fx[i] += f.x;
      fy[i] += f.y;
    }
  } else {
    // Tiles are built serially first; the parallel loop only reads them. Each particle is
    // independent, so the result does not depend on the thread count.
    for (std::size_t i = 0; i < n; ++i) tile_for({b.x[i], b.y[i]});
#pragma omp parallel for schedule(static) num_threads(nt)
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 p{b.x[i], b.y[i]};
      const magnet::MagnetField* t = tile_for(p);  // exists now: no write
      const magnet::Sample s = t ? t->at(p) : field_->at(p);
      moment_[i] = magnet::induced_moment(cfg_.toner, 0.5 * b.size[i], s.B);  // eq. 4.5.1
      const Vec2 f = magnet::dipole_force(moment_[i], s);                      // eq. 2.4.34
      fx[i] += f.x;
      fy[i] += f.y;
    }
  }
  if (!cfg_.dipole_dipole) return;
  // Re-evaluate the pair forces every dipole_interval calls, or when bodies changed.
  bool same = dipole_ids_.size() == n;
  if (same) for (std::size_t i = 0; i < n && same; ++i) same = dipole_ids_[i] == b.id[i];
  if (!same || calls_ % cfg_.dipole_interval == 0) {
    dipole_pass(b);
    dipole_ids_.assign(b.id.begin(), b.id.end());
  }
  ++calls_;
  for (std::size_t i = 0; i < n; ++i) { fx[i] += dfx_[i]; fy[i] += dfy_[i]; }
}

void MagnetForce::dipole_pass(const BodyStore& b) {
  const std::size_t n = b.x.size();
  dfx_.assign(n, 0.0);
  dfy_.assign(n, 0.0);
  if (n < 2) return;
  const double rc = cfg_.dipole_cutoff, rc2 = rc * rc;
  double xmin = b.x[0], xmax = b.x[0], ymin = b.y[0], ymax = b.y[0];
  for (std::size_t i = 0; i < n; ++i) {
    xmin = std::min(xmin, b.x[i]); xmax = std::max(xmax, b.x[i]);
    ymin = std::min(ymin, b.y[i]); ymax = std::max(ymax, b.y[i]);
  }
  const int nx = std::max(1, static_cast<int>((xmax - xmin) / rc) + 1);
  const int ny = std::max(1, static_cast<int>((ymax - ymin) / rc) + 1);
  head_.assign(static_cast<std::size_t>(nx) * ny, -1);
  next_.assign(n, -1);
  auto cell = [&](std::size_t i) {
    return std::min(ny - 1, static_cast<int>((b.y[i] - ymin) / rc)) * nx + std::min(nx - 1, static_cast<int>((b.x[i] - xmin) / rc));
  };
  for (std::size_t ii = n; ii-- > 0;) {
    const int c = cell(ii);
    next_[ii] = head_[c];
    head_[c] = static_cast<int>(ii);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const int c = cell(i);
    const int cx = c % nx, cy = c / nx;
    for (int dy = -1; dy <= 1; ++dy) {
      if (cy + dy < 0 || cy + dy >= ny) continue;
      for (int dx = -1; dx <= 1; ++dx) {
        if (cx + dx < 0 || cx + dx >= nx) continue;
        for (int j = head_[(cy + dy) * nx + cx + dx]; j >= 0; j = next_[j]) {
          if (j <= static_cast<int>(i)) continue;
          const Vec2 r{b.x[i] - b.x[j], b.y[i] - b.y[j]};
          if (norm2(r) >= rc2) continue;
          const Vec2 f = dipole::dipole_force(moment_[i], moment_[j], r);  // eqs. 2.4.38-2.4.39, on i
          dfx_[i] += f.x; dfy_[i] += f.y;
          dfx_[j] -= f.x; dfy_[j] -= f.y;
        }
      }
    }
  }
}

}  // namespace nipdem::experiments
