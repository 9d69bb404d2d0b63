#include "nipdem/nip/nip.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "nipdem/core/binary_io.hpp"
#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_forces.hpp"
#include "nipdem/io/checkpoint_file.hpp"
#include "nipdem/geometry/walls.hpp"

namespace nipdem::nip {

using constants::pi;

namespace {
// Random sequential addition stops after this many consecutive failed attempts: the pits are
// then full to within a few per cent of the jammed fill (docs/geometry.md, "Filled pits").
constexpr int kPitFillFailures = 400;
// Strip width of the spatial body order [d50]: a few particles, so that a disc's neighbours lie
// within a few strips (bench_nip: 1-3 d50 equal within noise, docs/performance.md ninth pass).
constexpr double kSortStripD50 = 3.0;
}  // namespace

ReachableRegion reachable_region(const NipConfig& c) {
  return {c.x_min, c.x_max, {c.nip_x, -c.roller_radius}, {c.nip_x, c.gap + c.drum_radius}, c.roller_radius, c.drum_radius,
          c.roughness ? c.rough_height : 0.0};
}

Vec2 NipRun::drum_centre() const { return reachable_region(cfg_).drum_centre; }
Vec2 NipRun::roller_centre() const { return reachable_region(cfg_).roller_centre; }
double NipRun::drum_surface_y(double x) const {
  const double dx = x - cfg_.nip_x;
  return drum_centre().y - std::sqrt(cfg_.drum_radius * cfg_.drum_radius - dx * dx);
}
double NipRun::roller_surface_y(double x) const {
  const double dx = x - cfg_.nip_x;
  return roller_centre().y + std::sqrt(cfg_.roller_radius * cfg_.roller_radius - dx * dx);
}

NipRun::NipRun(NipConfig cfg) : cfg_(std::move(cfg)), ts_(choose_time_step(cfg_)), rng_(cfg_.seed) {
  tmpl_ = &find_template(cfg_.templates, cfg_.cluster, cfg_.file, "toner.cluster");
  engine::EngineParams p;
  p.integrator = cfg_.integrator;
  p.dt = ts_.dt;
  p.gravity = cfg_.gravity;
  p.interactions = make_interactions(cfg_);
  p.skin = cfg_.list_skin_d50 * cfg_.size.d50;
  p.threads = cfg_.threads;

  // Both rollers turn clockwise: the roller's top moves towards +x, the drum's bottom towards -x.
  auto cylinder = [](const char* name, Vec2 centre, double radius, double surface_speed, int interaction) {
    geometry::Wall w;
    w.kind = geometry::Wall::Kind::cylinder;
    w.name = name;
    w.centre = centre;
    w.radius = radius;
    w.omega = -surface_speed / radius;
    w.interaction = interaction;
    return w;
  };
  geometry::Wall roller = cylinder("imaging_roller", roller_centre(), cfg_.roller_radius, cfg_.roller_speed, 1);
  if (cfg_.roughness && cfg_.rough_height > 0.0) geometry::set_pyramid_roughness(roller, cfg_.rough_height, cfg_.rough_base, cfg_.rough_spacing);
  geometry::Wall drum = cylinder("di_drum", drum_centre(), cfg_.drum_radius, cfg_.drum_speed, 2);
  sim_ = std::make_unique<engine::Simulation>(p, std::vector<geometry::Wall>{roller, drum});
  cfg_.magnet.threads = cfg_.threads;
  if (auto field = make_magnet_field(cfg_.magnet)) {
    // the field must be valid wherever a toner centre can go (refused at setup, not mid-run)
    check_field_region(*field, reachable_region(cfg_), fmt::format("{} (magnet.field = \"{}\")", cfg_.file.empty() ? "config" : cfg_.file, cfg_.magnet.field));
    magnet_ = std::make_shared<MagnetForce>(field, cfg_.magnet);
    sim_->add_force(magnet_);
  }
  if (cfg_.electric.enabled) {
    electric_ = std::make_shared<ElectricForce>(sim_.get(), cfg_.electric);
    sim_->add_force(electric_);
  }
  // The sleeve's pits are part of its state, independent of the drum layer's prefill.
  if (cfg_.roller_pits_filled) fill_pits_entering(true);
  if (cfg_.prefill) prefill();
  if (cfg_.assembly.enabled) {
    const auto& a = cfg_.assembly;
    fill_on_roller(a.x_min, a.x_max, 0.0, a.height > 0.0 ? a.height : 1.0, a.area_fraction);  // 1 m: up to the drum
  }
}

bool NipRun::place(engine::BodySpec spec, Vec2 pos, double angle, Vec2 velocity, double omega) {
  // member centres about the mass centre (the engine recentres the offsets the same way)
  double m = 0;
  Vec2 com{};
  for (std::size_t k = 0; k < spec.radii.size(); ++k) {
    const double mk = std::pow(spec.radii[k], 3);
    m += mk;
    com += mk * spec.offsets[k];
  }
  com /= m;
  std::vector<Vec2> pts;
  double extent = 0.0;
  for (std::size_t k = 0; k < spec.offsets.size(); ++k) {
    pts.push_back(pos + rotate(spec.offsets[k] - com, angle));
    extent = std::max(extent, norm(spec.offsets[k] - com) + spec.radii[k]);
  }
  // overlap with the drum and the roller (its real surface, pits included)
  const auto& roller = sim_->walls()[0];
  thread_local std::vector<geometry::WallHit> hits;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (norm(pts[k] - drum_centre()) < cfg_.drum_radius + spec.radii[k]) return false;
    if (norm(pts[k] - roller.centre) < roller.surface_radius(pts[k])) return false;  // centre inside the sleeve
    hits.clear();
    roller.query(pts[k], spec.radii[k], 0.0, hits);
    for (const auto& h : hits)
      if (h.gap < 0.0) return false;
  }
  const auto& dd = sim_->discs();
  const double reach = 2.0 * extent + cfg_.size.d_max();
  for (std::size_t i = 0; i < dd.x.size(); ++i) {
    if (std::fabs(dd.x[i] - pos.x) > reach || std::fabs(dd.y[i] - pos.y) > reach) continue;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double rr = dd.r[i] + spec.radii[k];
      const double dx = dd.x[i] - pts[k].x, dy = dd.y[i] - pts[k].y;
      if (dx * dx + dy * dy < rr * rr) return false;
    }
  }
  spec.position = pos;
  spec.angle = angle;
  spec.velocity = velocity;
  spec.omega = omega;
  spec.tag = 0;
  sim_->add_body(spec);
  ++inserted_;
  return true;
}

NipRun::Draw NipRun::draw_toner() {
  const double d = cfg_.size.sample(rng_);
  Draw t{make_toner(*tmpl_, d, cfg_.density), rng_.uniform(0.0, 2.0 * pi), 0.0};
  for (std::size_t k = 0; k < t.spec.radii.size(); ++k) t.extent = std::max(t.extent, norm(t.spec.offsets[k]) + t.spec.radii[k]);
  return t;
}

bool NipRun::try_insert(double x_lo, double x_hi) {
  auto [spec, angle, extent] = draw_toner();
  const double x = rng_.uniform(x_lo, x_hi);
  // within the layer under the drum surface, not touching it
  const double ytop = drum_surface_y(x) - extent - 1e-8;
  const double ybot = std::max(drum_surface_y(x) - cfg_.layer_thickness + extent, roller_surface_y(x) + extent + 1e-8);
  if (ytop < ybot) return false;
  const Vec2 pos{x, rng_.uniform(ybot, ytop)};
  // moving with the drum surface (rigid rotation about the drum axis)
  const auto& drum = sim_->walls()[1];
  return place(spec, pos, angle, cross(drum.omega, pos - drum.centre), drum.omega);
}

bool NipRun::try_insert_on_roller(double x_lo, double x_hi, double h_lo, double h_hi) {
  auto [spec, angle, extent] = draw_toner();
  const double x = rng_.uniform(x_lo, x_hi);
  const double ybot = roller_surface_y(x) + std::max(h_lo, 0.0) + extent + 1e-8;
  const double ytop = std::min(roller_surface_y(x) + h_hi - extent, drum_surface_y(x) - extent - 1e-8);
  if (ytop < ybot) return false;
  return place(spec, {x, rng_.uniform(ybot, ytop)}, angle, {0.0, 0.0}, 0.0);
}

int NipRun::fill_pits(double x_lo, double x_hi, int max_failures) {
  if (!cfg_.roughness || !(cfg_.rough_height > 0.0) || !(x_hi > x_lo)) return 0;
  const auto& roller = sim_->walls()[0];
  int n = 0, failures = 0;
  while (failures < max_failures) {
    Draw t = draw_toner();
    const double x = rng_.uniform(x_lo, x_hi);
    const double y0 = roller_surface_y(x);
    const Vec2 pos{x, rng_.uniform(y0 - cfg_.rough_height, y0)};
    // centre below the land level and in the open part of a pit; moving with the sleeve
    if (norm(pos - roller.centre) > roller.surface_radius(pos) &&
        place(t.spec, pos, t.angle, cross(roller.omega, pos - roller.centre), roller.omega)) {
      ++n;
      failures = 0;
    } else {
      ++failures;
    }
  }
  return n;
}

int NipRun::fill_pits_entering(bool whole_window) {
  if (!cfg_.roughness || !(cfg_.rough_height > 0.0)) return 0;
  const auto& w = sim_->walls()[0];
  const double P = w.period();
  const double L = w.profile[1].x, Bw = w.profile[3].x - w.profile[1].x;
  // period index of the material under x (s grows counter-clockwise, i.e. towards -x on top)
  auto index_at = [&](double x) {
    const Vec2 d = Vec2{x, roller_surface_y(x)} - w.centre;
    double s = (std::atan2(d.y, d.x) - w.angle) * w.radius - w.phase;
    return static_cast<int>(std::floor(s / P));
  };
  // x of the pit's upstream edge (its largest s, lowest x) now and one pass earlier
  const double back = w.omega * ts_.dt * cfg_.insert_interval;  // rotation over one pass
  auto edge_x = [&](int k, double extra_angle) {
    const double phi = (k * P + L + Bw + w.phase) / w.radius + w.angle - extra_angle;
    return w.centre.x + w.radius * std::cos(phi);
  };
  int added = 0;
  const int k_lo = index_at(cfg_.x_max) - 1, k_hi = index_at(cfg_.x_min) + 1;
  for (int k = k_lo; k <= k_hi; ++k) {
    const double x_left = edge_x(k, 0.0);
    const double x_right = w.centre.x + w.radius * std::cos((k * P + L + w.phase) / w.radius + w.angle);
    // at the start: every pit (part) in the window; later: the pit whose upstream edge
    // crossed x_min during the last pass (exactly once per pit, no bookkeeping needed)
    const bool entering = x_left >= cfg_.x_min && edge_x(k, back) < cfg_.x_min;
    if (!(whole_window || entering)) continue;
    const double lo = std::max(x_left, cfg_.x_min), hi = std::min(x_right, cfg_.x_max);
    if (hi > lo) added += fill_pits(lo, hi, kPitFillFailures);
  }
  return added;
}

int NipRun::fill_on_roller(double x0, double x1, double h0, double h1, double area_fraction) {
  // area of the region, clipped by the drum (the local gap grows away from the nip)
  double area = 0.0;
  constexpr int kSamples = 200;
  for (int k = 0; k < kSamples; ++k) {
    const double x = x0 + (k + 0.5) * (x1 - x0) / kSamples;
    area += std::max(0.0, std::min(h1, drum_surface_y(x) - roller_surface_y(x)) - h0) * (x1 - x0) / kSamples;
  }
  area *= area_fraction;
  int n = 0, failures = 0;
  while (area > 0.0 && failures < 20000) {
    if (try_insert_on_roller(x0, x1, h0, h1)) {
      const double d = sim_->bodies().size.back();
      area -= pi * d * d / 4.0;
      ++n;
    } else {
      ++failures;
    }
  }
  return n;
}

std::vector<double> NipRun::assembly_x(double max_height, double min_height) const {
  std::vector<double> xs;
  const auto& b = sim_->bodies();
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    if (b.x[i] < cfg_.x_min || b.x[i] > cfg_.x_max) continue;
    const double h = b.y[i] - roller_surface_y(b.x[i]);
    if (h < max_height && h > min_height) xs.push_back(b.x[i]);
  }
  return xs;
}

void NipRun::prefill() {
  // Fill the layer over the whole window at the target area fraction.
  const double width = cfg_.x_max - cfg_.x_min;
  double area = cfg_.layer_thickness * cfg_.area_fraction * width;
  const double a50 = pi * cfg_.size.d50 * cfg_.size.d50 / 4.0;
  int failures = 0;
  while (area > 0.5 * a50 && failures < 20000) {
    if (try_insert(cfg_.x_min, cfg_.x_max)) {
      const double d = sim_->bodies().size.back();
      area -= pi * d * d / 4.0;
    } else {
      ++failures;
    }
  }
}

void NipRun::exchange() {
  auto& b = sim_->bodies();
  const double t = sim_->time();
  // Outflow: bodies whose centre of mass left the window, classified by the nearer surface.
  const Vec2 cd = drum_centre(), cr = roller_centre();
  const double rough = cfg_.roughness ? cfg_.rough_height : 0.0;
  const auto inserted0 = inserted_, inserted_roller0 = inserted_roller_;
  const std::size_t removed = sim_->remove_bodies_if([&](int i) {
    const Vec2 p{b.x[i], b.y[i]};
    const double gd = norm(p - cd) - cfg_.drum_radius;
    const double gr = norm(p - cr) - cfg_.roller_radius;
    const bool escaped = gd < -0.5 * cfg_.size.d50 || gr < -rough - 0.5 * cfg_.size.d50 || !std::isfinite(p.x) || !std::isfinite(p.y);
    const bool outside = p.x < cfg_.x_min || p.x > cfg_.x_max;
    if (!escaped && !outside) return false;
    // Developed: left downstream (x < x_min, the drum's direction of travel) nearer the drum.
    // Everything else that leaves the window goes back towards the supply roller.
    const Exit e = escaped ? Exit::lost : (p.x < cfg_.x_min && gd < gr ? Exit::developed : Exit::returned);
    removals_.push_back({t, e, p.x, p.y, b.size[i], b.id[i]});
    ++removed_[static_cast<int>(e)];
    return true;
  });
  // Inflow: area flux layer_thickness * area_fraction * drum speed through x_max.
  area_debt_ += cfg_.layer_thickness * cfg_.area_fraction * std::fabs(cfg_.drum_speed) * ts_.dt * cfg_.insert_interval;
  const double zone = std::max(2.0 * cfg_.size.d_max(), std::fabs(cfg_.drum_speed) * ts_.dt * cfg_.insert_interval * 2.0);
  int attempts = 0;
  while (area_debt_ > 0.0 && attempts < 200) {
    ++attempts;
    if (try_insert(cfg_.x_max - zone, cfg_.x_max - 0.5 * cfg_.size.d_max())) {
      const double d = b.size.back();
      area_debt_ -= pi * d * d / 4.0;
    }
  }
  // A full zone leaves the debt to the next pass; do not let it grow without bound.
  area_debt_ = std::min(area_debt_, 10.0 * pi * cfg_.size.d_max() * cfg_.size.d_max());
  // The sleeve brings its filled pits in through x_min (it moves towards +x).
  if (cfg_.roller_pits_filled) inserted_roller_ += fill_pits_entering(false);
  // A changed body set is put in spatial order (the providers start afresh on a changed set
  // anyway): inflow appends at the end, so without it neighbours drift apart in memory and the
  // pair loops and the thread split slow down (docs/performance.md, ninth pass).
  if (removed > 0 || inserted_ != inserted0 || inserted_roller_ != inserted_roller0)
    sim_->sort_bodies_spatially(kSortStripD50 * cfg_.size.d50);
}

void NipRun::advance_to(double t_end, const std::function<void()>& on_interval) {
  while (sim_->time() < t_end - 0.5 * ts_.dt) {
    const std::int64_t n = std::min<std::int64_t>(cfg_.insert_interval - sim_->step_count() % cfg_.insert_interval,
                                                   static_cast<std::int64_t>(std::ceil((t_end - sim_->time()) / ts_.dt - 0.5)));
    for (std::int64_t i = 0; i < n; ++i) sim_->step();
    if (sim_->step_count() % cfg_.insert_interval == 0) exchange();
    if (on_interval) on_interval();
  }
}

// ---- checkpoint: runner state, then the engine's, in the checksummed frame of io/checkpoint_file.hpp
// (docs/reliability.md). Payload: "NIPDEMRUN4", resume and prefix keys, rng, counters, removals,
// engine. Every field is written on its own (no struct padding): the bytes are a function of the
// state, so two identical runs write identical files.
namespace {
constexpr char kRunTag[] = "NIPDEMRUN4";
constexpr std::size_t kRunTagLen = 10;
}  // namespace

std::string NipRun::checkpoint() const {
  std::ostringstream o;
  o.write(kRunTag, kRunTagLen);
  binary::put(o, static_cast<std::uint64_t>(std::hash<std::string>{}(cfg_.resume_key)));
  binary::put(o, static_cast<std::uint64_t>(std::hash<std::string>{}(cfg_.prefix_key)));
  for (int i = 0; i < 4; ++i) binary::put(o, rng_.state()[i]);
  binary::put(o, inserted_);
  binary::put(o, inserted_roller_);
  for (auto r : removed_) binary::put(o, r);
  binary::put(o, area_debt_);
  binary::put(o, static_cast<std::uint64_t>(removals_.size()));
  for (const auto& e : removals_) {
    binary::put(o, e.time);
    binary::put(o, static_cast<std::int32_t>(e.where));
    binary::put(o, e.x);
    binary::put(o, e.y);
    binary::put(o, e.size);
    binary::put(o, e.id);
  }
  sim_->save(o);
  return io::seal_checkpoint(o.str());
}

namespace {
struct CheckpointHeader { std::uint64_t resume_hash = 0, prefix_hash = 0; };
// Opens the frame and reads the run header; `in` is left at the runner state.
CheckpointHeader read_checkpoint_header(std::istringstream& in, const std::string& blob, const std::string& where) {
  const std::string_view payload = io::open_checkpoint(blob, where);
  if (payload.substr(0, kRunTagLen) != std::string_view(kRunTag, kRunTagLen))
    throw InputError(where + ": not a nipdem run checkpoint (payload tag is not " + kRunTag + ")");
  in.str(std::string(payload.substr(kRunTagLen)));
  CheckpointHeader h;
  try {
    binary::get(in, h.resume_hash);
    binary::get(in, h.prefix_hash);
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
  return h;
}
}  // namespace

void NipRun::restore(const std::string& blob, const std::string& where) {
  std::istringstream in;
  const auto h = read_checkpoint_header(in, blob, where);
  if (h.resume_hash != std::hash<std::string>{}(cfg_.resume_key))
    throw InputError(where + ": checkpoint was written with a different configuration; --resume needs the same config and --set options (only run.end_time_s and the output intervals may change)");
  restore_state(in, where);
}

void NipRun::restore_state(std::istream& in, const std::string& where) {
  try {
    auto bad = [](const std::string& what) { throw InputError("run state: " + what); };
    std::uint64_t st[4];
    for (auto& v : st) binary::get(in, v);
    if ((st[0] | st[1] | st[2] | st[3]) == 0) bad("random generator state is all zero");
    std::int64_t inserted, inserted_roller, removed[3];
    double area_debt;
    binary::get(in, inserted);
    binary::get(in, inserted_roller);
    for (auto& r : removed) binary::get(in, r);
    binary::get(in, area_debt);
    constexpr std::int64_t kMaxCount = std::int64_t{1} << 50;  // far above any run; their sum cannot overflow
    for (const std::int64_t c : {inserted, inserted_roller, removed[0], removed[1], removed[2]})
      if (c < 0 || c > kMaxCount) bad(fmt::format("a particle counter ({}) is outside [0, 2^50]", c));
    if (!std::isfinite(area_debt)) bad(fmt::format("inflow area debt {} is not finite", area_debt));
    std::uint64_t n;
    binary::get(in, n);
    const std::uint64_t total = static_cast<std::uint64_t>(removed[0] + removed[1] + removed[2]);
    if (n != total) bad(fmt::format("{} removal events, the counters say {}", n, total));
    std::vector<RemovalEvent> removals;
    for (std::uint64_t k = 0; k < n; ++k) {
      RemovalEvent e{};
      std::int32_t where_i;
      binary::get(in, e.time);
      binary::get(in, where_i);
      binary::get(in, e.x);
      binary::get(in, e.y);
      binary::get(in, e.size);
      binary::get(in, e.id);
      if (where_i < 0 || where_i > 2) bad(fmt::format("removal {}: exit {} is not developed/returned/lost", k, where_i));
      if (!std::isfinite(e.time) || !(e.size >= 0.0) || !std::isfinite(e.size) || e.id < 0)
        bad(fmt::format("removal {}: time, size or id out of range", k));
      e.where = static_cast<Exit>(where_i);
      removals.push_back(e);
    }
    sim_->load(in);
    if (in.peek() != std::char_traits<char>::eof()) bad("data after the end of the state (the payload is longer than what this build writes)");
    rng_.set_state(st);
    inserted_ = inserted;
    inserted_roller_ = inserted_roller;
    for (int i = 0; i < 3; ++i) removed_[i] = removed[i];
    area_debt_ = area_debt;
    removals_ = std::move(removals);
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
}

double NipRun::first_print_switch_time() const {
  if (!cfg_.electric.enabled || cfg_.drum_speed == 0.0) return std::numeric_limits<double>::infinity();
  const auto& pat = cfg_.electric.pattern;
  // the track position s = v t sweeps from 0 towards the sign of v
  double first = std::numeric_limits<double>::infinity();
  for (const auto& seg : pat.segments()) {
    if (seg.voltage_V == pat.off_voltage()) continue;
    const double s = cfg_.drum_speed > 0 ? seg.begin_m : -seg.end_m;
    if (s <= 0.0) return 0.0;
    first = std::min(first, s / std::fabs(cfg_.drum_speed));
  }
  return first;
}

void NipRun::restore_before_print_switch(const std::string& blob, const std::string& where) {
  std::istringstream in;
  const auto h = read_checkpoint_header(in, blob, where);
  if (h.prefix_hash != std::hash<std::string>{}(cfg_.prefix_key))
    throw InputError(where + ": prefix checkpoint was written with a configuration that differs in more than print.voltage_V");
  restore_state(in, where);
  const double t_on = first_print_switch_time();
  if (!(sim_->time() + ts_.dt <= t_on))
    throw InputError(fmt::format("prefix checkpoint at t = {:g} s is not before the drum track first switches on (t = {:g} s)", sim_->time(), t_on));
}

nlohmann::json NipRun::describe() const {
  const auto& w = sim_->walls();
  nlohmann::json prof = nlohmann::json::array();
  for (auto& p : w[0].profile) prof.push_back({p.x, p.y});
  return {
      {"drum", {{"centre_m", {w[1].centre.x, w[1].centre.y}}, {"radius_m", w[1].radius}, {"omega_rad_per_s", w[1].omega}}},
      {"roller",
       {{"centre_m", {w[0].centre.x, w[0].centre.y}},
        {"radius_m", w[0].radius},
        {"omega_rad_per_s", w[0].omega},
        {"profile_s_depth_m", prof},
        {"n_periods", w[0].n_periods},
        {"phase_m", w[0].phase}}},
      {"window_x_m", {cfg_.x_min, cfg_.x_max}},
      {"gap_m", cfg_.gap},
  };
}

std::vector<NipRun::CoverageBin> NipRun::coverage(double bin) const {
  std::vector<CoverageBin> out;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& e : removals_) {
    if (e.where != Exit::developed) continue;
    const double s = drum_position(e.time, e.x);
    lo = std::min(lo, s - e.size / 2);
    hi = std::max(hi, s + e.size / 2);
  }
  // the pattern's segments define the region of interest as well
  for (const auto& seg : cfg_.electric.pattern.segments()) { lo = std::min(lo, seg.begin_m); hi = std::max(hi, seg.end_m); }
  if (!(hi > lo)) return out;
  lo = std::floor(lo / bin) * bin - 5 * bin;
  hi = std::ceil(hi / bin) * bin + 5 * bin;
  const int n = static_cast<int>(std::lround((hi - lo) / bin));
  for (int k = 0; k < n; ++k) out.push_back({lo + k * bin, lo + (k + 1) * bin, 0, false});
  for (const auto& e : removals_) {
    if (e.where != Exit::developed) continue;
    const double s = drum_position(e.time, e.x);
    // a particle covers every bin its diameter overlaps (presence = 100 %, §5.3)
    const int k0 = std::max(0, static_cast<int>(std::floor((s - e.size / 2 - lo) / bin)));
    const int k1 = std::min(n - 1, static_cast<int>(std::floor((s + e.size / 2 - lo) / bin)));
    for (int k = k0; k <= k1; ++k) out[k].covered = true;
    const int kc = static_cast<int>(std::floor((s - lo) / bin));
    if (kc >= 0 && kc < n) ++out[kc].particles;
  }
  return out;
}

}  // namespace nipdem::nip
