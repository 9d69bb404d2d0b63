#include "nipdem/nip/nip_forces.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>

#include "nipdem/core/binary_io.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/dipole.hpp"
#include "nipdem/models/electric_screening.hpp"

namespace nipdem::nip {

std::shared_ptr<const magnet::MagnetField> make_magnet_field(const MagnetConfig& c) {
  if (c.field == "none") return nullptr;
  if (c.field == "knife") return std::make_shared<magnet::BlockAssembly>(magnet::make_knife());
  if (c.field == "color_pole") return std::make_shared<magnet::BlockAssembly>(magnet::make_color_pole());
  if (c.field == "map") return std::make_shared<io::FieldMap>(io::FieldMap::from_file(c.map_file));
  throw_input("magnet", "magnet.field", c.field, "unknown field source", "knife, color_pole, map, none");
}

MagnetForce::MagnetForce(std::shared_ptr<const magnet::MagnetField> field, MagnetConfig cfg)
    : field_(std::move(field)),
      cfg_(std::move(cfg)),
      pairs_(dipole::PairSumParams{cfg_.dipole_cutoff, cfg_.dipole_skin, std::max(1, cfg_.threads)}) {
  // A map is already a table; anything else (the analytic knife/pole) is tabulated in tiles.
  tabulate_ = field_ && dynamic_cast<const io::FieldMap*>(field_.get()) == nullptr;
  if (tabulate_) tiles_.resize(static_cast<std::size_t>(kTilesX) * kTilesY);
}

// Field at p: from the tile containing p (built on first use), or from the source itself
// outside the tiled region (|x| > 12.8 mm or |y| > 6.4 mm) or for a field map.
magnet::Sample MagnetForce::field_at(Vec2 p) { return sample(tile_for(p), p); }

magnet::Sample MagnetForce::sample(const Tile* t, Vec2 p) const {
  if (!t || !t->map) return field_->at(p);
  if (!t->exact_cell.empty()) {
    // the cell of p (rounding at the tile's edge stays in the tile)
    const int i = std::clamp(static_cast<int>(std::floor((p.x - t->x0) / kTileH)), 0, kTileCells - 1);
    const int j = std::clamp(static_cast<int>(std::floor((p.y - t->y0) / kTileH)), 0, kTileCells - 1);
    if (t->exact_cell[static_cast<std::size_t>(j) * kTileCells + i]) return field_->at(p);
  }
  return t->map->at(p);
}

int MagnetForce::tile_index(Vec2 p) const {
  if (!tabulate_) return -1;
  constexpr double T = kTileH * kTileCells;
  const double fx = std::floor(p.x / T) + kTilesX / 2, fy = std::floor(p.y / T) + kTilesY / 2;
  if (!(fx >= 0.0 && fx < kTilesX && fy >= 0.0 && fy < kTilesY)) return -1;  // also NaN
  return static_cast<int>(fy) * kTilesX + static_cast<int>(fx);
}

const MagnetForce::Tile* MagnetForce::tile_for(Vec2 p) {
  const int k = tile_index(p);
  if (k < 0) return nullptr;
  const int tx = k % kTilesX, ty = k / kTilesX;
  auto& tile = tiles_[static_cast<std::size_t>(k)];
  if (!tile) {
    // Nodes at integer multiples of h, two beyond the tile on each side so every node used
    // inside the tile has central 4th-order derivatives: the tile's values depend only on
    // (tx, ty), not on which tiles exist.
    const int n = kTileCells + 1 + 4;
    const long gx0 = static_cast<long>(tx - kTilesX / 2) * kTileCells - 2;
    const long gy0 = static_cast<long>(ty - kTilesY / 2) * kTileCells - 2;
    auto t = std::make_unique<Tile>();
    t->x0 = static_cast<double>(gx0 + 2) * kTileH;
    t->y0 = static_cast<double>(gy0 + 2) * kTileH;
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
    if (finite) {
      t->map = std::make_shared<io::FieldMap>(static_cast<double>(gx0) * kTileH, static_cast<double>(gy0) * kTileH, kTileH,
                                              kTileH, n, n, std::move(bx), std::move(by), "tile of " + field_->describe());
      // Cells whose stencil (nodes i-2 .. i+3) meets a magnet face: the field jumps there and the
      // interpolant would smear the jump over the stencil (up to 400x wrong, issue 18).
      if (!field_->smooth_in({t->x0 - 2 * kTileH, t->y0 - 2 * kTileH}, {t->x0 + (kTileCells + 2) * kTileH, t->y0 + (kTileCells + 2) * kTileH})) {
        t->exact_cell.assign(static_cast<std::size_t>(kTileCells) * kTileCells, 0);
        for (int j = 0; j < kTileCells; ++j)
          for (int i = 0; i < kTileCells; ++i) {
            const Vec2 lo{t->x0 + (i - 2) * kTileH, t->y0 + (j - 2) * kTileH}, hi{t->x0 + (i + 3) * kTileH, t->y0 + (j + 3) * kTileH};
            t->exact_cell[static_cast<std::size_t>(j) * kTileCells + i] = field_->smooth_in(lo, hi) ? 0 : 1;
          }
      }
    }
    tile = std::move(t);
  }
  return tile.get();
}

void MagnetForce::add(const BodyStore& b, const DiscStore&, double, std::span<double> fx, std::span<double> fy,
                      std::span<double>) {
  const std::size_t n = b.x.size();
  // Held forces belong to bodies by id; any change of the body set forces a fresh evaluation.
  // (The engine's body-set number, unchanged since the last call, saves comparing the ids.)
  const std::uint64_t version = body_set_version();
  const bool same = ids_.size() == n && ((version != 0 && version == seen_version_) ||
                                         std::equal(ids_.begin(), ids_.end(), b.id.begin()));
  seen_version_ = 0;  // (until the held forces belong to these bodies: a failed pass compares again)
  if (!same || calls_ % cfg_.field_interval == 0) field_pass(b);
  if (cfg_.dipole_dipole && (!same || calls_ % cfg_.dipole_interval == 0)) dipole_pass(b, same);
  if (!same) ids_.assign(b.id.begin(), b.id.end());
  seen_version_ = version;
  ++calls_;
  if (hand_held()) return;  // the engine adds the held forces (held()) in its own pass
  // The held forces, added per body (the same sums for any thread count), on the engine's
  // threads when there are enough bodies to pay for the region: a serial pass here is time
  // the engine's other threads wait.
  const bool dd = cfg_.dipole_dipole;
  const int nt = std::max(1, cfg_.threads);
  const int run = running_threads() > 0 ? std::min(running_threads(), nt) : nt;
  const double* hx = ffx_.data(); const double* hy = ffy_.data();
  const double* gx = dd ? dfx_.data() : nullptr; const double* gy = dd ? dfy_.data() : nullptr;
  double* ox = fx.data(); double* oy = fy.data();
#pragma omp parallel for schedule(static) num_threads(run) if (run > 1 && n >= 2048)
  for (std::size_t i = 0; i < n; ++i) {
    ox[i] += hx[i]; oy[i] += hy[i];
    if (dd) { ox[i] += gx[i]; oy[i] += gy[i]; }
  }
}

engine::BodyForce::Held MagnetForce::held() const {
  if (!hand_held()) return {};
  Held h;
  h.fx[0] = ffx_.data(); h.fy[0] = ffy_.data();
  h.terms = 1;
  if (cfg_.dipole_dipole) { h.fx[1] = dfx_.data(); h.fy[1] = dfy_.data(); h.terms = 2; }
  return h;
}

void MagnetForce::field_pass(const BodyStore& b) {
  const std::size_t n = b.x.size();
  // (every value is written below, by the thread that adds it to the bodies at each step: not
  // cleared here first by one thread, which would put every line in that thread's cache)
  moment_.resize(n);
  ffx_.resize(n);
  ffy_.resize(n);
  const int nt = std::max(1, cfg_.threads);
  if (nt == 1) {
    for (std::size_t i = 0; i < n; ++i) {
      const magnet::Sample s = field_at({b.x[i], b.y[i]});
      moment_[i] = magnet::induced_moment(cfg_.toner, 0.5 * b.size[i], s.B);  // eq. 4.5.1
      const Vec2 f = magnet::dipole_force(moment_[i], s);                      // eq. 2.4.34: (m . grad) B
      ffx_[i] = f.x;
      ffy_[i] = f.y;
    }
    return;
  }
  // The parallel loop only reads the tiles: a particle whose tile is not built yet is marked
  // and evaluated after the loop, on one thread, which builds its tile (a tile is built once;
  // a pass over every particle first to build them was time the other threads waited). Each
  // particle is independent and a tile's values do not depend on when it is built, so the
  // result does not depend on the thread count.
  // No exception may leave an OpenMP region (it would end the program): a failure (e.g. a field
  // map asked outside its range, InputError) is caught per particle and the one of the lowest
  // index rethrown after the loop, so any thread count reports the same error as one thread.
  std::size_t first_bad = n;
  std::exception_ptr error;
  pending_.resize(n);
  int any_pending = 0;
  auto evaluate = [&](std::size_t i, const Tile* t) {
    const Vec2 p{b.x[i], b.y[i]};
    const magnet::Sample s = sample(t, p);
    moment_[i] = magnet::induced_moment(cfg_.toner, 0.5 * b.size[i], s.B);  // eq. 4.5.1
    const Vec2 f = magnet::dipole_force(moment_[i], s);                      // eq. 2.4.34
    ffx_[i] = f.x;
    ffy_[i] = f.y;
  };
  const int run = running_threads() > 0 ? std::min(running_threads(), nt) : nt;  // the engine's choice (same results)
#pragma omp parallel for schedule(static) num_threads(run) reduction(| : any_pending)
  for (std::size_t i = 0; i < n; ++i) {
    const int k = tile_index({b.x[i], b.y[i]});
    const bool missing = k >= 0 && !tiles_[static_cast<std::size_t>(k)];
    pending_[i] = missing ? 1 : 0;
    any_pending |= missing ? 1 : 0;
    if (missing) continue;
    try {
      evaluate(i, k >= 0 ? tiles_[static_cast<std::size_t>(k)].get() : nullptr);
    } catch (...) {
#pragma omp critical(nipdem_magnet_field_pass_error)
      if (i < first_bad) { first_bad = i; error = std::current_exception(); }
    }
  }
  if (any_pending)
    for (std::size_t i = 0; i < n && i < first_bad; ++i) {
      if (!pending_[i]) continue;
      try {
        evaluate(i, tile_for({b.x[i], b.y[i]}));
      } catch (...) {
        first_bad = i;
        error = std::current_exception();
      }
    }
  if (error) std::rethrow_exception(error);
}

// Dipole-dipole forces (eqs. 2.4.38-2.4.39) between the induced moments within the cut-off:
// dipole::PairSum keeps a Verlet pair list between passes (rebuilt when the body set changed
// or the two largest displacements add up to the skin) and sums each pair once. The result equals the plain
// cut-off sum (tested against an O(N^2) sum) and does not depend on when the list was built.
void MagnetForce::dipole_pass(const BodyStore& b, bool same_set) {
  pairs_.compute(b.x, b.y, moment_, same_set, dfx_, dfy_, running_threads());
}

ElectricForce::ElectricForce(const engine::Simulation* sim, ElectricConfig cfg) : sim_(sim), cfg_(std::move(cfg)) {
  cfg_.rc.validate();
  cfg_.force.validate();
}

using binary::get;
using binary::get_vec;
using binary::put;
using binary::put_vec;

void MagnetForce::save(std::ostream& o) const {
  put(o, calls_); put_vec(o, ids_); put_vec(o, ffx_); put_vec(o, ffy_); put_vec(o, dfx_); put_vec(o, dfy_); put_vec(o, moment_);
}
namespace {
[[noreturn]] void bad_state(const char* provider, const std::string& what) {
  throw InputError(fmt::format("{} force state: {}", provider, what));
}
template <class T> void require_len(const char* provider, const std::vector<T>& v, std::size_t n, const char* name) {
  if (v.size() != n) bad_state(provider, fmt::format("{} has {} entries, expected {}", name, v.size(), n));
}
void require_finite_all(const char* provider, const std::vector<double>& v, const char* name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) bad_state(provider, fmt::format("{}[{}] = {} is not finite", name, i, v[i]));
}
}  // namespace

// Everything read is checked before use (docs/reliability.md): the held forces are indexed by
// body in add() whenever the ids match, so their sizes must match the ids they belong to.
void MagnetForce::load(std::istream& in) {
  seen_version_ = 0;  // (the ids are compared at the next call)
  get(in, calls_); get_vec(in, ids_, "magnet ids"); get_vec(in, ffx_, "magnet fx"); get_vec(in, ffy_, "magnet fy");
  get_vec(in, dfx_, "dipole fx"); get_vec(in, dfy_, "dipole fy"); get_vec(in, moment_, "magnet moments");
  const char* who = "magnetic";
  if (calls_ < 0) bad_state(who, fmt::format("call count {} < 0", calls_));
  const std::size_t n = ids_.size();
  require_len(who, ffx_, n, "field force x");
  require_len(who, ffy_, n, "field force y");
  require_len(who, moment_, n, "moments");
  if (cfg_.dipole_dipole || !dfx_.empty() || !dfy_.empty()) {
    require_len(who, dfx_, n, "dipole force x");
    require_len(who, dfy_, n, "dipole force y");
  }
  for (auto* v : {&ffx_, &ffy_, &dfx_, &dfy_}) require_finite_all(who, *v, "a held force");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(moment_[i].x) || !std::isfinite(moment_[i].y)) bad_state(who, fmt::format("moment[{}] is not finite", i));
  }
  if (const long k = first_repeated_id(ids_); k >= 0) bad_state(who, fmt::format("body id {} at {} repeats an earlier one", ids_[k], k));
  pairs_.invalidate();  // the list is a cache: rebuilt at the next pass, same forces (see PairSum)
}

void ElectricForce::save(std::ostream& o) const {
  put(o, calls_); put(o, t_last_); put(o, v_drum_); put(o, n_printable_);
  put_vec(o, u_); put_vec(o, ids_); put_vec(o, coupling_); put_vec(o, printable_); put_vec(o, near_disc_);
  put_vec(o, gap_); put_vec(o, r_path_);
}
void ElectricForce::load(std::istream& in) {
  get(in, calls_); get(in, t_last_); get(in, v_drum_); get(in, n_printable_);
  seen_version_ = 0;  // (the ids are compared at the next call)
  get_vec(in, u_, "voltages"); get_vec(in, ids_, "electric ids"); get_vec(in, coupling_, "couplings");
  get_vec(in, printable_, "printable flags"); get_vec(in, near_disc_, "nearest discs"); get_vec(in, gap_, "gaps");
  get_vec(in, r_path_, "path resistances");
  const char* who = "electric";
  if (calls_ < 0) bad_state(who, fmt::format("call count {} < 0", calls_));
  if (!std::isfinite(t_last_) || !std::isfinite(v_drum_)) bad_state(who, "last time or drum voltage not finite");
  require_len(who, u_, ids_.size(), "voltages");
  require_finite_all(who, u_, "voltage");
  if (const long k = first_repeated_id(ids_); k >= 0) bad_state(who, fmt::format("body id {} at {} repeats an earlier one", ids_[k], k));
  // The per-body refresh data (all sized at the last refresh) are used without a refresh only if
  // they match the engine's body count; their disc indices must then be the engine's discs.
  const std::size_t nr = coupling_.size();
  require_len(who, printable_, nr, "printable flags");
  require_len(who, near_disc_, nr, "nearest discs");
  require_len(who, gap_, nr, "gaps");
  require_len(who, r_path_, nr, "path resistances");
  const auto& b = sim_->bodies();
  const auto& d = sim_->discs();
  int printable = 0;
  for (std::size_t i = 0; i < nr; ++i) {
    const int c = static_cast<int>(coupling_[i]);
    if (c < 0 || c > 2) bad_state(who, fmt::format("coupling[{}] = {} is not none/capacitor/contact", i, c));
    if (printable_[i] != 0 && printable_[i] != 1) bad_state(who, fmt::format("printable[{}] is not 0 or 1", i));
    if (printable_[i] && coupling_[i] == charge::DrumCoupling::none) bad_state(who, fmt::format("body {} printable without coupling", i));
    printable += printable_[i];
    if (std::isnan(gap_[i]) || std::isnan(r_path_[i]) || !(r_path_[i] > 0.0))
      bad_state(who, fmt::format("gap or path resistance of body {} is not a number (> 0 for the resistance)", i));
    const int k = near_disc_[i];
    const bool used = nr == b.x.size() && coupling_[i] != charge::DrumCoupling::none;
    if (k < -1 || (used && (k < 0 || static_cast<std::size_t>(k) >= d.x.size() || d.body[k] != static_cast<int>(i))))
      bad_state(who, fmt::format("nearest disc {} of body {} is not one of its discs", k, i));
  }
  if (printable != n_printable_) bad_state(who, fmt::format("{} printable bodies, the count says {}", printable, n_printable_));
  paths_.resize(0);  // rebuilt from the contacts at the next refresh (exact, same distances)
}

void ElectricForce::refresh(const BodyStore& b, const DiscStore& d) {
  const std::size_t nb = b.x.size();
  const auto& walls = sim_->walls();
  const auto& drum = walls[cfg_.drum_wall];
  const auto& roller = walls[cfg_.roller_wall];
  // Contacts between bodies (from disc overlaps in the neighbour list) and with the roller.
  const auto& nl = sim_->neighbor_list();
  // (each body pair once, in ascending order: sorted and made unique)
  auto& pairs = pair_scratch_;
  pairs.clear();
  for (std::size_t i = 0; i + 1 < nl.row_start_.size() && i < d.x.size(); ++i) {
    for (int e = nl.row_start_[i]; e < nl.row_start_[i + 1]; ++e) {
      const int j = nl.nbr_[e];
      const double dx = d.x[i] - d.x[j], dy = d.y[i] - d.y[j], rs = d.r[i] + d.r[j];
      if (dx * dx + dy * dy < rs * rs) {
        const int a = d.body[i], c = d.body[j];
        pairs.push_back({std::min(a, c), std::max(a, c)});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<conduction::Contact> contacts;
  contacts.reserve(pairs.size());
  for (auto& [a, c] : pairs) contacts.push_back({a, c, cfg_.rc.R_tt_ohm});
  std::vector<conduction::RollerContact> roll;
  std::vector<geometry::WallHit> hits;
  std::vector<char> on_roller(nb, 0);
  near_disc_.assign(nb, -1);
  gap_.assign(nb, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < d.x.size(); ++k) {
    const int bi = d.body[k];
    hits.clear();
    roller.query({d.x[k], d.y[k]}, d.r[k], 0.0, hits);
    for (auto& h : hits) if (h.gap < 0.0) on_roller[bi] = 1;
    const double g = norm(Vec2{d.x[k], d.y[k]} - drum.centre) - drum.radius - d.r[k];
    if (g < gap_[bi]) { gap_[bi] = g; near_disc_[bi] = static_cast<int>(k); }
  }
  for (std::size_t i = 0; i < nb; ++i) if (on_roller[i]) roll.push_back({static_cast<int>(i), cfg_.rc.R_ti_ohm});
  if (paths_.size() != static_cast<int>(nb)) paths_.resize(static_cast<int>(nb));
  paths_.update(contacts, roll);
  r_path_.assign(nb, charge::kNoPath);
  for (std::size_t i = 0; i < nb; ++i) r_path_[i] = paths_.path_resistance(static_cast<int>(i));
  // Who feels the force: within range of the drum and not screened (§2.5.4).
  // The layer's discs in order of x: a body's candidates for screening are those within
  // `window` of it along x (see below), found by bisection instead of a pass over the layer.
  std::vector<int>& layer = layer_scratch_;
  layer.clear();
  const double reach = cfg_.rc.range_m + 2.0 * cfg_.rc.range_m;
  double r_max = 0.0;
  for (std::size_t k = 0; k < d.x.size(); ++k) {
    if (norm(Vec2{d.x[k], d.y[k]} - drum.centre) - drum.radius - d.r[k] < reach) {
      layer.push_back(static_cast<int>(k));
      r_max = std::max(r_max, d.r[k]);
    }
  }
  std::sort(layer.begin(), layer.end(), [&](int a, int c) { return d.x[a] < d.x[c] || (d.x[a] == d.x[c] && a < c); });
  std::vector<double>& layer_x = layer_x_scratch_;
  layer_x.resize(layer.size());
  for (std::size_t q = 0; q < layer.size(); ++q) layer_x[q] = d.x[layer[q]];
  // A disc that blocks a body's corridor is centred within screening_reach of the body's disc
  // (every disc tested is of the layer, radius <= r_max): one farther along x cannot block (the
  // window is that bound with 1e-6 to spare, so rounding never leaves a blocking disc out).
  // Only whether some disc blocks is used, not which: the screened flags are those of testing
  // every disc of the layer.
  electric::ScreeningParams sp;
  sp.range_m = cfg_.rc.range_m;
  sp.corridor_fraction = cfg_.corridor_fraction;
  const double window = electric::screening_reach(sp, r_max) * (1.0 + 1e-6);
  const auto surface = electric::DrumSurface::circle(drum.centre, drum.radius);
  coupling_.assign(nb, charge::DrumCoupling::none);
  printable_.assign(nb, 0);
  n_printable_ = 0;
  for (std::size_t i = 0; i < nb; ++i) {
    if (!(gap_[i] < cfg_.rc.range_m)) continue;
    coupling_[i] = gap_[i] < 0.0 ? charge::DrumCoupling::contact : charge::DrumCoupling::capacitor;
    const int k = near_disc_[i];
    // screening by discs of other bodies only (a particle's own members never screen it)
    bool screened = false;
    const electric::Disc self{{d.x[k], d.y[k]}, d.r[k]};
    std::vector<electric::Disc>& others = others_scratch_;
    others.clear();
    const auto lo = std::lower_bound(layer_x.begin(), layer_x.end(), d.x[k] - window);
    for (auto q = static_cast<std::size_t>(lo - layer_x.begin()); q < layer.size() && layer_x[q] <= d.x[k] + window; ++q) {
      const int c = layer[q];
      if (d.body[c] != static_cast<int>(i)) others.push_back({{d.x[c], d.y[c]}, d.r[c]});
    }
    const auto res = electric::screening(self, surface, others, sp);
    screened = res.screened;
    if (!screened) { printable_[i] = 1; ++n_printable_; }
  }
}

void ElectricForce::add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
                        std::span<double> torque) {
  const std::size_t nb = b.x.size();
  // Keep the charges with their bodies when bodies were added or removed.
  // (The engine's body-set number, unchanged since the last call, saves comparing the ids.)
  const std::uint64_t version = body_set_version();
  bool same = ids_.size() == nb;
  if (same && !(version != 0 && version == seen_version_))
    for (std::size_t i = 0; i < nb && same; ++i) same = ids_[i] == b.id[i];
  seen_version_ = version;
  if (!same) {
    std::unordered_map<std::int64_t, double> old;
    for (std::size_t i = 0; i < ids_.size() && i < u_.size(); ++i) old[ids_[i]] = u_[i];
    u_.assign(nb, 0.0);
    for (std::size_t i = 0; i < nb; ++i) { auto it = old.find(b.id[i]); if (it != old.end()) u_[i] = it->second; }
    ids_.assign(b.id.begin(), b.id.end());
  }
  if (!same || calls_ % cfg_.path_interval == 0 || coupling_.size() != nb) refresh(b, d);
  ++calls_;
  v_drum_ = cfg_.pattern.voltage_at_time(t, cfg_.drum_speed);
  const double dt = t_last_ < 0.0 ? 0.0 : t - t_last_;
  t_last_ = t;
  const auto& drum = sim_->walls()[cfg_.drum_wall];
  for (std::size_t i = 0; i < nb; ++i) {
    if (coupling_[i] == charge::DrumCoupling::none) continue;
    if (dt > 0.0) u_[i] = charge::rc_update(u_[i], v_drum_, r_path_[i], coupling_[i], cfg_.rc, dt);
    if (!printable_[i] || u_[i] == 0.0) continue;
    const int k = near_disc_[i];
    const Vec2 p{d.x[k], d.y[k]};
    const double l = std::max(norm(p - drum.centre) - drum.radius - d.r[k], 0.0);
    const double dd = cfg_.dielectric_layer ? electric::effective_gap(l, cfg_.layer_thickness, cfg_.layer_permittivity) : std::max(l, 1e-12);
    const double R = 0.5 * b.size[i];
    const double f = cfg_.force.model == electric::ForceModel::exact ? table_.force(R, std::fabs(u_[i]), dd)
                                                                      : electric::force(cfg_.force, R, std::fabs(u_[i]), dd);
    const Vec2 n = (drum.centre - p) / norm(drum.centre - p);  // towards the drum axis
    fx[i] += f * n.x;
    fy[i] += f * n.y;
    torque[i] += d.wx[k] * f * n.y - d.wy[k] * f * n.x;  // applied at the nearest disc
  }
}

}  // namespace nipdem::nip

namespace nipdem::nip {

double ReachableRegion::y_low(double x) const {
  const double dx = x - roller_centre.x;
  return roller_centre.y + std::sqrt(std::max(0.0, roller_radius * roller_radius - dx * dx)) - pit_depth;
}
double ReachableRegion::y_high(double x) const {
  const double dx = x - drum_centre.x;
  return drum_centre.y - std::sqrt(std::max(0.0, drum_radius * drum_radius - dx * dx));
}

void check_field_region(const magnet::MagnetField& f, const ReachableRegion& r, const std::string& field_name) {
  const std::string window = fmt::format("[{:.4g}, {:.4g}] mm", 1e3 * r.x_min, 1e3 * r.x_max);
  const std::string keys = "geometry.window_x_min_m, geometry.window_x_max_m";
  // Magnet material where toner can go: the field there is the one inside a magnet, and a toner
  // cannot be there. Sampled along every block edge every 1 um (a part of a block above the
  // surface has edge points above it: straight up from any such point one meets the boundary).
  const double cx = r.roller_centre.x;
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (const auto& poly : f.material()) {
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
      const int n = std::max(1, static_cast<int>(std::ceil(norm(b - a) / 1e-6)));
      for (int k = 0; k <= n; ++k) {
        const Vec2 p = a + (static_cast<double>(k) / n) * (b - a);
        if (std::fabs(p.x - cx) >= r.roller_radius || p.y <= r.y_low(p.x)) continue;
        if (p.x >= cx) hi = std::min(hi, p.x);
        else lo = std::max(lo, p.x);
      }
    }
  }
  if (r.x_min <= lo || r.x_max >= hi)
    throw_input(field_name, keys, window,
                fmt::format("the magnet's material reaches above the imaging-roller surface less the pit depth ({:.3g} um) "
                            "at x {} mm, where toner can go: the field is not valid there (docs/magnetic.md, \"Field tables\")",
                            1e6 * r.pit_depth, r.x_max >= hi ? fmt::format(">= {:.4g}", 1e3 * hi) : fmt::format("<= {:.4g}", 1e3 * lo)),
                fmt::format("a window inside the valid region x in ({:.4g}, {:.4g}) mm", 1e3 * lo, 1e3 * hi));
  // A map must cover everything a toner centre can reach: the window from the roller surface
  // less the pits up to the drum.
  if (const auto* m = dynamic_cast<const io::FieldMap*>(&f)) {
    double ylo = std::numeric_limits<double>::infinity(), yhi = -ylo;
    const int n = 200;
    for (int k = 0; k <= n; ++k) {
      const double x = r.x_min + (r.x_max - r.x_min) * k / n;
      ylo = std::min(ylo, r.y_low(x));
      yhi = std::max(yhi, r.y_high(x));
    }
    if (m->x_min() > r.x_min || m->x_max() < r.x_max || m->y_min() > ylo || m->y_max() < yhi)
      throw_input(field_name, "magnet.map_file",
                  fmt::format("x [{:.4g}, {:.4g}] mm, y [{:.4g}, {:.4g}] um", 1e3 * m->x_min(), 1e3 * m->x_max(), 1e6 * m->y_min(), 1e6 * m->y_max()),
                  fmt::format("the map does not cover where toner can go (window {} from {}, y from the roller surface less the pits to the drum)", window, keys),
                  fmt::format("a map covering x [{:.4g}, {:.4g}] mm, y [{:.4g}, {:.4g}] um", 1e3 * r.x_min, 1e3 * r.x_max, 1e6 * ylo, 1e6 * yhi));
  }
}

}  // namespace nipdem::nip
