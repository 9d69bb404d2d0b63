// bench_nip: macro benchmark of the full nip (preset "black": real stiffness, tri3 toner,
// rough imaging roller, drum, Hamaker adhesion, inflow/outflow) with ~10,000 particles
// prefilled in a wide window. Runs the same configuration twice: without the magnet
// (magnet.field = "none") and with it (analytic knife + dipole-dipole), and reports
// disc-steps/s, wall time per simulated ms, peak memory and the magnet's cost.
//
// Usage: bench_nip [--steps N=2000] [--settle N=200] [--threads T=1] [--half-width M=4.2e-3]
//                  [--set key=value ...]   (extra config overrides, as `nipdem run --set`)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "nipdem/core/error.hpp"
#include "nipdem/experiments/nip.hpp"
#include "nipdem/experiments/nip_config.hpp"
#include "nipdem/experiments/presets.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;

namespace {

struct Result {
  std::size_t bodies = 0, discs = 0;
  double wall_s = 0, cpu_s = 0, sim_s = 0, dt = 0, rate = 0, contacts_per_disc = 0;
  int builds = 0;
  long maxrss_kb = 0;
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

// Error of the tabulated magnet force (MagnetForce tabulates the analytic knife with bicubic
// Hermite at h = 20 um): the same interpolation on the same spacing, compared with the exact
// field at the particle positions.
void report_table_error(const engine::Simulation& sim, const experiments::NipConfig& cfg) {
  const auto knife = magnet::make_knife();
  const auto& b = sim.bodies();
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    x0 = std::min(x0, b.x[i]); x1 = std::max(x1, b.x[i]);
    y0 = std::min(y0, b.y[i]); y1 = std::max(y1, b.y[i]);
  }
  const double h = 20e-6;
  x0 -= 3 * h; y0 -= 3 * h; x1 += 3 * h; y1 += 3 * h;
  const int nx = static_cast<int>((x1 - x0) / h) + 1, ny = static_cast<int>((y1 - y0) / h) + 1;
  const auto map = io::FieldMap::sample(knife, x0, x0 + (nx - 1) * h, nx, y0, y0 + (ny - 1) * h, ny);
  double max_rel = 0, sum2 = 0, fmax = 0, max_abs = 0;
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    const double R = 0.5 * b.size[i];
    const Vec2 fe = magnet::induced_dipole_force(cfg.magnet.toner, R, knife.at({b.x[i], b.y[i]}));
    const Vec2 fm = magnet::induced_dipole_force(cfg.magnet.toner, R, map.at({b.x[i], b.y[i]}));
    const double e = norm(fm - fe), f = norm(fe);
    fmax = std::max(fmax, f);
    max_abs = std::max(max_abs, e);
    if (f > 0) { max_rel = std::max(max_rel, e / f); sum2 += (e / f) * (e / f); }
  }
  std::printf("  tabulated magnet force (h = 20 um) vs analytic at %zu particles: max relative error %.2e, "
              "rms %.2e, max abs error / max force %.2e\n",
              b.x.size(), max_rel, std::sqrt(sum2 / static_cast<double>(b.x.size())), max_abs / fmax);
}

Result run(const std::vector<std::string>& overrides, long settle, long steps, bool print_params) {
  auto cfg = experiments::parse_nip_config(experiments::preset_text("black"), "preset:black", overrides);
  // The magnet's per-particle loop runs on the engine's threads (MagnetConfig::threads is not
  // a config key; the nip should set it from run.threads the same way).
  cfg.magnet.threads = cfg.threads;
  experiments::NipRun nip(cfg);
  auto& sim = nip.sim();
  const double dt = nip.time_step().dt;
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
  nip.advance_to(s0 + steps * dt);
  r.builds = sim.neighbor_list().builds() - builds0;
  const auto t1 = std::chrono::steady_clock::now();
  r.cpu_s = cpu_seconds() - c0;
  r.wall_s = std::chrono::duration<double>(t1 - t0).count();
  r.sim_s = sim.time() - s0;
  r.discs = (d0 + sim.discs().x.size()) / 2;  // average over the timed phase (inflow/outflow)
  r.rate = static_cast<double>(r.discs) * static_cast<double>(steps) / r.wall_s;
  r.contacts_per_disc = static_cast<double>(sim.contacts()) / static_cast<double>(sim.discs().x.size());
  r.maxrss_kb = maxrss_kb();
  if (print_params) report_table_error(sim, cfg);
  return r;
}

void print(const char* label, const Result& r, long steps) {
  std::printf("  %-28s particles=%zu discs=%zu wall=%.3f s cpu=%.3f s disc_steps_per_s=%.4g "
              "wall_per_simulated_ms=%.2f s contacts_per_disc=%.3f list_builds=%d peak_rss=%.1f MB\n",
              label, r.bodies, r.discs, r.wall_s, r.cpu_s, r.rate, r.wall_s / (r.sim_s * 1e3), r.contacts_per_disc,
              r.builds, r.maxrss_kb / 1024.0);
  (void)steps;
}

}  // namespace

int main(int argc, char** argv) {
  long steps = 2000, settle = 200;
  int threads = 1;
  std::string half_width = "4.2e-3";
  std::vector<std::string> extra;
  for (int a = 1; a < argc; ++a) {
    const std::string k = argv[a];
    auto val = [&]() -> std::string {
      if (a + 1 >= argc) { std::fprintf(stderr, "missing value for %s\n", k.c_str()); std::exit(2); }
      return argv[++a];
    };
    if (k == "--steps") steps = std::stol(val());
    else if (k == "--settle") settle = std::stol(val());
    else if (k == "--threads") threads = std::stoi(val());
    else if (k == "--half-width") half_width = val();
    else if (k == "--set") extra.push_back(val());
    else {
      std::fprintf(stderr, "usage: bench_nip [--steps N] [--settle N] [--threads T] [--half-width M] [--set key=value]\n");
      return 2;
    }
  }
  // A dense layer (140 um in the 150 um gap, area fraction 0.5) over a window wide enough
  // for ~10,000 tri3 particles; real stiffness (stiffness_scale = 1), default time step.
  std::vector<std::string> base = {
      "geometry.window_x_min_m=-" + half_width, "geometry.window_x_max_m=" + half_width,
      "inflow.layer_thickness_m=140e-6",       "inflow.area_fraction=0.5",
      "run.threads=" + std::to_string(threads), "output.vtk=false",
  };
  base.insert(base.end(), extra.begin(), extra.end());
  std::printf("bench_nip git=%s preset=black steps=%ld settle=%ld threads=%d\n", kGitHash, steps, settle, threads);
  try {
    auto no_magnet = base;
    no_magnet.push_back("magnet.field=\"none\"");
    const Result a = run(no_magnet, settle, steps, true);
    print("magnet.field=none:", a, steps);
    std::fflush(stdout);
    const Result b = run(base, settle, steps, false);
    print("knife + dipole-dipole:", b, steps);
    // Per disc-step, so a slightly different particle count does not count as magnet cost.
    const double cost_a = a.wall_s / (static_cast<double>(a.discs) * steps);
    const double cost_b = b.wall_s / (static_cast<double>(b.discs) * steps);
    const double ccost_a = a.cpu_s / (static_cast<double>(a.discs) * steps);
    const double ccost_b = b.cpu_s / (static_cast<double>(b.discs) * steps);
    std::printf("  magnet overhead: %+.1f %% wall time per disc-step (%+.1f %% cpu time)\n", 100.0 * (cost_b / cost_a - 1.0),
                100.0 * (ccost_b / ccost_a - 1.0));
    std::printf("RESULT nip threads=%d particles=%zu disc_steps_per_s_nomagnet=%.4g disc_steps_per_s_magnet=%.4g "
                "magnet_overhead_pct=%.1f peak_rss_MB=%.1f\n",
                threads, b.bodies, a.rate, b.rate, 100.0 * (cost_b / cost_a - 1.0), b.maxrss_kb / 1024.0);
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_nip: %s\n", e.what());
    return 2;
  }
  return 0;
}
