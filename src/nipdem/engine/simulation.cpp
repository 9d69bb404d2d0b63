#include "nipdem/engine/simulation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <istream>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>
#include <omp.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/engine/kernels.hpp"

namespace nipdem::engine {

using models::ContactParams;
using models::TangentialState;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

void Simulation::body_set_changed() {
  static std::atomic<std::uint64_t> versions{0};  // (unique across the process's engines)
  structure_changed_ = true;
  body_set_version_ = ++versions;
}

Simulation::Simulation(EngineParams params, std::vector<geometry::Wall> walls)
    : params_(std::move(params)), walls_(std::move(walls)) {
  if (params_.interactions.empty()) throw_input("engine", "interactions", "", "at least the disc-disc interaction is required");
  require_positive("engine", "dt_s", params_.dt);
  require_positive("engine", "skin_m", params_.skin);
  if (params_.threads < 1) throw_input("engine", "threads", std::to_string(params_.threads), "must be >= 1");
  if (!(params_.skin_speed_quantile >= 0.0 && params_.skin_speed_quantile < 1.0))
    throw_input("engine", "skin_speed_quantile", std::to_string(params_.skin_speed_quantile), "must be in [0, 1)");
  if (!(params_.inner_skin_fraction >= 0.0 && params_.inner_skin_fraction < 1.0))
    throw_input("engine", "inner_skin_fraction", std::to_string(params_.inner_skin_fraction), "must be in [0, 1)");
  if (params_.run_threads < 0 || params_.run_threads > params_.threads)
    throw_input("engine", "run_threads", std::to_string(params_.run_threads), "must be 0 (adaptive) or 1..threads");
  if (params_.periodic_x && !(params_.x_hi > params_.x_lo))
    throw_input("engine", "periodic_x", "", "x_hi must exceed x_lo for a periodic box");
  for (auto& w : walls_) {
    w.validate();
    w.prepare();
    if (w.interaction < 0 || w.interaction >= static_cast<int>(params_.interactions.size()))
      throw_input("wall '" + w.name + "'", "interaction", std::to_string(w.interaction), "no such interaction");
  }
  const auto& ad = params_.interactions[0].adhesion;
  pair_reach_ = ad.hamaker_J != 0.0 ? ad.cutoff_m : 0.0;
  nl_params_.skin = params_.skin;
  nl_params_.extra_range = pair_reach_;
  nl_params_.periodic_x = params_.periodic_x;
  nl_params_.x_lo = params_.x_lo;
  nl_params_.x_hi = params_.x_hi;
}

// Expects a spec add_body accepts (as many radii as offsets, at least one; positive density and
// radii): add_body checks that before calling it.
MassProperties mass_properties(const BodySpec& s) {
  const std::size_t n = s.offsets.size();
  MassProperties mp;
  std::vector<double> mk(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double r = s.radii[k];
    mk[k] = s.density * 4.0 / 3.0 * constants::pi * r * r * r;  // each member a solid sphere (§2.1)
    mp.mass += mk[k];
    mp.com += mk[k] * s.offsets[k];
  }
  mp.com /= mp.mass;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = s.radii[k];
    const double own = s.sphere_inertia ? 0.4 * mk[k] * r * r : 0.5 * mk[k] * r * r;
    mp.inertia += own + mk[k] * norm2(s.offsets[k] - mp.com);  // parallel-axis theorem
  }
  return mp;
}

int Simulation::add_body(const BodySpec& s) {
  const std::size_t n = s.offsets.size();
  if (n == 0 || s.radii.size() != n) throw_input("body", "discs", std::to_string(n), "need >= 1 disc with one radius each");
  require_positive("body", "density_kg_per_m3", s.density);
  for (const double r : s.radii) require_positive("body", "radius_m", r);
  const MassProperties mp = mass_properties(s);
  // Every array grows by one body (its discs), value-initialised (0); then the entries that are
  // not 0 are set.
  const std::size_t bi = b_.size_n(), d0 = d_.size_n();
  b_.for_each_array([&](const char*, auto& v, std::size_t per) { v.resize((bi + 1) * per); });
  d_.for_each_array([&](const char*, auto& v, std::size_t per) { v.resize((d0 + n) * per); });
  b_.x[bi] = s.position.x; b_.y[bi] = s.position.y;
  b_.vx[bi] = s.velocity.x; b_.vy[bi] = s.velocity.y;
  b_.theta[bi] = s.angle; b_.omega[bi] = s.omega;
  b_.cth[bi] = std::cos(s.angle); b_.sth[bi] = std::sin(s.angle);
  b_.mass[bi] = mp.mass; b_.inertia[bi] = mp.inertia;
  b_.id[bi] = next_id_++;
  b_.first_disc[bi] = static_cast<int>(d0);
  b_.n_discs[bi] = static_cast<int>(n);
  b_.tag[bi] = s.tag;
  b_.size[bi] = s.size;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = d0 + k;
    const Vec2 o = s.offsets[k] - mp.com;
    d_.ox[i] = o.x; d_.oy[i] = o.y;
    d_.r[i] = s.radii[k];
    d_.body[i] = static_cast<int>(bi);
    for (int q = 0; q < kWallSlots; ++q) d_.wall_key[i * kWallSlots + q] = -1;  // empty history slot
    old_of_new_.push_back(-1);
  }
  update_disc_positions(bi, bi + 1);
  for (auto& v : prov_fx_) v.push_back(0.0);
  for (auto& v : prov_fy_) v.push_back(0.0);
  for (auto& v : prov_tq_) v.push_back(0.0);
  body_set_changed();
  simple_valid_ = false;
  forces_valid_ = false;
  return static_cast<int>(bi);
}

std::size_t Simulation::remove_bodies_if(const std::function<bool(int)>& pred) {
  const std::size_t nb = b_.x.size();
  std::vector<char> drop(nb, 0);
  std::size_t count = 0;
  for (std::size_t i = 0; i < nb; ++i) if (pred(static_cast<int>(i))) { drop[i] = 1; ++count; }
  if (count == 0) return 0;
  // Compact bodies and discs in order (keeps the relative order: the mapping is monotone).
  std::size_t bw = 0, dw = 0;
  std::vector<int> new_old_of_new;
  new_old_of_new.reserve(d_.x.size());
  auto move = [](std::size_t from, std::size_t to) {
    return [=](const char*, auto& v, std::size_t per) {
      for (std::size_t q = 0; q < per; ++q) v[to * per + q] = v[from * per + q];
    };
  };
  for (std::size_t i = 0; i < nb; ++i) {
    if (drop[i]) continue;
    const int first = b_.first_disc[i], nd = b_.n_discs[i];
    b_.for_each_array(move(i, bw));
    for (std::size_t k = 0; k < prov_fx_.size(); ++k) {
      prov_fx_[k][bw] = prov_fx_[k][i]; prov_fy_[k][bw] = prov_fy_[k][i]; prov_tq_[k][bw] = prov_tq_[k][i];
    }
    b_.first_disc[bw] = static_cast<int>(dw);
    for (int k = 0; k < nd; ++k) {
      d_.for_each_array(move(static_cast<std::size_t>(first + k), dw));
      d_.body[dw] = static_cast<int>(bw);
      new_old_of_new.push_back(old_of_new_[first + k]);
      ++dw;
    }
    ++bw;
  }
  b_.for_each_array([&](const char*, auto& v, std::size_t per) { v.resize(bw * per); });
  d_.for_each_array([&](const char*, auto& v, std::size_t per) { v.resize(dw * per); });
  for (auto& v : prov_fx_) v.resize(bw);
  for (auto& v : prov_fy_) v.resize(bw);
  for (auto& v : prov_tq_) v.resize(bw);
  old_of_new_.swap(new_old_of_new);
  body_set_changed();
  simple_valid_ = false;
  forces_valid_ = false;
  return count;
}

void Simulation::permute_bodies(std::span<const int> order) {
  const std::size_t nb = b_.x.size();
  if (order.size() != nb) throw std::invalid_argument(fmt::format("permute_bodies: {} indices for {} bodies", order.size(), nb));
  std::vector<char> seen(nb, 0);
  for (const int i : order) {
    if (i < 0 || static_cast<std::size_t>(i) >= nb || seen[static_cast<std::size_t>(i)])
      throw std::invalid_argument(fmt::format("permute_bodies: index {} is out of range or repeated", i));
    seen[static_cast<std::size_t>(i)] = 1;
  }
  // Source of every new body and disc entry; then every array gathered from its source.
  std::vector<int> disc_src;
  disc_src.reserve(d_.x.size());
  for (const int i : order)
    for (int k = 0; k < b_.n_discs[i]; ++k) disc_src.push_back(b_.first_disc[i] + k);
  auto gather = [](const auto& src) {
    return [&src](const char*, auto& v, std::size_t per) {
      std::remove_reference_t<decltype(v)> out(src.size() * per);
      for (std::size_t k = 0; k < src.size(); ++k)
        for (std::size_t q = 0; q < per; ++q) out[k * per + q] = v[static_cast<std::size_t>(src[k]) * per + q];
      v.swap(out);
    };
  };
  b_.for_each_array(gather(order));
  d_.for_each_array(gather(disc_src));
  for (auto* pv : {&prov_fx_, &prov_fy_, &prov_tq_})
    for (auto& v : *pv) gather(order)("", v, 1);
  std::vector<int> old_of_new(disc_src.size());
  for (std::size_t k = 0; k < disc_src.size(); ++k) old_of_new[k] = old_of_new_[static_cast<std::size_t>(disc_src[k])];
  old_of_new_.swap(old_of_new);
  for (std::size_t b = 0, k = 0; b < nb; ++b) {
    b_.first_disc[b] = static_cast<int>(k);
    for (int q = 0; q < b_.n_discs[b]; ++q) d_.body[k++] = static_cast<int>(b);
  }
  body_set_changed();
  simple_valid_ = false;
  ensure_neighbor_list(-1);  // now: energy() and the history mapping read the list
}

void Simulation::sort_bodies_spatially(double strip_m) {
  require_positive("engine", "sort strip_m", strip_m);
  const std::size_t nb = b_.x.size();
  if (nb == 0) return;
  // A state that is not finite is left as it is: the next list build reports where it blew up.
  for (std::size_t i = 0; i < nb; ++i)
    if (!std::isfinite(b_.x[i]) || !std::isfinite(b_.y[i])) return;
  const double x0 = *std::min_element(b_.x.begin(), b_.x.end());
  std::vector<double> strip(nb);  // strip numbers, kept as doubles (no overflow for any width)
  for (std::size_t i = 0; i < nb; ++i) strip[i] = std::floor((b_.x[i] - x0) / strip_m);
  std::vector<int> order(nb);
  for (std::size_t i = 0; i < nb; ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return strip[a] != strip[b] ? strip[a] < strip[b] : b_.y[a] < b_.y[b];
  });
  bool identity = true;
  for (std::size_t i = 0; i < nb && identity; ++i) identity = order[i] == static_cast<int>(i);
  if (!identity) permute_bodies(order);
}

void Simulation::add_force(std::shared_ptr<BodyForce> f) {
  forces_.push_back(std::move(f));
  prov_fx_.emplace_back(b_.x.size(), 0.0);
  prov_fy_.emplace_back(b_.x.size(), 0.0);
  prov_tq_.emplace_back(b_.x.size(), 0.0);
  forces_valid_ = false;
}

// The pair kernel's copy of disc i: centre, radius and body mass; velocity of the disc centre.
inline void Simulation::pack_disc(int i) {
  const int b = d_.body[i];
  const double w = b_.omega[b];
  pdisc_[i] = {d_.x[i], d_.y[i], d_.r[i], b_.mass[b], b_.vx[b] - w * d_.wy[i], b_.vy[b] + w * d_.wx[i], w, 0.0};
}

// World positions of the discs of body b from its pose.
inline void Simulation::place_body(std::size_t b) {
  const int first = b_.first_disc[b], nd = b_.n_discs[b];
  const double X = b_.x[b], Y = b_.y[b];
  if (nd == 1 && d_.ox[first] == 0.0 && d_.oy[first] == 0.0) {
    d_.x[first] = X; d_.y[first] = Y; d_.wx[first] = 0.0; d_.wy[first] = 0.0;
    return;
  }
  const double c = b_.cth[b], s = b_.sth[b];
  for (int k = first; k < first + nd; ++k) {
    const double wx = c * d_.ox[k] - s * d_.oy[k];
    const double wy = s * d_.ox[k] + c * d_.oy[k];
    d_.wx[k] = wx; d_.wy[k] = wy;
    d_.x[k] = X + wx; d_.y[k] = Y + wy;
  }
}

void Simulation::update_simple() {
  const std::size_t nb = b_.x.size();
  simple_prefix_.assign(nb + 1, 0);
  for (std::size_t b = 0; b < nb; ++b) {
    const int k = b_.first_disc[b];
    const bool simple = b_.n_discs[b] == 1 && d_.ox[k] == 0.0 && d_.oy[k] == 0.0;
    simple_prefix_[b + 1] = simple_prefix_[b] + (simple ? 1 : 0);
  }
  simple_valid_ = true;
}

void Simulation::update_disc_positions(std::size_t b0, std::size_t b1) {
  for (std::size_t b = b0; b < b1; ++b) place_body(b);
}

int Simulation::team() {
  if (tuner_threads_ != params_.threads || tuner_fixed_ != params_.run_threads) {  // (params may be changed between steps)
    tuner_threads_ = params_.threads;
    tuner_fixed_ = params_.run_threads;
    tuner_.reset(params_.threads, params_.run_threads);
  }
  return tuner_.team();
}

// moved: -1 = unknown (check every disc), 0/1 = the caller already checked (step() does it
// in the drift loop).
bool Simulation::ensure_neighbor_list(int moved) {
  nl_params_.threads = team();
  try {
    if (structure_changed_) {
      choose_skins();
      nlist_.rebuild(d_.x, d_.y, d_.r, d_.body, old_of_new_, nl_params_, half_skin_);
    } else if (moved > 0 || (moved < 0 && nlist_.needs_rebuild(d_.x, d_.y))) {
      choose_skins();
      nlist_.rebuild(d_.x, d_.y, d_.r, d_.body, {}, nl_params_, half_skin_);
    } else {
      return false;
    }
  } catch (const geometry::BadPositionError& e) {
    // A runtime failure (exit 1), not an input error: a checkpoint's positions are checked
    // when it is read, so the state blew up during the run. Say when and which body.
    const int b = e.disc() < d_.body.size() ? d_.body[e.disc()] : -1;
    throw std::runtime_error(fmt::format(
        "engine: at t = {} s (step {}), body id {}: {} (the state has blown up: time step too large for the forces, "
        "or a force that is not finite?)",
        time_, step_, b >= 0 && static_cast<std::size_t>(b) < b_.id.size() ? b_.id[b] : -1, e.what()));
  }
  structure_changed_ = false;
  for (std::size_t i = 0; i < old_of_new_.size(); ++i) old_of_new_[i] = static_cast<int>(i);
  build_wall_candidates();
  return true;
}

// Each disc's skin for the next list build: skin/2, or for a disc faster than the quantile q of
// the disc speeds u, u tau with tau = (skin/2) / u_q, the time skin/2 lasts a disc at the
// quantile; at most kMaxSkinFactor skin/2, so the fast discs' searches stay a few cells wide.
// The speed of a disc is that of its centre now. Empty (one skin for all) if q = 0, or if no
// disc would get more than skin/2.
void Simulation::choose_skins() {
  const double q = params_.skin_speed_quantile, h0 = 0.5 * params_.skin;
  const std::size_t n = d_.x.size();
  half_skin_.clear();
  if (q <= 0.0 || n < 2) return;
  speed_.resize(n);
  half_skin_.resize(n);
  // (the loops on the engine's threads: at a list build every few tens of steps at
  // stiffness_scale 0.01, a serial pass here is time the other threads wait)
#pragma omp parallel for schedule(static) num_threads(team())
  for (std::size_t i = 0; i < n; ++i) {
    const int b = d_.body[i];
    const double w = b_.omega[b];
    const double ux = b_.vx[b] - w * d_.wy[i], uy = b_.vy[b] + w * d_.wx[i];
    const double u = std::sqrt(ux * ux + uy * uy);
    speed_[i] = u == u ? u : 0.0;  // (a NaN velocity: the list build refuses its position anyway)
    half_skin_[i] = speed_[i];
  }
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(n - 1));
  std::nth_element(half_skin_.begin(), half_skin_.begin() + k, half_skin_.end());
  const double uq = half_skin_[static_cast<std::size_t>(k)];
  const double cap = EngineParams::kMaxSkinFactor * h0;
  int wider = 0;
#pragma omp parallel for schedule(static) num_threads(team()) reduction(| : wider)
  for (std::size_t i = 0; i < n; ++i) {
    // u_i tau = h0 u_i / u_q, compared as u_i > u_q first (uq may be 0: a settled state)
    const double h = speed_[i] > uq ? std::min(cap, h0 * (speed_[i] / uq)) : h0;
    half_skin_[i] = h;
    wider |= h > h0 ? 1 : 0;
  }
  if (!wider) half_skin_.clear();
}

// Which walls each disc may touch until the next list build: may_touch() with the reach
// widened by the farthest the disc can move before it (NeighborList::max_move), plus what it
// has moved since the build when the masks are rebuilt in between. A wall's may_touch() depends only on
// its fixed shape (plane position, cylinder axis and radius; not on its rotation), so the
// masks stay valid while the shapes do; a changed shape rebuilds them (wall_shapes_changed).
void Simulation::build_wall_candidates() {
  const std::size_t n = d_.x.size(), nw = walls_.size();
  sub_valid_ = false;  // its wall candidates are a subset of these
  wall_mask_.assign(n, 0);
  wall_shape_.resize(nw);
  for (std::size_t w = 0; w < nw; ++w) wall_shape_[w] = shape_of(w);
  if (nw == 0) return;
  if (nw > 32) {  // more walls than mask bits: every disc checks every wall (as before)
    std::fill(wall_mask_.begin(), wall_mask_.end(), ~std::uint32_t{0});
    return;
  }
  prepare_walls();
  const bool listed = nlist_.size() == n;
#pragma omp parallel for schedule(static) num_threads(team())
  for (std::size_t i = 0; i < n; ++i) {
    const double move = listed ? nlist_.max_move(i) + std::sqrt(nlist_.displacement2(i, d_.x[i], d_.y[i])) : kInf;
    std::uint32_t m = 0;
    for (std::size_t w = 0; w < nw; ++w)
      if (walls_[w].may_touch({d_.x[i], d_.y[i]}, d_.r[i], wall_reach_[w] + move)) m |= std::uint32_t{1} << w;
    wall_mask_[i] = m;
    // A disc that can touch no wall until the next build has no wall contact to remember: its
    // history is cleared here (wall_disc() would clear it at this step's evaluation, which
    // follows), so that wall_disc() need not be called for it at all.
    if (m == 0 && d_.wall_key[i * kWallSlots] != -1)
      for (int q = 0; q < kWallSlots; ++q) {
        d_.wall_key[i * kWallSlots + q] = -1;
        d_.wall_eta[i * kWallSlots + q] = 0.0;
        d_.wall_slide[i * kWallSlots + q] = 0;
      }
  }
}

Simulation::WallShape Simulation::shape_of(std::size_t k) const {
  const geometry::Wall& w = walls_[k];
  const auto& ad = params_.interactions[w.interaction].adhesion;
  return {w.kind == geometry::Wall::Kind::plane ? 0 : 1, w.point.x, w.point.y, w.normal.x, w.normal.y,
          w.centre.x, w.centre.y, w.radius, w.inside ? 1 : 0, ad.hamaker_J != 0.0 ? ad.cutoff_m : 0.0, params_.skin};
}

bool Simulation::wall_shapes_changed() const {
  if (wall_shape_.size() != walls_.size() || wall_mask_.size() != d_.x.size()) return true;
  for (std::size_t w = 0; w < walls_.size(); ++w)
    if (!(shape_of(w) == wall_shape_[w])) return true;
  return false;
}

// Row ranges per part, balanced by list entries, and each part's cross entries (partners beyond
// its rows) in slots of their own. Recomputed only when the list or the part count changes.
void Simulation::update_thread_split() {
  const int nt = params_.threads;
  const int n = static_cast<int>(d_.x.size());
  if (split_builds_ == nlist_.builds() && split_threads_ == nt && static_cast<int>(nlist_.size()) == n) return;
  split_builds_ = -1;  // (until the tables below are whole: an allocation that fails leaves them to be made again)
  entry_row_.resize(nlist_.pair_count());
  split_.assign(nt + 1, 0);
  const auto& rs = nlist_.row_start_;
  const double per = static_cast<double>(nlist_.pair_count()) / nt;
  for (int t = 1; t < nt; ++t) {
    const int target = static_cast<int>(per * t);
    int s = static_cast<int>(std::lower_bound(rs.begin(), rs.end(), target) - rs.begin());
    split_[t] = std::clamp(s, split_[t - 1], n);
  }
  split_[nt] = n;
  touch_blocks_ = (n >> kTouchShift) + 1;
  const std::size_t tb2 = static_cast<std::size_t>(touch_blocks_) + 2;
  cross_block_.assign(static_cast<std::size_t>(nt) * tb2, 0);
  // Room for every entry to be a cross entry (part t's slots start at its first entry); grown
  // only, and the slots hold zero between steps, new ones too.
  if (nt > 1 && cross_val_.size() < nlist_.pair_count()) {
    cross_slot_.resize(nlist_.pair_count());
    cross_disc_.resize(nlist_.pair_count());
    cross_val_.resize(nlist_.pair_count(), CrossForce{0.0, 0.0, 0.0});
  }
  // Each part's entries' rows and its cross slots, on the engine's threads (part u by thread u
  // mod T; after a list build, serial time here is time the other threads wait).
  int* er = entry_row_.data();
  const int* nbr = nlist_.nbr_.data();
  std::int64_t cross = 0;
#pragma omp parallel num_threads(team()) reduction(+ : cross)
  {
    const int team_size = omp_get_num_threads();
    for (int t = omp_get_thread_num(); t < nt; t += team_size) {
      for (int i = split_[t]; i < split_[t + 1]; ++i) std::fill(er + rs[i], er + rs[i + 1], i);
      if (nt == 1) continue;
      // a counting sort of the part's cross entries by the block of their disc (entry order kept)
      int* c = cross_block_.data() + static_cast<std::size_t>(t) * tb2;
      const int e0 = rs[split_[t]], e1 = rs[split_[t + 1]], end = split_[t + 1];
      for (int e = e0; e < e1; ++e)
        if (nbr[e] >= end) ++c[(nbr[e] >> kTouchShift) + 2];
      for (std::size_t q = 2; q < tb2; ++q) c[q] += c[q - 1];
      for (int e = e0; e < e1; ++e) {
        const int j = nbr[e];
        if (j < end) continue;
        const int slot = e0 + c[(j >> kTouchShift) + 1]++;
        cross_slot_[e] = slot;
        cross_disc_[slot] = j;
      }
      cross += c[tb2 - 1];
      for (std::size_t q = 0; q < tb2; ++q) c[q] += e0;  // slot numbers (the part's start from its first entry)
    }
  }
  cross_count_ = cross;
  split_builds_ = nlist_.builds();
  split_threads_ = nt;
}

// The pair kernel: rows [i0, i1) of the half list. Reads only the packed copies (plus the
// list and its history), accumulates force and torque about the disc centre into f (the adhesive
// part is not kept apart: update_adhesive_parts()). One loop over the entries: a distance test, and for a
// pair within contact or adhesion range the law at once (detail::pair_contact) and its sums
// into both discs, in list order (a row's own sum is accumulated apart and added when the row
// ends; a partner from i1 on gets its part in the entry's cross slot). The history of a pair
// out of range is cleared.
// (Kept out of line: inlined into contact_forces' parallel region, GCC 12 made it ~3 % slower.)
template <bool kAdhesion, bool kPeriodic, int kList, bool kCross>
[[gnu::noinline]] void Simulation::pair_rows(int i0, int i1, PackedForce* f, std::int64_t& nc_out,
                                             SubEntry* sub, int& sub_n, int* xs, int& xs_n) {
  const ContactParams cp = params_.interactions[0].contact;
  const models::HamakerParams hp = params_.interactions[0].adhesion;
  const double dt = params_.dt;
  const double L = params_.x_hi - params_.x_lo, hL = 0.5 * L;
  const double reach = pair_reach_;
  const PackedDisc* P = pdisc_.data();
  const int* rs = nlist_.row_start_.data();
  const int* nb = nlist_.nbr_.data();
  double* eta = nlist_.eta_.data();
  std::uint8_t* sl = nlist_.slide_.data();
  const int* own = entry_row_.data();
  // a partner from i1 on is a cross entry: its force on j goes into the entry's slot (kCross:
  // not the last part, the only one that can have none; without the test 1 part ran 0.7 % fewer
  // instructions per step, cachegrind on the packing)
  const int* cslot = cross_slot_.data();
  CrossForce* cval = cross_val_.data();
  // i - j centre vector, the minimum image if periodic (|dx| < 1.5 L since centres are wrapped)
  auto separation = [&](const PackedDisc& pi, const PackedDisc& pj) __attribute__((always_inline)) {
    double dx = pi.x - pj.x;
    const double dy = pi.y - pj.y;
    if constexpr (kPeriodic) {
      dx = dx > hL ? dx - L : dx;
      dx = dx < -hL ? dx + L : dx;
    }
    return Vec2{dx, dy};
  };
  std::int64_t nc = 0;
  // the row whose own sum is open, and that sum
  int row = -1;
  double fxi = 0.0, fyi = 0.0, tqi = 0.0;
  auto close_row = [&]() __attribute__((always_inline)) {
    if (row < 0) return;
    f[row].fx += fxi; f[row].fy += fyi; f[row].tq += tqi;
    fxi = fyi = tqi = 0.0;
  };
  const double margin = sub_margin_;
  const double* G = kList == 1 && sub_per_disc_ ? sub_g_.data() : nullptr;  // margins per disc
  int m = 0, mx = 0;
  // kX: 0 = the partner is within the rows, 1 = test it, 2 = a cross entry
  auto test = [&]<int kX>(int e, int i, int j) __attribute__((always_inline)) {
    const PackedDisc& pi = P[i];
    const PackedDisc& pj = P[j];
    const Vec2 d = separation(pi, pj);
    const double rc = (pi.r + pj.r) + reach;
    const double d2 = d.x * d.x + d.y * d.y;
    const bool interacts = d2 < rc * rc;
    if constexpr (kList == 1) {  // taken into the sublist within range + margin (branch-free)
      const double rm = G ? rc + (G[i] + G[j]) : rc + margin;
      const bool in = d2 < rm * rm;
      sub[m] = {e, i, j};
      if constexpr (kCross) {  // where the sublist's cross entries are (see kList 2)
        xs[mx] = m;
        mx += in && j >= i1 ? 1 : 0;
      }
      m += in ? 1 : 0;
    }
    if (interacts) {
      const PackedDisc& vi = pi;
      const PackedDisc& vj = pj;
      double et = eta[e], sd = static_cast<double>(sl[e]);
      double fx, fy, ti, tj, fax = 0.0, fay = 0.0, touching;
      detail::pair_contact<kAdhesion>(cp, hp, dt, d.x, d.y, pi.r, pj.r, pi.m, pj.m, vi.vx, vi.vy, vi.w, vj.vx, vj.vy,
                                      vj.w, et, sd, fx, fy, ti, tj, fax, fay, touching);
      if (i != row) { close_row(); row = i; }
      eta[e] = et; sl[e] = static_cast<std::uint8_t>(sd);
      nc += static_cast<std::int64_t>(touching);
      fxi += fx; fyi += fy; tqi += ti;
      if (kX == 0 || (kX == 1 && j < i1)) {
        f[j].fx -= fx; f[j].fy -= fy; f[j].tq += tj;
      } else {
        cval[cslot[e]] = CrossForce{fx, fy, tj};
      }
    } else if ((sl[e] != 0) | (eta[e] != 0.0)) {
      // History of a pair out of range is reset where there is some (rare: a contact that just
      // opened); most stay clean, and a read keeps their cache lines clean (no write-back). A
      // pair left out of the sublist is out of range when it is taken, so its history is clean
      // then and stays so until the next sublist.
      eta[e] = 0.0; sl[e] = 0;
    }
  };
  if constexpr (kList == 2) {
    // The discs of entry k + 8 are fetched ahead (their centres, velocities, force sums and the
    // pair's history: scattered over ~2 MB, in L2 at best): the next entries' loads then
    // overlap this one's arithmetic. Measured: stiffness_scale 0.01 (0.8 contacts per disc)
    // 1.029x; 4 or 16 ahead, or only centres and velocities, were slower than 8.
    // (the count in a local: the history's byte stores may alias the reference, and GCC reloaded it per entry)
    const int sn = sub_n;
    auto ahead = [&](int k) __attribute__((always_inline)) {
      if (k + 8 < sn) {
        const SubEntry& q = sub[k + 8];
        __builtin_prefetch(&P[q.j]); __builtin_prefetch(&f[q.j], 1);
        __builtin_prefetch(&eta[q.e]);
      }
    };
    // With cross entries, the runs between them (xs[0, xs_n): their places in the sublist, in
    // order) without the partner test, and each cross entry on its own: the same entries in the
    // same order as one loop that tests each partner. (The test in every entry cost one thread
    // running two parts 0.44 % of its instructions on the packing, cachegrind.)
    int k = 0;
    for (int x = 0; kCross && x < xs_n; ++x) {
      for (const int stop = xs[x]; k < stop; ++k) {
        ahead(k);
        test.template operator()<0>(sub[k].e, sub[k].i, sub[k].j);
      }
      ahead(k);
      test.template operator()<2>(sub[k].e, sub[k].i, sub[k].j);
      ++k;
    }
    for (; k < sn; ++k) {
      ahead(k);
      test.template operator()<0>(sub[k].e, sub[k].i, sub[k].j);
    }
  } else {
    for (int e = rs[i0], e1 = rs[i1]; e < e1; ++e) test.template operator()<kCross ? 1 : 0>(e, own[e], nb[e]);
  }
  if constexpr (kList == 1) {
    sub_n = m;
    if constexpr (kCross) xs_n = mx;
  }
  close_row();
  nc_out = nc;
}

// The pair sums of discs [k0, k1) (a block of bodies' discs, in contact_forces' per-body phase)
// into d_.fx/fy/tq. Per disc: from +0, the sum of its cross slots of each earlier part (each from
// +0, in entry order), parts in order, then its own part's buffer value. Those are the
// operations of summing one buffer per part in part order, each buffer accumulated from +0 in
// list order: a part that reached no disc of a block of 2^kTouchShift is left out (it held +0
// there, and adding +0 changes no sum that starts at +0: such a sum is never -0). So the sums
// depend on the part count only, not on which thread ran which part. Each value read is cleared.
// (Inlined into the region, as the loop it replaced was.)
[[gnu::always_inline]] inline void Simulation::reduce_pair_sums(int k0, int k1) {
  if (k1 <= k0) return;
  double* dfx = d_.fx.data(); double* dfy = d_.fy.data(); double* dtq = d_.tq.data();
  PackedForce* g = pforce_.data();
  const int nt = params_.threads;
  const std::size_t tb2 = static_cast<std::size_t>(touch_blocks_) + 2;
  const int b0 = k0 >> kTouchShift, b1 = ((k1 - 1) >> kTouchShift) + 1;
  bool any = false;  // cross slots in these discs' blocks (the last part has none)
  for (int u = 0; u + 1 < nt && !any; ++u) {
    const int* c = cross_block_.data() + static_cast<std::size_t>(u) * tb2;
    any = c[b0] < c[b1];
  }
  auto plain = [&](int s, int e) __attribute__((always_inline)) {
    for (int i = s; i < e; ++i) {
      double a = 0.0, b = 0.0, c = 0.0;
      a += g[i].fx; b += g[i].fy; c += g[i].tq;
      g[i] = PackedForce{0.0, 0.0, 0.0, 0.0};
      dfx[i] = a; dfy[i] = b; dtq[i] = c;
    }
  };
  if (!any) {
    plain(k0, k1);
    return;
  }
  constexpr int kB = 1 << kTouchShift;
  // Discs [s, e) of touch block tb (from base) reached by one earlier part only, through its slots
  // [q0, q1): their sums are S + own, and own + S has the same bits (addition commutes; 0 + own
  // is own but for -0, and S + -0 = S: S is never -0). So after the plain loop each reached disc's
  // S (from +0, in entry order) is added.
  auto add_slots = [&](int q0, int q1, int s, int e, int base) __attribute__((always_inline)) {
    double sx[kB], sy[kB], st[kB];
    bool open[kB];  // reached, S not yet added
    for (int q = q0; q < q1; ++q) {
      const int j = cross_disc_[q];
      if (j < s || j >= e) continue;  // (a block of 2^kTouchShift discs may span two blocks of bodies)
      sx[j - base] = sy[j - base] = st[j - base] = 0.0;
      open[j - base] = true;
    }
    for (int q = q0; q < q1; ++q) {
      const int j = cross_disc_[q];
      if (j < s || j >= e) continue;
      CrossForce& v = cross_val_[q];
      sx[j - base] -= v.fx; sy[j - base] -= v.fy; st[j - base] += v.tq;
      v = CrossForce{0.0, 0.0, 0.0};
    }
    for (int q = q0; q < q1; ++q) {  // each reached disc once
      const int j = cross_disc_[q];
      if (j < s || j >= e || !open[j - base]) continue;
      dfx[j] += sx[j - base]; dfy[j] += sy[j - base]; dtq[j] += st[j - base];
      open[j - base] = false;
    }
  };
  // Where no touch block is reached by two earlier parts (always with two parts), one plain loop
  // over all the discs and then the slots: the plain loop split at every touch block of a reached
  // block of bodies cost one part running two 0.2 % of its instructions (packing, cachegrind).
  bool single = true;
  for (int tb = b0; tb < b1 && single && nt > 2; ++tb) {
    int np = 0;
    for (int u = 0; u + 1 < nt; ++u) {
      const int* c = cross_block_.data() + static_cast<std::size_t>(u) * tb2;
      np += c[tb] < c[tb + 1] ? 1 : 0;
    }
    single = np < 2;
  }
  if (single) {
    plain(k0, k1);
    for (int u = 0; u + 1 < nt; ++u) {
      const int* c = cross_block_.data() + static_cast<std::size_t>(u) * tb2;
      for (int tb = b0; tb < b1; ++tb)
        if (c[tb] < c[tb + 1])
          add_slots(c[tb], c[tb + 1], std::max(k0, tb << kTouchShift), std::min(k1, (tb + 1) << kTouchShift),
                    tb << kTouchShift);
    }
    return;
  }
  for (int tb = b0; tb < b1; ++tb) {
    const int s = std::max(k0, tb << kTouchShift), e = std::min(k1, (tb + 1) << kTouchShift);
    const int base = tb << kTouchShift;
    int np = 0, only = 0;
    for (int u = 0; u + 1 < nt; ++u) {
      const int* c = cross_block_.data() + static_cast<std::size_t>(u) * tb2;
      if (c[tb] < c[tb + 1]) { ++np; only = u; }
    }
    if (np == 0) {
      plain(s, e);
      continue;
    }
    if (np == 1) {
      plain(s, e);
      const int* c = cross_block_.data() + static_cast<std::size_t>(only) * tb2;
      add_slots(c[tb], c[tb + 1], s, e, base);
      continue;
    }
    bool has = false;
    double ax[kB], ay[kB], at[kB];
    for (int u = 0; u + 1 < nt; ++u) {
      const int* c = cross_block_.data() + static_cast<std::size_t>(u) * tb2;
      const int q0 = c[tb], q1 = c[tb + 1];
      if (q0 == q1) continue;
      if (!has) {
        for (int i = s; i < e; ++i) ax[i - base] = ay[i - base] = at[i - base] = 0.0;
        has = true;
      }
      double sx[kB], sy[kB], st[kB];
      for (int i = s; i < e; ++i) sx[i - base] = sy[i - base] = st[i - base] = 0.0;
      for (int q = q0; q < q1; ++q) {
        const int j = cross_disc_[q];
        if (j < s || j >= e) continue;  // (a block of 2^kTouchShift discs may span two blocks of bodies)
        CrossForce& v = cross_val_[q];
        sx[j - base] -= v.fx; sy[j - base] -= v.fy; st[j - base] += v.tq;
        v = CrossForce{0.0, 0.0, 0.0};
      }
      for (int i = s; i < e; ++i) {
        ax[i - base] += sx[i - base]; ay[i - base] += sy[i - base]; at[i - base] += st[i - base];
      }
    }
    if (!has) {
      plain(s, e);
      continue;
    }
    for (int i = s; i < e; ++i) {
      double a = ax[i - base], b = ay[i - base], c = at[i - base];
      a += g[i].fx; b += g[i].fy; c += g[i].tq;
      g[i] = PackedForce{0.0, 0.0, 0.0, 0.0};
      dfx[i] = a; dfy[i] = b; dtq[i] = c;
    }
  }
}

// Pair forces, wall forces and their sum per body, in one parallel region: pack the discs
// (unless step() has), run the pair kernel on each part's rows, gather each disc's pair sums
// (reduce_pair_sums) and add the wall forces of that disc, then sum per body (and, with kick_h > 0, kick it:
// step()).
void Simulation::contact_forces(double kick_h, bool packed, bool providers) {
  const int n = static_cast<int>(d_.x.size());
  const int nb = static_cast<int>(b_.x.size());
  const bool has_walls = !walls_.empty();
  if (has_walls) {
    if (wall_shapes_changed()) build_wall_candidates();
    prepare_walls();
  }
  const int nt = params_.threads;
  const bool adh = params_.interactions[0].adhesion.hamaker_J != 0.0;
  const bool periodic = params_.periodic_x;
  update_thread_split();
  if (!packed) {
    pdisc_.resize(n);
  }
  // Every buffer the region writes is sized here: nothing allocates inside it (an exception must
  // not cross an OpenMP region), except the wall queries' scratch, whose failures are carried out.
  if (static_cast<int>(pforce_.size()) < n) pforce_.resize(n);
  thread_nc_.assign(nt, 0);
  if (has_walls) thread_fail_.assign(nt, nullptr);
  // per disc and wall: the roller period the disc was last found in (a hint for the query,
  // which checks it; stale after renumbering, never wrong)
  if (has_walls && wall_hint_.size() != static_cast<std::size_t>(n) * walls_.size())
    wall_hint_.assign(static_cast<std::size_t>(n) * walls_.size(), -1);
  // The per-step sublist: used while it was taken from this list build, thread split, reach and
  // margin and no two discs can have closed the margin since; taken again otherwise.
  const double margin = params_.inner_skin_fraction * params_.skin;
  int list_mode = 0;
  if (margin > 0.0) {
    bool ok = sub_valid_ && sub_builds_ == nlist_.builds() && sub_threads_ == nt && sub_reach_ == pair_reach_ &&
              sub_margin_ == margin && sub_x0_.size() == static_cast<std::size_t>(n);
    if (ok) ok = sub_moved_ == 0 || (sub_moved_ < 0 && !sublist_moved());
    if (ok && has_walls) ok = walls_within_margin();
    list_mode = ok ? 2 : 1;
    if (!ok) {
      sub_valid_ = false;
      sub_margin_ = margin;
      // With skins per disc, margins per disc: the same fraction of each disc's own skin.
      sub_per_disc_ = nlist_.per_disc() && nlist_.size() == static_cast<std::size_t>(n);
      // (They depend only on the list's skins: made again only after a list build, not at each
      // take of the sublist, where one thread made them while the others waited.)
      if (sub_per_disc_ && (sub_g_builds_ != nlist_.builds() || sub_g_fraction_ != params_.inner_skin_fraction ||
                            sub_g_.size() != static_cast<std::size_t>(n))) {
        sub_g_.resize(static_cast<std::size_t>(n));
        sub_w_.resize(static_cast<std::size_t>(n));
        for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
          const double g = params_.inner_skin_fraction * nlist_.max_move(i);
          sub_g_[i] = g;
          sub_w_[i] = 1.0 / (0.99 * g * 0.99 * g);
        }
        sub_g_builds_ = nlist_.builds();
        sub_g_fraction_ = params_.inner_skin_fraction;
      }
      sub_.resize(nt);
      sub_n_.assign(nt, 0);
      subx_.resize(nt);
      subx_n_.assign(nt, 0);
      const std::size_t tb2 = static_cast<std::size_t>(touch_blocks_) + 2;
      for (int u = 0; u < nt; ++u) {
        const int e0 = nlist_.row_start_[split_[u]];
        sub_[u].resize(static_cast<std::size_t>(nlist_.row_start_[split_[u + 1]] - e0));
        // room for the part's cross entries (update_thread_split numbered its slots from e0) + 1
        const int nx = u + 1 < nt ? cross_block_[static_cast<std::size_t>(u) * tb2 + tb2 - 1] - e0 : 0;
        subx_[u].resize(static_cast<std::size_t>(nx) + 1);
      }
    }
  }
  sub_moved_ = -1;
  // Taken now with room in the list for the margins (list_room_): the list holds while this
  // sublist does, and step() need not check it until the sublist is taken again.
  if (list_mode != 2) list_check_ = !(list_mode == 1 && list_room_ == 1);
  list_room_ = -1;
  // The wall candidates follow the sublist: taken with it, used with it (up to 32 walls, one
  // mask bit each). Each disc's bits start cleared, so a disc without candidates has none.
  const bool near_walls = has_walls && list_mode == 2 && walls_.size() <= 32;
  const bool take_near = has_walls && list_mode == 1 && walls_.size() <= 32;
  if (take_near) wall_near_.resize(static_cast<std::size_t>(n));  // (each disc's bits set in the region)
  // The sublist's reference positions, copied per block in the region (not by one thread after it)
  if (list_mode == 1) {
    sub_x0_.resize(static_cast<std::size_t>(n));
    sub_y0_.resize(static_cast<std::size_t>(n));
  }
  int unused_n = 0, unused_xn = 0;
  auto run_rows = [&]<bool A, bool Per>(int i0, int i1, PackedForce* f, std::int64_t& nc, SubEntry* sub, int& sn,
                                         int* xs, int& xn) {
    const bool cross = i1 < n;  // (rows before the last part's: partners may lie beyond them)
    if (list_mode == 2)
      cross ? pair_rows<A, Per, 2, true>(i0, i1, f, nc, sub, sn, xs, xn) : pair_rows<A, Per, 2, false>(i0, i1, f, nc, sub, sn, xs, xn);
    else if (list_mode == 1)
      cross ? pair_rows<A, Per, 1, true>(i0, i1, f, nc, sub, sn, xs, xn) : pair_rows<A, Per, 1, false>(i0, i1, f, nc, sub, sn, xs, xn);
    else
      cross ? pair_rows<A, Per, 0, true>(i0, i1, f, nc, sub, sn, xs, xn) : pair_rows<A, Per, 0, false>(i0, i1, f, nc, sub, sn, xs, xn);
  };
  const int run = team();  // threads that run the nt parts (results depend on nt only)
  body_blocks_.reset((nb + kBodyBlock - 1) / kBodyBlock, run);
  const bool simple_blocks = simple_valid_ && simple_prefix_.size() == static_cast<std::size_t>(nb) + 1;
#pragma omp parallel num_threads(run)
  {
    const int t = omp_get_thread_num();
    if (!packed) {
#pragma omp for schedule(static)
      for (int i = 0; i < n; ++i) pack_disc(i);
      // (implicit barrier: every thread reads all packed discs)
    }
    // Row chunk u (of nt) goes to thread u mod T: the same sums even if the runtime gave fewer
    // threads than asked for (OMP_DYNAMIC, OMP_THREAD_LIMIT, a nested region); one chunk each else.
    const int team_size = omp_get_num_threads();
    for (int u = t; u < nt; u += team_size) {
      // The buffer and the cross slots are zero here: the per-body phase below clears each value
      // as it reads it (one pass over them per step instead of two), and they start zero.
      const int lo = split_[u];
      std::int64_t nc = 0;
      const int i1 = split_[u + 1];
      SubEntry* sub = list_mode > 0 ? sub_[u].data() : nullptr;
      int& sn = list_mode > 0 ? sub_n_[u] : unused_n;
      int* xs = list_mode > 0 ? subx_[u].data() : nullptr;
      int& xn = list_mode > 0 ? subx_n_[u] : unused_xn;
      if (adh) {
        if (periodic) run_rows.template operator()<true, true>(lo, i1, pforce_.data(), nc, sub, sn, xs, xn);
        else run_rows.template operator()<true, false>(lo, i1, pforce_.data(), nc, sub, sn, xs, xn);
      } else {
        if (periodic) run_rows.template operator()<false, true>(lo, i1, pforce_.data(), nc, sub, sn, xs, xn);
        else run_rows.template operator()<false, false>(lo, i1, pforce_.data(), nc, sub, sn, xs, xn);
      }
      thread_nc_[u] = nc;
    }
    std::int64_t wall_nc = 0;
#pragma omp barrier
    // Blocks of bodies and their discs (bodies own consecutive discs): each disc's pair sums
    // (reduce_pair_sums: bitwise reproducible for a given part count, whichever thread does
    // it), its wall forces added, then sum its bodies (and kick them). A body's discs are in
    // the same block as the body, so no barrier is needed between the discs and the bodies.
    // In blocks of bodies, so that a block's disc sums are still in L1 when its bodies read them.
    // Each thread starts on its own share of the blocks and then takes what is left of the
    // others' (BlockSteal): the wall contacts are not spread evenly over the bodies.
    double* vx = b_.vx.data(); double* vy = b_.vy.data(); double* om = b_.omega.data();
    const double* im = inv_mass_.data(); const double* iI = inv_inertia_.data();
    for (int q = body_blocks_.next(t); q >= 0; q = body_blocks_.next(t)) {
      const int c0 = q * kBodyBlock, c1 = std::min(nb, c0 + kBodyBlock);
      const int k0 = b_.first_disc[c0], k1 = c1 < nb ? b_.first_disc[c1] : n;
      // the force providers' arrays, cleared for provider_forces() (which follows every call
      // without providers; with them, step() cleared them before calling the providers)
      for (std::size_t k = 0; k < (providers ? 0 : forces_.size()); ++k) {
        std::fill(prov_fx_[k].begin() + c0, prov_fx_[k].begin() + c1, 0.0);
        std::fill(prov_fy_[k].begin() + c0, prov_fy_[k].begin() + c1, 0.0);
        std::fill(prov_tq_[k].begin() + c0, prov_tq_[k].begin() + c1, 0.0);
      }
      reduce_pair_sums(k0, k1);
      // then each disc's wall forces, added to its pair sums
      for (int i = has_walls ? k0 : k1; i < k1; ++i) {
        // Walls: the candidates of the list build, or while the sublist is in use only those
        // within reach + margin when it was taken (most discs: none, no call).
        const std::uint32_t wm = !has_walls ? 0u : near_walls ? wall_near_[i] : wall_mask_[i];
        if (take_near) wall_near_[i] = 0u;
        if (wm != 0) {
          try {  // the hit lists grow on first use (bad_alloc); rethrown after the region
            wall_disc(static_cast<std::size_t>(i), wm, thread_hits_[t].v, wall_nc);
            if (take_near)
              wall_near_[i] = walls_near(static_cast<std::size_t>(i), sub_per_disc_ ? sub_g_[i] + 0.5 * margin : margin,
                                         thread_hits_[t].v);
          } catch (...) {
            if (!thread_fail_[t]) thread_fail_[t] = std::current_exception();
          }
        }
      }
      if (list_mode == 1) {
        std::copy(d_.x.begin() + k0, d_.x.begin() + k1, sub_x0_.begin() + k0);
        std::copy(d_.y.begin() + k0, d_.y.begin() + k1, sub_y0_.begin() + k0);
      }
      if (simple_blocks && simple_prefix_[c1] - simple_prefix_[c0] == c1 - c0) {
        // One disc per body at its centre (step()): reduce_bodies' sums with its offset (0, 0),
        // in one loop without the disc ranges.
        const Vec2 g = params_.gravity;
        const double* m = b_.mass.data();
        const double* dfx = d_.fx.data() + (k0 - c0); const double* dfy = d_.fy.data() + (k0 - c0);
        const double* dtq = d_.tq.data() + (k0 - c0);
        double* bfx = b_.fx.data(); double* bfy = b_.fy.data(); double* btq = b_.torque.data();
        for (int bb = c0; bb < c1; ++bb) {
          const double fx = 0.0 + dfx[bb], fy = 0.0 + dfy[bb];
          bfx[bb] = fx + m[bb] * g.x;
          bfy[bb] = fy + m[bb] * g.y;
          btq[bb] = 0.0 + (dtq[bb] + 0.0 * dfy[bb] - 0.0 * dfx[bb]);
        }
        if (providers) add_provider_forces(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1));
        if (kick_h > 0.0)
          for (int bb = c0; bb < c1; ++bb) {
            vx[bb] += kick_h * bfx[bb] * im[bb]; vy[bb] += kick_h * bfy[bb] * im[bb]; om[bb] += kick_h * btq[bb] * iI[bb];
          }
      } else if (kick_h > 0.0 || providers) {
        // The same operations as provider_forces()' loop, so the same bits.
        reduce_bodies(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1));
        if (providers) add_provider_forces(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1));
        const double* bfx = b_.fx.data(); const double* bfy = b_.fy.data(); const double* btq = b_.torque.data();
        if (kick_h > 0.0)
          for (int bb = c0; bb < c1; ++bb) {
            vx[bb] += kick_h * bfx[bb] * im[bb]; vy[bb] += kick_h * bfy[bb] * im[bb]; om[bb] += kick_h * btq[bb] * iI[bb];
          }
      } else {
        reduce_bodies(static_cast<std::size_t>(c0), static_cast<std::size_t>(c1));
      }
    }
    thread_nc_[t] += wall_nc;
  }
  if (has_walls)
    for (const auto& e : thread_fail_)
      if (e) std::rethrow_exception(e);
  std::int64_t total = 0;
  for (auto c : thread_nc_) total += c;
  n_contacts_ = total;
  if (list_mode == 1) {
    sub_builds_ = nlist_.builds();
    sub_threads_ = nt;
    sub_reach_ = pair_reach_;
    sub_wall_angle_.resize(walls_.size());
    for (std::size_t w = 0; w < walls_.size(); ++w) sub_wall_angle_[w] = walls_[w].angle;
    sub_valid_ = true;
    ++sub_takes_;
  }
}

// A rough cylinder's surface moves with its rotation: no point of it has moved more than
// |angle change| x radius since the sublist was taken. Together with the discs' half margin
// (sub_exceeds; with margins per disc, its own 0.99 g_i against candidates within g_i + half the
// margin) that keeps a disc left without a wall candidate out of its reach. Planes and
// smooth cylinders keep their shape as they move (a changed shape rebuilds the candidates).
bool Simulation::walls_within_margin() const {
  if (sub_wall_angle_.size() != walls_.size()) return false;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    const auto& wall = walls_[w];
    if (wall.kind != geometry::Wall::Kind::cylinder || !wall.rough()) continue;
    if (!(std::fabs(wall.angle - sub_wall_angle_[w]) * wall.radius <= 0.49 * sub_margin_)) return false;
  }
  return true;
}

// The walls of disc i's candidates within reach + margin of it now (one bit per wall).
std::uint32_t Simulation::walls_near(std::size_t i, double margin, std::vector<geometry::WallHit>& hits) {
  const std::uint32_t mask = wall_mask_[i];
  const Vec2 c{d_.x[i], d_.y[i]};
  const double r = d_.r[i];
  std::uint32_t near = 0;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    if (!(mask >> w & 1u)) continue;
    const double reach = wall_reach_[w] + margin;
    if (!walls_[w].may_touch(c, r, reach)) continue;
    hits.clear();
    walls_[w].query(c, r, reach, hits, &wall_hint_[i * walls_.size() + w]);
    if (!hits.empty()) near |= std::uint32_t{1} << w;
  }
  return near;
}

// The list's displacement measures over every disc, as step()'s block loop takes them: the two
// largest squared displacements (one skin), or the largest weighted by 1 / h_i^2 (skins per disc).
void Simulation::list_displacements(double& d1, double& d2, double& l1) const {
  d1 = d2 = l1 = 0.0;
  const std::size_t n = d_.x.size();
  if (nlist_.per_disc()) {
    l1 = detail::max_weighted_displacement2(d_.x.data(), d_.y.data(), nlist_.x0(), nlist_.y0(), nlist_.inv_skin2(), 0, n,
                                            params_.periodic_x, params_.x_hi - params_.x_lo);
  } else {
    for (std::size_t k = 0; k < n; ++k) geometry::NeighborList::top2(nlist_.displacement2(k, d_.x[k], d_.y[k]), d1, d2);
  }
}

bool Simulation::sublist_moved() const {
  double m = 0.0;
  for (std::size_t k = 0; k < d_.x.size(); ++k) {
    const double d2 = sub_per_disc_ ? sub_disp2(k) * sub_w_[k] : sub_disp2(k);
    if (!(d2 <= m)) m = d2 == d2 ? d2 : kInf;  // (a NaN position: taken again, and refused by the list)
  }
  return sub_exceeds(m);
}

void Simulation::prepare_walls() {
  const std::size_t nw = walls_.size();
  wall_reach_.resize(nw);
  for (auto& w : walls_) w.prepare_angle();  // one sin/cos per wall and evaluation, not per query
  for (std::size_t w = 0; w < nw; ++w) {
    const auto& ad = params_.interactions[walls_[w].interaction].adhesion;
    wall_reach_[w] = ad.hamaker_J != 0.0 ? ad.cutoff_m : 0.0;
  }
  if (static_cast<int>(thread_hits_.size()) < params_.threads) thread_hits_.resize(params_.threads);
  // Which thread queries a disc's walls is decided at run time (BlockSteal), so every thread's hit
  // list gets the largest capacity any has needed: a thread new to a wall block does not grow its
  // list inside the region (an allocation there is a bad_alloc to carry out, and a needless call).
  std::size_t cap = 0;
  for (const auto& h : thread_hits_) cap = std::max(cap, h.v.capacity());
  for (auto& h : thread_hits_) h.v.reserve(cap);
}

// Wall forces on disc i, added to its force arrays; wall history slots updated.
void Simulation::wall_disc(std::size_t i, std::uint32_t mask, std::vector<geometry::WallHit>& hits, std::int64_t& nc) {
  const std::size_t nw = walls_.size();
  const double dt = params_.dt;
  std::int64_t new_key[kWallSlots];
  double new_eta[kWallSlots];
  std::uint8_t new_sl[kWallSlots];
  if (mask == 0) return;  // no candidate wall, and no history (build_wall_candidates cleared it)
  const Vec2 c{d_.x[i], d_.y[i]};
  const double r = d_.r[i];
  int nnew = 0;
  double fx = 0, fy = 0, tq = 0;
  bool touched = false;
  for (std::size_t w = 0; w < nw; ++w) {
    if (!(mask >> (w & 31) & 1u)) continue;  // (nw > 32: every bit set)
    const auto& wall = walls_[w];
    if (!wall.may_touch(c, r, wall_reach_[w])) continue;  // most discs: no trigonometry, no query
    const Interaction& ia = params_.interactions[wall.interaction];
    hits.clear();
    wall.query(c, r, wall_reach_[w], hits, &wall_hint_[i * nw + w]);
    const int bi = d_.body[i];
    for (const auto& h : hits) {
      touched = true;
      const double overlap = -h.gap;
      const bool touching = overlap > 0.0;
      const std::int64_t key = (static_cast<std::int64_t>(w) << 40) | h.key;
      double l = 0.0, vn = 0.0, vt = 0.0;
      TangentialState st{};
      if (touching) {
        ++nc;
        l = r - 0.5 * overlap;  // centre to contact point
        const double rx = d_.wx[i] - l * h.normal.x, ry = d_.wy[i] - l * h.normal.y;
        const double vrx = b_.vx[bi] - b_.omega[bi] * ry - h.velocity.x;
        const double vry = b_.vy[bi] + b_.omega[bi] * rx - h.velocity.y;
        vn = vrx * h.normal.x + vry * h.normal.y;
        vt = -vrx * h.normal.y + vry * h.normal.x;
        for (int q = 0; q < kWallSlots; ++q) {
          if (d_.wall_key[i * kWallSlots + q] == key) {
            st.eta = d_.wall_eta[i * kWallSlots + q];
            st.sliding = d_.wall_slide[i * kWallSlots + q] != 0 ? 1.0 : 0.0;
            break;
          }
        }
      }
      // A wall has infinite mass and radius: the reduced mass is the body's. Adhesion is always
      // evaluated (hamaker_force is 0 for A = 0): walls are few, and this keeps the sums as they were.
      const models::ContactForce cf = models::contact_force<true>(ia.contact, ia.adhesion, r, kInf, overlap, vn, vt,
                                                                  b_.mass[bi], dt, st);
      double fnx = 0, fny = 0;
      if (touching) {
        if (nnew < kWallSlots) {  // more simultaneous wall contacts than slots: no history for the extra
          new_key[nnew] = key; new_eta[nnew] = st.eta; new_sl[nnew] = static_cast<std::uint8_t>(st.sliding); ++nnew;
        }
        fnx = cf.fn * h.normal.x - cf.ft * h.normal.y;
        fny = cf.fn * h.normal.y + cf.ft * h.normal.x;
        tq += -l * cf.ft;
      }
      fnx -= cf.fa * h.normal.x; fny -= cf.fa * h.normal.y;
      fx += fnx; fy += fny;
    }
  }
  // Slots are filled from 0, so an empty slot 0 means nothing to clear.
  if (nnew > 0 || d_.wall_key[i * kWallSlots] != -1) {
    for (int q = 0; q < kWallSlots; ++q) {
      d_.wall_key[i * kWallSlots + q] = q < nnew ? new_key[q] : -1;
      d_.wall_eta[i * kWallSlots + q] = q < nnew ? new_eta[q] : 0.0;
      d_.wall_slide[i * kWallSlots + q] = q < nnew ? new_sl[q] : 0;
    }
  }
  if (touched) { d_.fx[i] += fx; d_.fy[i] += fy; d_.tq[i] += tq; }
}

// Total force and torque about the centre of mass of bodies [b0, b1) from their discs, plus gravity.
inline void Simulation::reduce_bodies(std::size_t b0, std::size_t b1) {
  const Vec2 g = params_.gravity;
  const int* first_disc = b_.first_disc.data(); const int* n_discs = b_.n_discs.data();
  const double* dfx = d_.fx.data(); const double* dfy = d_.fy.data(); const double* dtq = d_.tq.data();
  const double* wx = d_.wx.data(); const double* wy = d_.wy.data(); const double* mass = b_.mass.data();
  double* bfx = b_.fx.data(); double* bfy = b_.fy.data(); double* btq = b_.torque.data();
  for (std::size_t b = b0; b < b1; ++b) {
    const int first = first_disc[b], nd = n_discs[b];
    double fx = 0, fy = 0, tq = 0;
    for (int k = first; k < first + nd; ++k) {
      fx += dfx[k]; fy += dfy[k];
      tq += dtq[k] + wx[k] * dfy[k] - wy[k] * dfx[k];
    }
    bfx[b] = fx + mass[b] * g.x;
    bfy[b] = fy + mass[b] * g.y;
    btq[b] = tq;
  }
}

// The body forces of the external providers (serial: their code is not ours), into their
// arrays (cleared by contact_forces()' body phase, or with providers_early by step()'s drift).
void Simulation::call_providers() {
  const std::size_t np = forces_.size();
  held_.resize(np);
  for (std::size_t k = 0; k < np; ++k) {
    forces_[k]->set_running_threads(team());
    forces_[k]->set_hand_held(true);
    forces_[k]->set_body_set_version(body_set_version_);
    forces_[k]->add(b_, d_, time_, prov_fx_[k], prov_fy_[k], prov_tq_[k]);
    held_[k] = forces_[k]->held();
    forces_[k]->set_hand_held(false);  // (a direct call of add() elsewhere adds everything
    forces_[k]->set_body_set_version(0);  // and compares what it holds)
    if (held_[k].terms < 0 || held_[k].terms > BodyForce::Held::kMaxTerms)
      throw std::logic_error(fmt::format("force provider {}: {} held terms", forces_[k]->name(), held_[k].terms));
  }
}

// Bodies [b0, b1)'s provider forces added to their sums, per body in provider order: each
// provider's array value plus its held terms (stored back in its array, which outputs read).
// (Providers in the outer loop: each body still gets the same additions in the same order.)
void Simulation::add_provider_forces(std::size_t b0, std::size_t b1) {
  double* fx = b_.fx.data(); double* fy = b_.fy.data(); double* tq = b_.torque.data();
  for (std::size_t k = 0; k < forces_.size(); ++k) {
    double* px = prov_fx_[k].data(); double* py = prov_fy_[k].data(); const double* pt = prov_tq_[k].data();
    const BodyForce::Held& h = held_[k];
    if (h.terms == 0) {
      for (std::size_t b = b0; b < b1; ++b) { fx[b] += px[b]; fy[b] += py[b]; tq[b] += pt[b]; }
    } else if (h.terms == 1) {
      const double* h0x = h.fx[0]; const double* h0y = h.fy[0];
      for (std::size_t b = b0; b < b1; ++b) {
        const double sx = px[b] + h0x[b], sy = py[b] + h0y[b];
        px[b] = sx; py[b] = sy;
        fx[b] += sx; fy[b] += sy; tq[b] += pt[b];
      }
    } else {
      const double* h0x = h.fx[0]; const double* h0y = h.fy[0];
      const double* h1x = h.fx[1]; const double* h1y = h.fy[1];
      for (std::size_t b = b0; b < b1; ++b) {
        const double sx = px[b] + h0x[b] + h1x[b], sy = py[b] + h0y[b] + h1y[b];
        px[b] = sx; py[b] = sy;
        fx[b] += sx; fy[b] += sy; tq[b] += pt[b];
      }
    }
  }
}

// The providers' forces after contact_forces(): the sums into the bodies (in provider order)
// and the closing half kick (kick_h > 0), per thread on its share of the bodies.
void Simulation::provider_forces(double kick_h) {
  const std::size_t nb = b_.x.size();
  if (forces_.empty()) return;
  call_providers();
  double* vx = b_.vx.data(); double* vy = b_.vy.data(); double* om = b_.omega.data();
  const double* fx = b_.fx.data(); const double* fy = b_.fy.data(); const double* tq = b_.torque.data();
  const double* im = inv_mass_.data(); const double* iI = inv_inertia_.data();
#pragma omp parallel num_threads(team())
  {
    const auto t = static_cast<std::size_t>(omp_get_thread_num()), team_size = static_cast<std::size_t>(omp_get_num_threads());
    const std::size_t b0 = nb * t / team_size, b1 = nb * (t + 1) / team_size;
    add_provider_forces(b0, b1);
    if (kick_h > 0.0)
      for (std::size_t b = b0; b < b1; ++b) {
        vx[b] += kick_h * fx[b] * im[b]; vy[b] += kick_h * fy[b] * im[b]; om[b] += kick_h * tq[b] * iI[b];
      }
  }
}

void Simulation::compute_forces() {
  list_room_ = ensure_neighbor_list(-1) ? 1 : -1;
  contact_forces();
  provider_forces(0.0);
  forces_valid_ = true;
}

// The Hamaker part (eq. 2.3.2) of each disc's force, from the present positions: the same pairs
// (listed, within r_i + r_j + reach) and wall features (within the wall's reach) that the force
// evaluation takes adhesion from, each attraction -fa along the outward normal of its surface,
// in the pair kernel's order on one thread (other thread counts sum the parts in another order:
// rounding level). The pair kernel used to sum this part into per-thread buffers at every step,
// for an output read a few times per run: at 0.8 contacts per disc that was ~4 % of bench_nip's
// step (docs/performance.md, fourteenth pass).
void Simulation::update_adhesive_parts() {
  if (!forces_valid_) {
    update_disc_positions(0, b_.x.size());
    compute_forces();  // (makes the list hold every pair in range)
  }
  prepare_walls();  // the walls' reach and rotation, as the force evaluation has them
  const std::size_t n = d_.x.size();
  std::fill(d_.fax.begin(), d_.fax.end(), 0.0);
  std::fill(d_.fay.begin(), d_.fay.end(), 0.0);
  const models::HamakerParams hp = params_.interactions[0].adhesion;
  const double L = params_.x_hi - params_.x_lo;
  if (hp.hamaker_J != 0.0 && nlist_.size() == n) {
    for (std::size_t i = 0; i < n; ++i) {
      double ax = 0.0, ay = 0.0;  // row i's own sum, added when the row ends (as the pair kernel does)
      for (int e = nlist_.row_start_[i]; e < nlist_.row_start_[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(nlist_.nbr_[e]);
        double dx = d_.x[i] - d_.x[j];
        const double dy = d_.y[i] - d_.y[j];
        if (params_.periodic_x) {  // minimum image, as the pair kernel takes it
          dx = dx > 0.5 * L ? dx - L : dx;
          dx = dx < -0.5 * L ? dx + L : dx;
        }
        const double rc = (d_.r[i] + d_.r[j]) + pair_reach_;
        const double d2 = dx * dx + dy * dy;
        if (!(d2 < rc * rc)) continue;
        const double dist = std::sqrt(d2);
        const double fa = models::hamaker_force(hp, d_.r[i], d_.r[j], dist - (d_.r[i] + d_.r[j]));
        const double inv = 1.0 / dist;
        const double nx = dx * inv, ny = dy * inv;  // from j to i
        ax -= fa * nx; ay -= fa * ny;
        d_.fax[j] += fa * nx; d_.fay[j] += fa * ny;
      }
      d_.fax[i] += ax; d_.fay[i] += ay;
    }
  }
  // each disc's walls summed apart and then added, in wall order (as wall_disc does)
  std::vector<geometry::WallHit> hits;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 c{d_.x[i], d_.y[i]};
    double ax = 0.0, ay = 0.0;
    bool any = false;
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& wall = walls_[w];
      const models::HamakerParams& wh = params_.interactions[wall.interaction].adhesion;
      const double reach = wall_reach_[w];
      if (wh.hamaker_J == 0.0 || !wall.may_touch(c, d_.r[i], reach)) continue;
      hits.clear();
      wall.query(c, d_.r[i], reach, hits);
      for (const auto& h : hits) {
        const double fa = models::hamaker_force(wh, d_.r[i], kInf, h.gap);
        ax -= fa * h.normal.x; ay -= fa * h.normal.y;
        any = true;
      }
    }
    if (any) { d_.fax[i] += ax; d_.fay[i] += ay; }
  }
}

void Simulation::step() {
  const double t_start = omp_get_wtime();
  if (!forces_valid_) {
    update_disc_positions(0, b_.x.size());
    compute_forces();
  }
  const double dt = params_.dt;
  const std::size_t nb = b_.x.size();
  const bool periodic = params_.periodic_x;
  const bool newmark = params_.integrator == Integrator::newmark_explicit;
  // The list's reference positions are only comparable if nothing was added/removed.
  const bool check_moves = !structure_changed_ && nlist_.size() == d_.x.size();
  double* x = b_.x.data(); double* y = b_.y.data(); double* vx = b_.vx.data(); double* vy = b_.vy.data();
  double* om = b_.omega.data();
  const double* fx = b_.fx.data(); const double* fy = b_.fy.data(); const double* tq = b_.torque.data();
  inv_mass_.resize(nb);
  inv_inertia_.resize(nb);
  double* inv_m = inv_mass_.data(); double* inv_I = inv_inertia_.data();
  // Per thread, on its share of the bodies: the vectorised drift (engine/kernels.hpp), the rare
  // large rotations, then placing the discs and tracking the two largest disc displacements
  // since the list was built.
  dtheta_.resize(nb);
  const detail::BodyArrays arrays{x, y, vx, vy, b_.theta.data(), om, b_.cth.data(), b_.sth.data(),
                                  fx, fy, tq, b_.mass.data(), b_.inertia.data(), inv_m, inv_I, dtheta_.data()};
  const detail::DriftParams drift{dt, newmark, periodic, params_.x_lo, params_.x_hi};
  const int nt = params_.threads;
  thread_disp_.assign(4 * nt, 0.0);
  // the per-step sublist's displacements too, if it may still be used (contact_forces())
  const bool check_sub = check_moves && sub_valid_ && sub_x0_.size() == d_.x.size();
  // The list's own check can wait while the sublist holds, if it was taken with room for its
  // margins (list_check_, set by contact_forces()): see list_room_.
  const bool check_list = check_moves && (list_check_ || !check_sub);
  const bool list_per_disc = check_list && nlist_.per_disc();
  pdisc_.resize(d_.x.size());
  if (!simple_valid_ || simple_prefix_.size() != nb + 1) update_simple();
  // Force providers that read no contact state run before the contact forces, whose pass over
  // the bodies adds their forces and kicks (BodyForce::reads_contacts): their arrays are
  // cleared here, per thread on its share of the bodies.
  const bool providers_early =
      !forces_.empty() && std::none_of(forces_.begin(), forces_.end(), [](const auto& f) { return f->reads_contacts(); });
  const std::size_t n_clear = providers_early ? forces_.size() : 0;
#pragma omp parallel num_threads(team())
  {
  const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
  const std::size_t team_size = static_cast<std::size_t>(omp_get_num_threads());
  const std::size_t b0 = nb * t / team_size, b1 = nb * (t + 1) / team_size;
  // In blocks of bodies small enough that what the drift wrote is still in L1 when the discs
  // are placed, checked and packed (one pass over memory per step instead of three).
  constexpr std::size_t kBlock = 256;
  double d1 = 0.0, d2 = 0.0, s1 = 0.0, l1 = 0.0;
  for (std::size_t c0 = b0; c0 < b1; c0 += kBlock) {
    const std::size_t c1 = std::min(b1, c0 + kBlock);
    detail::drift_bodies(drift, c0, c1, arrays);
    for (std::size_t k = 0; k < n_clear; ++k) {
      std::fill(prov_fx_[k].begin() + c0, prov_fx_[k].begin() + c1, 0.0);
      std::fill(prov_fy_[k].begin() + c0, prov_fy_[k].begin() + c1, 0.0);
      std::fill(prov_tq_[k].begin() + c0, prov_tq_[k].begin() + c1, 0.0);
    }
    // The block's discs (contiguous: bodies own consecutive discs).
    const std::size_t k0 = static_cast<std::size_t>(b_.first_disc[c0]);
    const std::size_t k1 = static_cast<std::size_t>(b_.first_disc[c1 - 1] + b_.n_discs[c1 - 1]);
    const bool simple = simple_prefix_[c1] - simple_prefix_[c0] == static_cast<int>(c1 - c0);
    for (std::size_t b = c0; b < c1; ++b)
      if (std::fabs(dtheta_[b]) > 1e-2) detail::rotate_by(b_.cth[b], b_.sth[b], dtheta_[b]);
    if (simple) {
      // One disc per body at its centre: disc k = k0 + (b - c0) sits at the body's position, its
      // offset (wx, wy) stays (0, 0); placed and packed in one loop (the same values as
      // place_body and pack_disc, whose w * wy and w * wx are w * 0.0 here).
      const double* r = d_.r.data(); const double* mass = b_.mass.data();
      double* dx = d_.x.data(); double* dy = d_.y.data();
      PackedDisc* pd = pdisc_.data();
      for (std::size_t b = c0, k = k0; b < c1; ++b, ++k) {
        const double X = x[b], Y = y[b], w = om[b];
        dx[k] = X; dy[k] = Y;
        pd[k] = {X, Y, r[k], mass[b], vx[b] - w * 0.0, vy[b] + w * 0.0, w, 0.0};
      }
    } else {
      // place_body and pack_disc in one pass: the same values (pack_disc reads back what
      // place_body wrote; a body's discs are its own), each disc's offset used while in a register.
      const double* r = d_.r.data(); const double* ox = d_.ox.data(); const double* oy = d_.oy.data();
      const double* mass = b_.mass.data(); const double* cth = b_.cth.data(); const double* sth = b_.sth.data();
      const int* first_disc = b_.first_disc.data(); const int* n_discs = b_.n_discs.data();
      double* dx = d_.x.data(); double* dy = d_.y.data(); double* dwx = d_.wx.data(); double* dwy = d_.wy.data();
      PackedDisc* pd = pdisc_.data();
      for (std::size_t b = c0; b < c1; ++b) {
        const int first = first_disc[b], nd = n_discs[b];
        const double X = x[b], Y = y[b], w = om[b], m = mass[b], u = vx[b], v = vy[b];
        if (nd == 1 && ox[first] == 0.0 && oy[first] == 0.0) {
          dx[first] = X; dy[first] = Y; dwx[first] = 0.0; dwy[first] = 0.0;
          pd[first] = {X, Y, r[first], m, u - w * 0.0, v + w * 0.0, w, 0.0};
          continue;
        }
        const double c = cth[b], sn = sth[b];
        for (int k = first; k < first + nd; ++k) {
          const double wx = c * ox[k] - sn * oy[k];
          const double wy = sn * ox[k] + c * oy[k];
          const double px = X + wx, py = Y + wy;
          dwx[k] = wx; dwy[k] = wy;
          dx[k] = px; dy[k] = py;
          pd[k] = {px, py, r[k], m, u - w * wy, v + w * wx, w, 0.0};
        }
      }
    }
    if (check_list && !list_per_disc)
      for (std::size_t k = k0; k < k1; ++k) geometry::NeighborList::top2(nlist_.displacement2(k, d_.x[k], d_.y[k]), d1, d2);
    // The sublist's largest displacement, in a loop without branches, and the pair kernel's
    // copy of the discs, which contact_forces() then need not make in a pass (and a barrier)
    // of its own.
    const double L = params_.x_hi - params_.x_lo;
    if (list_per_disc) {  // displacements relative to each disc's own skin (in a loop without branches)
      const double m = detail::max_weighted_displacement2(d_.x.data(), d_.y.data(), nlist_.x0(), nlist_.y0(),
                                                          nlist_.inv_skin2(), k0, k1, periodic, L);
      l1 = m > l1 || m != m ? m : l1;
    }
    if (check_sub) {
      const double m = sub_per_disc_ ? detail::max_weighted_displacement2(d_.x.data(), d_.y.data(), sub_x0_.data(),
                                                                          sub_y0_.data(), sub_w_.data(), k0, k1, periodic, L)
                                     : detail::max_displacement2(d_.x.data(), d_.y.data(), sub_x0_.data(),
                                                                 sub_y0_.data(), k0, k1, periodic, L);
      s1 = m > s1 || m != m ? m : s1;  // (NaN wins)
    }
  }
  thread_disp_[4 * t] = d1;
  thread_disp_[4 * t + 1] = d2;
  thread_disp_[4 * t + 2] = s1;
  thread_disp_[4 * t + 3] = l1;
  }
  int moved = 0;
  list_room_ = -1;
  if (check_moves) {
    double d1 = 0.0, d2 = 0.0, l1 = 0.0;
    double s1 = 0.0;
    auto fold = [](double v, double& m) { m = v > m || v != v ? v : m; };  // (NaN wins)
    for (int t = 0; t < nt; ++t) {
      geometry::NeighborList::top2(thread_disp_[4 * t], d1, d2);
      geometry::NeighborList::top2(thread_disp_[4 * t + 1], d1, d2);
      fold(thread_disp_[4 * t + 2], s1);
      fold(thread_disp_[4 * t + 3], l1);
    }
    if (check_sub) sub_moved_ = sub_exceeds(s1) ? 1 : 0;
    for (auto& w : walls_) w.advance(dt);
    // The sublist is to be taken again (discs moved, or a rough roller turned): the list is
    // judged now if its check waited.
    bool list_known = check_list;
    if (!check_list && (sub_moved_ == 1 || (!walls_.empty() && !walls_within_margin()))) {
      list_displacements(d1, d2, l1);
      list_known = true;
    }
    if (list_known) {
      const double room = 1.0 - params_.inner_skin_fraction;
      if (nlist_.per_disc()) {
        moved = !(l1 <= 1.0) ? 1 : 0;
        list_room_ = l1 <= 0.99 * room * 0.99 * room ? 1 : 0;
      } else {
        moved = nlist_.exceeds(d1, d2) ? 1 : 0;
        list_room_ = std::sqrt(d1) + std::sqrt(d2) + params_.inner_skin_fraction * params_.skin <= 0.99 * params_.skin ? 1 : 0;
      }
    }
  } else {
    for (auto& w : walls_) w.advance(dt);
  }
  time_ += dt;
  ++step_;
  if (ensure_neighbor_list(check_moves ? moved : -1)) list_room_ = 1;  // (built now: nothing moved yet)
  // The closing half kick runs where the body forces are complete: without force providers, or
  // with providers that read no contact state (called first), in contact_forces()' region; else
  // in provider_forces()' loop that adds their forces (the same operations each way).
  const double kick_h = newmark ? 0.0 : 0.5 * dt;
  if (forces_.empty()) {
    contact_forces(kick_h, true);
  } else if (providers_early) {
    call_providers();
    contact_forces(kick_h, true, true);
  } else {
    contact_forces(0.0, true);
    provider_forces(kick_h);
  }
  forces_valid_ = true;
  tuner_.step_done(omp_get_wtime() - t_start);
}

Energy Simulation::energy() const {
  Energy e;
  for (std::size_t b = 0; b < b_.x.size(); ++b) {
    e.kinetic += 0.5 * b_.mass[b] * (b_.vx[b] * b_.vx[b] + b_.vy[b] * b_.vy[b]) + 0.5 * b_.inertia[b] * b_.omega[b] * b_.omega[b];
    e.gravity -= b_.mass[b] * (params_.gravity.x * b_.x[b] + params_.gravity.y * b_.y[b]);
  }
  const auto& cp = params_.interactions[0].contact;
  const double L = params_.x_hi - params_.x_lo;
  for (std::size_t i = 0; i + 1 < nlist_.row_start_.size(); ++i) {
    for (int k = nlist_.row_start_[i]; k < nlist_.row_start_[i + 1]; ++k) {
      const int j = nlist_.nbr_[k];
      double dx = d_.x[i] - d_.x[j];
      if (params_.periodic_x) dx -= L * std::nearbyint(dx / L);
      const double dy = d_.y[i] - d_.y[j];
      const double ov = d_.r[i] + d_.r[j] - std::sqrt(dx * dx + dy * dy);
      e.elastic += models::contact_energy(cp, ov, nlist_.eta_[k]);
    }
  }
  std::vector<geometry::WallHit> hits;
  for (std::size_t i = 0; i < d_.x.size(); ++i) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      hits.clear();
      walls_[w].query({d_.x[i], d_.y[i]}, d_.r[i], 0.0, hits);
      const auto& wc = params_.interactions[walls_[w].interaction].contact;
      for (auto& h : hits) {
        if (h.gap >= 0) continue;
        const std::int64_t key = (static_cast<std::int64_t>(w) << 40) | h.key;
        double eta = 0.0;  // a contact beyond the history slots has none
        for (int q = 0; q < kWallSlots; ++q)
          if (d_.wall_key[i * kWallSlots + q] == key) eta = d_.wall_eta[i * kWallSlots + q];
        e.elastic += models::contact_energy(wc, -h.gap, eta);
      }
    }
  }
  return e;
}

// Simulation::save / load: engine/checkpoint.cpp

}  // namespace nipdem::engine
