// bench_nip: macro benchmark of the full nip (preset "black": real stiffness, tri3 toner,
// rough imaging roller, drum, Hamaker adhesion, inflow/outflow) with ~10,000 particles in a
// wide window. Runs the same configuration without the magnet (magnet.field = "none") and
// with it (analytic knife + dipole-dipole), alternating, from the same starting state, and
// reports disc-steps/s, wall time per simulated ms, peak memory and the magnet's cost.
//
// Starting states (--state):
//   dense (default): the prefilled layer pressed onto the roller and settled before timing
//       (untimed, see make_dense_state): held by the knife, toner-toner coordination ~0.6 per
//       disc and ~1.3 per tri3 particle (measured at half-width 6.3 mm).
//   loose: the prefilled layer as inserted (area fraction 0.5, ~0 contacts): the old benchmark.
// On the dense state the fair magnet cost is its share inside the magnet run (stopwatch around
// the provider): without the magnet that assembly falls apart (bench/README.md).
//
// Usage: bench_nip [--steps N=2000] [--settle N] [--threads T=1] [--run-threads R=0] [--half-width M=2.6e-3]
//                  [--state dense|loose] [--dense-file FILE] [--repeat R=1]
//                  [--press-time S=2e-4] [--relax-steps N=4000] [--dipole-skin M (default magnet.dipole_skin_m, 8e-6)]
//                  [--inner-skin F (EngineParams::inner_skin_fraction, speed only)]
//                  [--skin-quantile Q (EngineParams::skin_speed_quantile, speed only; 0: one skin for all)]
//                  [--sort-cell M (0: the state's own order)] [--set key=value ...]   (extra config overrides, as `nipdem run --set`)
// --sort-cell M adds the start state's bodies in spatial order (strips M wide in x, by y within a
// strip) instead of the order they were made in: what memory locality is worth (bench/README.md,
// eighth pass). Since 4260d29 the nip sorts the bodies itself after each inflow/outflow pass that
// changed the set (every 200 steps), so this matters only before the first pass.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "bench_args.hpp"
#include "nipdem/core/wait_policy.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/nip/nip_forces.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/nip/toner.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;

namespace {

struct Result {
  std::size_t bodies = 0, discs = 0;
  double wall_s = 0, cpu_s = 0, sim_s = 0, dt = 0, rate = 0, contacts_per_disc = 0;
  double z_disc = 0, z_body = 0;  // coordination numbers (toner-toner contacts counted at both ends)
  double magnet_s = 0;            // wall time inside the magnet provider during the timed steps
  int dipole_builds = 0;          // dipole pair-list builds during the timed steps
  std::size_t dipole_pairs = 0;   // listed dipole pairs (r < r_c + skin) at the end
  int builds = 0;
  int sublist_takes = 0;          // the pair kernel's per-step sublist taken (EngineParams::inner_skin_fraction)
  std::size_t listed_pairs = 0;   // pairs in the contact list at the end
  long long cross_entries = 0;    // of those, partners in a later part than their row (Simulation::pair_cross_entries)
  long maxrss_kb = 0;
  int threads_running = 1, thread_switches = 0;  // the engine's thread choice at the end (engine/team_tuner.hpp)
};

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

long maxrss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;  // kilobytes on Linux
}

// Error of the tabulated magnet force: the provider's own table (MagnetForce::field_sample, the
// 20 um bicubic Hermite tiles with exact cells next to magnet faces) against the exact field at
// the particle positions. The bound it promises is 2e-3 (docs/magnetic.md "Field tables").
void report_table_error(const engine::Simulation& sim, const nip::MagnetConfig& mc) {
  const auto field = nip::make_magnet_field(mc);
  if (!field) return;
  nip::MagnetForce table(field, mc);
  const auto& b = sim.bodies();
  double max_rel = 0, sum2 = 0, fmax = 0, max_abs = 0;
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    const double R = 0.5 * b.size[i];
    const Vec2 fe = magnet::induced_dipole_force(mc.toner, R, field->at({b.x[i], b.y[i]}));
    const Vec2 fm = magnet::induced_dipole_force(mc.toner, R, table.field_sample({b.x[i], b.y[i]}));
    const double e = norm(fm - fe), f = norm(fe);
    fmax = std::max(fmax, f);
    max_abs = std::max(max_abs, e);
    if (f > 0) { max_rel = std::max(max_rel, e / f); sum2 += (e / f) * (e / f); }
  }
  std::printf("  tabulated magnet force (provider's table) vs exact at %zu particles: max relative error %.2e, "
              "rms %.2e, max abs error / max force %.2e\n",
              b.x.size(), max_rel, std::sqrt(sum2 / static_cast<double>(b.x.size())), max_abs / std::max(fmax, 1e-300));
}

// Coordination numbers from the disc-disc contacts (overlap > 0) in the neighbour list: per
// disc (2 x contacting disc pairs / discs, as LAMMPS compute contact/atom) and per body
// (2 x distinct touching body pairs / bodies). Wall contacts are not included.
void coordination(const engine::Simulation& sim, double& z_disc, double& z_body) {
  const auto& d = sim.discs();
  const auto& nl = sim.neighbor_list();
  std::size_t pairs = 0;
  std::vector<std::pair<int, int>> bp;
  for (std::size_t i = 0; i + 1 < nl.row_start_.size() && i < d.x.size(); ++i)
    for (int e = nl.row_start_[i]; e < nl.row_start_[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(nl.nbr_[static_cast<std::size_t>(e)]);
      const double dx = d.x[i] - d.x[j], dy = d.y[i] - d.y[j], rs = d.r[i] + d.r[j];
      if (dx * dx + dy * dy < rs * rs) {
        ++pairs;
        bp.emplace_back(std::min(d.body[i], d.body[j]), std::max(d.body[i], d.body[j]));
      }
    }
  std::sort(bp.begin(), bp.end());
  const auto nbp = static_cast<std::size_t>(std::unique(bp.begin(), bp.end()) - bp.begin());
  z_disc = 2.0 * static_cast<double>(pairs) / static_cast<double>(d.x.size());
  z_body = 2.0 * static_cast<double>(nbp) / static_cast<double>(sim.bodies().x.size());
}

// The nip's magnet provider with a stopwatch around add(): the magnet's share of a step is
// measured inside the same run, on the same assembly (the fair measure on the dense state,
// where the run without magnet is a different, dilating assembly).
class TimedForce final : public engine::BodyForce {
 public:
  explicit TimedForce(std::shared_ptr<engine::BodyForce> f) : f_(std::move(f)) {}
  std::string name() const override { return f_->name(); }
  void add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
           std::span<double> tq) override {
    const auto t0 = std::chrono::steady_clock::now();
    f_->set_running_threads(running_threads());  // the engine's thread choice reaches the magnet's loops
    f_->set_hand_held(hand_held());               // and the engine's offer to add its held forces
    f_->set_body_set_version(body_set_version());
    f_->add(b, d, t, fx, fy, tq);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  Held held() const override { return f_->held(); }
  bool reads_contacts() const override { return f_->reads_contacts(); }
  void save(std::ostream& o) const override { f_->save(o); }
  void load(std::istream& in) override { f_->load(in); }
  double seconds = 0.0;

 private:
  std::shared_ptr<engine::BodyForce> f_;
};

// Largest disc-disc overlap and largest disc-wall overlap [m] (diagnostic of a state).
std::pair<double, double> max_overlaps(engine::Simulation& sim) {
  sim.compute_forces();
  const auto& d = sim.discs();
  const auto& nl = sim.neighbor_list();
  double dd = 0, dw = 0;
  for (std::size_t i = 0; i + 1 < nl.row_start_.size() && i < d.x.size(); ++i)
    for (int e = nl.row_start_[i]; e < nl.row_start_[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(nl.nbr_[static_cast<std::size_t>(e)]);
      dd = std::max(dd, d.r[i] + d.r[j] - std::hypot(d.x[i] - d.x[j], d.y[i] - d.y[j]));
    }
  std::vector<geometry::WallHit> hits;
  for (std::size_t i = 0; i < d.x.size(); ++i)
    for (const auto& w : sim.walls()) {
      hits.clear();
      w.query({d.x[i], d.y[i]}, d.r[i], 0.0, hits);
      for (const auto& h : hits) dw = std::max(dw, -h.gap);
    }
  return {dd, dw};
}

// Largest overlap of each body with another body or a wall [m].
std::vector<double> body_overlaps(engine::Simulation& sim) {
  sim.compute_forces();
  const auto& d = sim.discs();
  const auto& nl = sim.neighbor_list();
  std::vector<double> ov(sim.bodies().x.size(), 0.0);
  for (std::size_t i = 0; i + 1 < nl.row_start_.size() && i < d.x.size(); ++i)
    for (int e = nl.row_start_[i]; e < nl.row_start_[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(nl.nbr_[static_cast<std::size_t>(e)]);
      const double o = d.r[i] + d.r[j] - std::hypot(d.x[i] - d.x[j], d.y[i] - d.y[j]);
      auto& a = ov[static_cast<std::size_t>(d.body[i])];
      auto& b = ov[static_cast<std::size_t>(d.body[j])];
      a = std::max(a, o);
      b = std::max(b, o);
    }
  std::vector<geometry::WallHit> hits;
  for (std::size_t i = 0; i < d.x.size(); ++i)
    for (const auto& w : sim.walls()) {
      hits.clear();
      w.query({d.x[i], d.y[i]}, d.r[i], 0.0, hits);
      for (const auto& h : hits) ov[static_cast<std::size_t>(d.body[i])] = std::max(ov[static_cast<std::size_t>(d.body[i])], -h.gap);
    }
  return ov;
}

// Bodies of a starting state (centre of mass, angle, velocities, volume-equivalent diameter).
struct State {
  std::vector<double> x, y, theta, vx, vy, omega, size;
  std::vector<double> wall_angle;  // the rough roller's pits must stay where the toner rests
  std::size_t n() const { return x.size(); }
};

State snapshot(const engine::Simulation& sim) {
  const auto& b = sim.bodies();
  State s{b.x, b.y, b.theta, b.vx, b.vy, b.omega, b.size, {}};
  for (const auto& w : sim.walls()) s.wall_angle.push_back(w.angle);
  return s;
}

void save_state(const State& s, const std::string& path) {
  std::ofstream o(path, std::ios::binary);
  const std::uint64_t n = s.n();
  o.write("NIPBENCH2", 9);
  o.write(reinterpret_cast<const char*>(&n), sizeof n);
  const std::uint64_t nw = s.wall_angle.size();
  o.write(reinterpret_cast<const char*>(&nw), sizeof nw);
  o.write(reinterpret_cast<const char*>(s.wall_angle.data()), static_cast<std::streamsize>(nw * sizeof(double)));
  for (const auto* v : {&s.x, &s.y, &s.theta, &s.vx, &s.vy, &s.omega, &s.size})
    o.write(reinterpret_cast<const char*>(v->data()), static_cast<std::streamsize>(n * sizeof(double)));
  if (!o) throw std::runtime_error("cannot write " + path);
}

bool load_state(State& s, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char tag[9];
  std::uint64_t n = 0;
  in.read(tag, 9);
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  if (!in || std::string(tag, 9) != "NIPBENCH2" || n > 10000000) return false;
  std::uint64_t nw = 0;
  in.read(reinterpret_cast<char*>(&nw), sizeof nw);
  if (!in || nw > 16) return false;
  s.wall_angle.resize(nw);
  in.read(reinterpret_cast<char*>(s.wall_angle.data()), static_cast<std::streamsize>(nw * sizeof(double)));
  for (auto* v : {&s.x, &s.y, &s.theta, &s.vx, &s.vy, &s.omega, &s.size}) {
    v->resize(n);
    in.read(reinterpret_cast<char*>(v->data()), static_cast<std::streamsize>(n * sizeof(double)));
  }
  return static_cast<bool>(in);
}

// The dense, settled state (untimed). Real compaction of a 140 um layer by the knife takes
// milliseconds at the real time step (the 14:50 trial: 0.3 contacts per disc after 50,000
// steps), so: (1) the prefilled layer is pressed onto the roller by the knife plus an extra
// body acceleration of 3e4 m/s^2 towards the roller (about the knife's pull on a d50 toner,
// acting everywhere in the wide window) with contacts softened 100x (stiffness_scale 0.01,
// dt 10x longer) for 0.2 ms; (2) the extra acceleration is removed and the contacts are
// stiffened in steps of ~3x (0.03, 0.1, 0.3, 1) with dt following the preset rule, ~20
// contact times each, so the overlaps shrink quasi-statically to their real size instead of
// exploding. The knife and the dipole-dipole forces act throughout.
State make_dense_state(const std::vector<std::string>& base, double press_time, double press_acc, long relax_steps) {
  auto cfg = nip::parse_nip_config(nip::preset_text("black"), "preset:black", base);
  cfg.magnet.threads = cfg.threads;
  nip::NipRun nip(cfg);
  auto& sim = nip.sim();
  const auto t0 = std::chrono::steady_clock::now();
  const Vec2 g0 = sim.params().gravity;
  auto set_scale = [&](double s) {
    auto c = cfg;
    c.stiffness_scale = s;
    sim.mutable_params().interactions = nip::make_interactions(c);
    sim.mutable_params().dt = nip::choose_time_step(c).dt;
  };
  auto run_steps = [&](long n) {
    for (long i = 0; i < n; ++i) {
      sim.step();
      if (sim.step_count() % cfg.insert_interval == 0) nip.exchange();  // outflow of escaped toner
    }
  };
  auto report = [&](const char* what) {
    double zd = 0, zb = 0;
    coordination(sim, zd, zb);
    std::printf("  dense state: %-34s t=%.3g s particles=%zu contacts_per_disc=%.3f coordination disc %.2f body %.2f (%.0f s so far)\n",
                what, sim.time(), sim.bodies().x.size(), static_cast<double>(sim.contacts()) / static_cast<double>(sim.discs().x.size()), zd, zb,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::fflush(stdout);
  };
  set_scale(0.01);
  sim.mutable_params().gravity = g0 + Vec2{0.0, -press_acc};
  const long press_steps = static_cast<long>(press_time / sim.params().dt);
  for (int k = 1; k <= 4; ++k) {
    run_steps(press_steps / 4);
    report("pressing (k x 0.01, +3e4 m/s^2)");
  }
  for (double s : {0.03, 0.1, 0.3, 1.0}) {
    set_scale(s);
    if (s == 1.0) sim.mutable_params().gravity = g0;
    // contact time ~ 200 steps at every stiffness (dt follows sqrt(m/k)): 20 contact times
    run_steps(relax_steps);
    report(s < 1.0 ? "stiffening, pressed" : "real stiffness, released");
  }
  // A few toner particles end up wedged deep into a neighbour or a roller pit while pressed
  // with soft contacts (up to ~4 um). At real stiffness such an overlap is a force of
  // hundreds of uN that keeps shooting particles around (the engine's list was rebuilt every
  // ~20 steps): remove every body overlapping anything by more than 0.3 um (17 uN at
  // k = 56 N/m; the sleeve sliding under the held assembly makes transient overlaps of
  // ~0.05-0.1 um, which are left alone) and relax again.
  for (int round = 0; round < 3; ++round) {
    const auto ov = body_overlaps(sim);
    const std::size_t removed = sim.remove_bodies_if([&](int i) { return ov[static_cast<std::size_t>(i)] > 0.3e-6; });
    const auto [dd, dw] = max_overlaps(sim);
    std::printf("  dense state: removed %zu wedged particles; largest overlap now disc-disc %.3g m, disc-wall %.3g m\n", removed,
                dd, dw);
    if (removed == 0) break;
    run_steps(2000);
    report("relaxed again");
  }
  return snapshot(sim);
}

double g_dipole_skin = -1;  // --dipole-skin: overrides magnet.dipole_skin_m
int g_run_threads = 0;      // --run-threads: EngineParams::run_threads (0: the engine's measured choice)
double g_inner_skin = -1;  // --inner-skin: EngineParams::inner_skin_fraction (speed only; <0: the engine's)
double g_skin_quantile = -1;  // --skin-quantile: EngineParams::skin_speed_quantile (speed only; <0: the engine's)
double g_sort_cell = 0;     // --sort-cell: strip width [m] of the start state's spatial order (0: file order)

Result run(std::vector<std::string> overrides, const State* start, long settle, long steps, bool print_params) {
  if (start) overrides.push_back("inflow.prefill=false");
  auto cfg = nip::parse_nip_config(nip::preset_text("black"), "preset:black", overrides);
  // The magnet's per-particle loop runs on the engine's threads (MagnetConfig::threads is not
  // a config key; the nip should set it from run.threads the same way).
  cfg.magnet.threads = cfg.threads;
  if (g_dipole_skin >= 0) cfg.magnet.dipole_skin = g_dipole_skin;
  // The magnet provider is added here (as NipRun would, it is the only provider) so that it
  // can be timed.
  const auto magnet_cfg = cfg.magnet;
  cfg.magnet.field = "none";
  nip::NipRun nip(cfg);
  auto& sim = nip.sim();
  std::shared_ptr<TimedForce> timed;
  std::shared_ptr<nip::MagnetForce> mf;
  if (auto field = nip::make_magnet_field(magnet_cfg)) {
    mf = std::make_shared<nip::MagnetForce>(field, magnet_cfg);
    timed = std::make_shared<TimedForce>(mf);
    sim.add_force(timed);
  }
  sim.mutable_params().run_threads = g_run_threads;  // checked against --threads in main()
  if (g_inner_skin >= 0) sim.mutable_params().inner_skin_fraction = g_inner_skin;
  if (g_skin_quantile >= 0) sim.mutable_params().skin_speed_quantile = g_skin_quantile;
  const double dt = nip.time_step().dt;
  if (start) {  // the same bodies in the same order (contact history starts empty)
    const auto& tmpl = nip::find_template(cfg.templates, cfg.cluster, cfg.file, "toner.cluster");
    std::vector<std::size_t> order(start->n());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (g_sort_cell > 0)
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const double sa = std::floor(start->x[a] / g_sort_cell), sb = std::floor(start->x[b] / g_sort_cell);
        return sa != sb ? sa < sb : start->y[a] < start->y[b];
      });
    for (std::size_t i : order) {
      engine::BodySpec spec = nip::make_toner(tmpl, start->size[i], cfg.density);
      spec.position = {start->x[i], start->y[i]};
      spec.angle = start->theta[i];
      spec.velocity = {start->vx[i], start->vy[i]};
      spec.omega = start->omega[i];
      sim.add_body(spec);
    }
    for (std::size_t k = 0; k < start->wall_angle.size() && k < sim.walls().size(); ++k) sim.walls()[k].angle = start->wall_angle[k];
    if (print_params) {
      const auto [dd, dw] = max_overlaps(sim);
      std::printf("  start state: %zu particles, largest overlap disc-disc %.3g m, disc-wall %.3g m\n", sim.bodies().x.size(), dd, dw);
    }
  }
  if (print_params) {
    std::printf("  dt=%.4g s (%s), window x=[%g, %g] m, gap=%g m, layer=%g m at area fraction %g, cluster=%s\n", dt,
                nip.time_step().limiting.c_str(), cfg.x_min, cfg.x_max, cfg.gap, cfg.layer_thickness,
                cfg.area_fraction, cfg.cluster.c_str());
    const auto& ia = sim.params().interactions;
    std::printf("  k toner-toner=%g roller=%g drum=%g N/m, skin=%g m, threads=%d, insert interval=%d steps\n",
                ia[0].contact.k, ia[1].contact.k, ia[2].contact.k, sim.params().skin, sim.params().threads,
                cfg.insert_interval);
  }
  nip.advance_to(sim.time() + settle * dt);
  Result r;
  r.dt = dt;
  const std::size_t d0 = sim.discs().x.size();
  r.bodies = sim.bodies().x.size();
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  const double s0 = sim.time();
  const int builds0 = sim.neighbor_list().builds();
  const int takes0 = sim.pair_sublist_builds();
  if (timed) timed->seconds = 0.0;
  const int dbuilds0 = mf ? mf->dipole_pairs().builds() : 0;
  nip.advance_to(s0 + steps * dt);
  r.builds = sim.neighbor_list().builds() - builds0;
  r.sublist_takes = sim.pair_sublist_builds() - takes0;
  r.listed_pairs = sim.neighbor_list().pair_count();
  r.cross_entries = static_cast<long long>(sim.pair_cross_entries());
  const auto t1 = std::chrono::steady_clock::now();
  r.cpu_s = cpu_seconds() - c0;
  r.wall_s = std::chrono::duration<double>(t1 - t0).count();
  r.magnet_s = timed ? timed->seconds : 0.0;
  if (mf) {
    r.dipole_builds = mf->dipole_pairs().builds() - dbuilds0;
    r.dipole_pairs = mf->dipole_pairs().listed_pairs();
  }
  r.sim_s = sim.time() - s0;
  r.discs = (d0 + sim.discs().x.size()) / 2;  // average over the timed phase (inflow/outflow)
  r.rate = static_cast<double>(r.discs) * static_cast<double>(steps) / r.wall_s;
  r.contacts_per_disc = static_cast<double>(sim.contacts()) / static_cast<double>(sim.discs().x.size());
  coordination(sim, r.z_disc, r.z_body);
  r.maxrss_kb = maxrss_kb();
  r.threads_running = sim.team_tuner().team();
  r.thread_switches = sim.team_tuner().switches();
  if (print_params && timed) report_table_error(sim, magnet_cfg);
  return r;
}

void print(const char* label, const Result& r, long steps) {
  std::printf("  %-28s particles=%zu discs=%zu wall=%.3f s cpu=%.3f s disc_steps_per_s=%.4g "
              "wall_per_simulated_ms=%.2f s contacts_per_disc=%.3f coordination_disc=%.2f coordination_body=%.2f list_builds=%d "
              "sublist_takes=%d listed_pairs=%zu cross_part_entries=%lld peak_rss=%.1f MB magnet_share=%.1f %% dipole_list_builds=%d dipole_listed_pairs=%zu threads_running=%d thread_switches=%d\n",
              label, r.bodies, r.discs, r.wall_s, r.cpu_s, r.rate, r.wall_s / (r.sim_s * 1e3), r.contacts_per_disc, r.z_disc, r.z_body,
              r.builds, r.sublist_takes, r.listed_pairs, r.cross_entries, r.maxrss_kb / 1024.0, 100.0 * r.magnet_s / r.wall_s, r.dipole_builds, r.dipole_pairs, r.threads_running,
              r.thread_switches);
  (void)steps;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double load_average() {
  double l = -1;
  if (FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &l) != 1) l = -1;
    std::fclose(f);
  }
  return l;
}

}  // namespace

int main(int argc, char** argv) {
  nipdem::apply_wait_policy(argv);  // may re-execute once (core/wait_policy.hpp)
  long steps = 2000, settle = -1;
  int threads = 1, repeat = 1;
  double press_time = 2e-4;
  long relax_steps = 4000;
  std::string half_width = "2.6e-3", state = "dense", dense_file;
  std::vector<std::string> extra;
  bench::parse_args(argc, argv,
                    "bench_nip [--steps N] [--settle N] [--threads T] [--half-width M] [--state dense|loose] [--dense-file FILE] "
                    "[--repeat R] [--press-time S] [--relax-steps N] [--dipole-skin M] [--run-threads R] [--inner-skin F] [--skin-quantile Q] [--sort-cell M] [--set key=value]",
                    {{"--steps", [&](const std::string& v) { steps = nipdem::bench::at_least(nipdem::bench::to_long(v), 1L); }},
                     {"--settle", [&](const std::string& v) { settle = nipdem::bench::at_least(nipdem::bench::to_long(v), 0L); }},
                     {"--threads", [&](const std::string& v) { threads = nipdem::bench::at_least(nipdem::bench::to_int(v), 1); }},
                     {"--half-width", [&](const std::string& v) { half_width = v; }},
                     {"--state", [&](const std::string& v) { state = v; }},
                     {"--dense-file", [&](const std::string& v) { dense_file = v; }},
                     {"--press-time", [&](const std::string& v) { press_time = nipdem::bench::to_double(v); }},
                     {"--relax-steps", [&](const std::string& v) { relax_steps = nipdem::bench::at_least(nipdem::bench::to_long(v), 0L); }},
                     {"--dipole-skin", [&](const std::string& v) { g_dipole_skin = nipdem::bench::to_double(v); }},
                     {"--run-threads", [&](const std::string& v) { g_run_threads = nipdem::bench::to_int(v); }},
                     {"--inner-skin", [&](const std::string& v) {
                        g_inner_skin = nipdem::bench::to_double(v);
                        if (!(g_inner_skin >= 0 && g_inner_skin <= 1)) throw std::invalid_argument("must be in [0, 1]");
                      }},
                     {"--skin-quantile", [&](const std::string& v) {
                        g_skin_quantile = nipdem::bench::to_double(v);
                        if (!(g_skin_quantile >= 0 && g_skin_quantile < 1)) throw std::invalid_argument("must be in [0, 1)");
                      }},
                     {"--sort-cell", [&](const std::string& v) {
                        g_sort_cell = nipdem::bench::to_double(v);
                        if (!(g_sort_cell >= 0 && g_sort_cell <= 1)) throw std::invalid_argument("must be in [0, 1] m");
                      }},
                     {"--repeat", [&](const std::string& v) { repeat = nipdem::bench::at_least(nipdem::bench::to_int(v), 1); }},
                     {"--set", [&](const std::string& v) { extra.push_back(v); }}});
  if (g_run_threads < 0 || g_run_threads > threads) {
    std::fprintf(stderr, "bench_nip: --run-threads %d: must be 0 (the engine's measured choice) or 1..threads (%d)\n", g_run_threads, threads);
    return 2;
  }
  if (state != "dense" && state != "loose") {
    std::fprintf(stderr, "bench_nip: --state must be dense or loose\n");
    return 2;
  }
  // Untimed steps before timing: after loading the dense state the contact history is empty
  // (it is rebuilt within a contact time, ~200 steps).
  if (settle < 0) settle = state == "dense" ? 1000 : 200;
  // A layer of 140 um in the 150 um gap at area fraction 0.5 over a window wide enough for
  // ~10,000 tri3 particles; real stiffness (stiffness_scale = 1), default time step.
  std::vector<std::string> base = {
      "geometry.window_x_min_m=-" + half_width, "geometry.window_x_max_m=" + half_width,
      "inflow.layer_thickness_m=140e-6",       "inflow.area_fraction=0.5",
      "run.threads=" + std::to_string(threads), "output.vtk=false",
      // the pressed layer fills the pits itself; pits arriving filled (the preset's default since
      // 2026-11-23 17:00) would add toner on top of a saved dense state
      "inflow.roller_pits=\"empty\"",
  };
  base.insert(base.end(), extra.begin(), extra.end());
  std::printf("bench_nip git=%s preset=black state=%s steps=%ld settle=%ld threads=%d repeat=%d load_average=%.2f waits=%s\n",
              kGitHash, state.c_str(), steps, settle, threads, repeat, load_average(), nipdem::wait_policy().c_str());
  try {
    State dense;
    if (state == "dense") {
      if (dense_file.empty() || !load_state(dense, dense_file)) {
        dense = make_dense_state(base, press_time, 3e4, relax_steps);
        if (!dense_file.empty()) save_state(dense, dense_file);
      } else {
        std::printf("  dense state: %zu particles read from %s\n", dense.n(), dense_file.c_str());
      }
    }
    const State* start = state == "dense" ? &dense : nullptr;
    auto no_magnet = base;
    no_magnet.push_back("magnet.field=\"none\"");
    std::vector<double> overhead, cpu_overhead, rate_a, rate_b, inrun;
    Result a, b;
    for (int rep = 0; rep < repeat; ++rep) {  // alternate off/on: both see the same machine load
      a = run(no_magnet, start, settle, steps, rep == 0);
      print("magnet.field=none:", a, steps);
      std::fflush(stdout);
      b = run(base, start, settle, steps, rep == 0);
      print("knife + dipole-dipole:", b, steps);
      // Per disc-step, so a slightly different particle count does not count as magnet cost.
      const double cost_a = a.wall_s / (static_cast<double>(a.discs) * steps);
      const double cost_b = b.wall_s / (static_cast<double>(b.discs) * steps);
      const double ccost_a = a.cpu_s / (static_cast<double>(a.discs) * steps);
      const double ccost_b = b.cpu_s / (static_cast<double>(b.discs) * steps);
      overhead.push_back(100.0 * (cost_b / cost_a - 1.0));
      inrun.push_back(100.0 * b.magnet_s / (b.wall_s - b.magnet_s));
      cpu_overhead.push_back(100.0 * (ccost_b / ccost_a - 1.0));
      rate_a.push_back(a.rate);
      rate_b.push_back(b.rate);
      std::printf("  magnet overhead: %+.1f %% wall time per disc-step against the run without magnet (%+.1f %% cpu time); "
                  "in the magnet run itself: magnet %.3f s of %.3f s = %+.1f %% on top of the rest of the step; load average %.2f\n",
                  overhead.back(), cpu_overhead.back(), b.magnet_s, b.wall_s, inrun.back(), load_average());
      std::fflush(stdout);
    }
    std::printf("RESULT nip state=%s threads=%d particles=%zu disc_steps_per_s_nomagnet=%.4g disc_steps_per_s_magnet=%.4g "
                "magnet_overhead_pct=%.1f (median of %d; cpu %.1f) magnet_overhead_in_run_pct=%.1f wall_per_sim_ms_nomagnet=%.1f wall_per_sim_ms_magnet=%.1f "
                "contacts_per_disc=%.3f/%.3f coordination_disc=%.2f/%.2f coordination_body=%.2f/%.2f peak_rss_MB=%.1f\n",
                state.c_str(), threads, b.bodies, median(rate_a), median(rate_b), median(overhead), repeat, median(cpu_overhead), median(inrun),
                static_cast<double>(a.discs) / median(rate_a) / a.dt * 1e-3, static_cast<double>(b.discs) / median(rate_b) / b.dt * 1e-3,
                a.contacts_per_disc, b.contacts_per_disc, a.z_disc, b.z_disc, a.z_body, b.z_body, b.maxrss_kb / 1024.0);
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_nip: %s\n", e.what());
    return 2;
  }
  return 0;
}
