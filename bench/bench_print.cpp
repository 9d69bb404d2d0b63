// bench_print: cost of the charge model (issue 4 "Speed"): a print-state nip step with the
// electric force and RC charging over the conduction network (thesis §2.5.5, §4.7) against
// the same step without them.
//
// State: black preset (real stiffness unless --set collision.stiffness_scale=..), filled
// sleeve pits, the magnet with dipole-dipole, and a dense assembly that bridges the gap from
// the roller to the drum over [--x0, --x1] in a window of -300..+700 um (the configuration of
// examples/print_line_black.toml), the drum track at 40 V throughout. After
// `--settle` steps (contacts and conduction paths form, toner near the drum charges) the
// next `--steps` are timed. Both runs start from the same seed, hence the same fill.
//
// Usage: bench_print [--steps N=2000] [--settle N=20000] [--threads T=1] [--repeat R=3] [--x0 M=-250e-6]
//                    [--x1 M=450e-6] [--set key=value ...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "nipdem/core/wait_policy.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;

namespace {

struct Result {
  std::size_t bodies = 0, discs = 0;
  double wall_s = 0, sim_s = 0, rate = 0;
  int printable = 0, charged = 0;
  double vmax = 0;
};

Result run(const std::vector<std::string>& overrides, double x0, double x1, long settle, long steps, bool show) {
  auto cfg = nip::parse_nip_config(nip::preset_text("black"), "preset:black", overrides);
  nip::NipRun nip(cfg);
  const int n = nip.fill_on_roller(x0, x1, 0.0, cfg.gap, 0.6);
  auto& sim = nip.sim();
  const double dt = nip.time_step().dt;
  if (show)
    std::printf("  dt=%.4g s, window [%g, %g] m, gap %g m, assembly of %d particles over [%g, %g] m + %zu in pits, threads %d\n", dt,
                cfg.x_min, cfg.x_max, cfg.gap, n, x0, x1, sim.bodies().x.size() - n, cfg.threads);
  nip.advance_to(sim.time() + settle * dt);
  Result r;
  const std::size_t d0 = sim.discs().x.size();
  r.bodies = sim.bodies().x.size();
  const auto t0 = std::chrono::steady_clock::now();
  const double s0 = sim.time();
  nip.advance_to(s0 + steps * dt);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.sim_s = sim.time() - s0;
  r.discs = (d0 + sim.discs().x.size()) / 2;
  r.rate = static_cast<double>(r.discs) * static_cast<double>(steps) / r.wall_s;
  if (const auto* e = nip.electric()) {
    r.printable = e->printable_count();
    for (double u : e->voltage()) {
      r.vmax = std::max(r.vmax, std::fabs(u));
      r.charged += std::fabs(u) > 1.0;
    }
  }
  return r;
}

void print(const char* label, const Result& r) {
  std::printf("  %-26s particles=%zu discs=%zu wall=%.3f s disc_steps_per_s=%.4g wall_per_simulated_ms=%.1f s "
              "printable=%d charged_over_1V=%d max_voltage=%.1f V\n",
              label, r.bodies, r.discs, r.wall_s, r.rate, r.wall_s / (r.sim_s * 1e3), r.printable, r.charged, r.vmax);
}

}  // namespace

int main(int argc, char** argv) {
  nipdem::apply_wait_policy(argv);  // may re-execute once (core/wait_policy.hpp)
  long steps = 2000, settle = 20000;
  int threads = 1, repeat = 3;
  double x0 = -250e-6, x1 = 450e-6;
  std::vector<std::string> extra;
  bench::parse_args(argc, argv, "bench_print [--steps N] [--settle N] [--threads T] [--repeat R] [--x0 M] [--x1 M] [--set key=value]",
                    {{"--steps", [&](const std::string& v) { steps = nipdem::bench::to_long(v); }},
                     {"--settle", [&](const std::string& v) { settle = nipdem::bench::to_long(v); }},
                     {"--threads", [&](const std::string& v) { threads = nipdem::bench::to_int(v); }},
                     {"--repeat", [&](const std::string& v) { repeat = std::max(1, nipdem::bench::to_int(v)); }},
                     {"--x0", [&](const std::string& v) { x0 = nipdem::bench::to_double(v); }},
                     {"--x1", [&](const std::string& v) { x1 = nipdem::bench::to_double(v); }},
                     {"--set", [&](const std::string& v) { extra.push_back(v); }}});
  std::vector<std::string> base = {
      "geometry.window_x_min_m=-300e-6", "geometry.window_x_max_m=700e-6", "inflow.layer_thickness_m=0",
      "inflow.prefill=false",            "inflow.roller_pits=\"filled\"",  "run.threads=" + std::to_string(threads),
      "output.vtk=false",                "print.pattern=\"line\"",         "print.voltage_V=40",
      "print.start_m=-0.5",                "print.length_m=1",               "electric.charge_preset=\"black\"",
  };
  base.insert(base.end(), extra.begin(), extra.end());
  std::printf("bench_print git=%s preset=black steps=%ld settle=%ld threads=%d\n", kGitHash, steps, settle, threads);
  try {
    auto off = base, on = base;
    off.push_back("electric.enabled=false");
    on.push_back("electric.enabled=true");
    // Interleaved repeats; the fastest of each kind is the least disturbed by other jobs on
    // a shared machine (the work is identical from repeat to repeat).
    Result a, b;
    for (int k = 0; k < repeat; ++k) {
      const Result ak = run(off, x0, x1, settle, steps, k == 0);
      print("electric.enabled=false:", ak);
      std::fflush(stdout);
      const Result bk = run(on, x0, x1, settle, steps, false);
      print("charge model + force:", bk);
      std::fflush(stdout);
      if (k == 0 || ak.wall_s < a.wall_s) a = ak;
      if (k == 0 || bk.wall_s < b.wall_s) b = bk;
    }
    const double ca = a.wall_s / (static_cast<double>(a.discs) * steps);
    const double cb = b.wall_s / (static_cast<double>(b.discs) * steps);
    std::printf("fastest of %d interleaved repeats each\n", repeat);
    std::printf("RESULT print threads=%d particles=%zu disc_steps_per_s_off=%.4g disc_steps_per_s_on=%.4g charge_overhead_pct=%.1f\n",
                threads, b.bodies, a.rate, b.rate, 100.0 * (cb / ca - 1.0));
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_print: %s\n", e.what());
    return 2;
  }
  return 0;
}
