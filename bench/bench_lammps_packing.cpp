// bench_lammps_packing: nipdem's contact engine on the LAMMPS peer workload
// (/work/shared/bench/lammps-2d-packing: 30,000 discs settled on a floor, periodic in x,
// linear spring-dashpot with tangential history, mass-proportional damping, dt = 7.8e-9 s).
// Same law, same parameters, same packing as bench_lammps_hooke.in, so disc-steps/s can be
// compared with LAMMPS's "Loop time" run right before or after (bench/run_lammps_compare.sh).
//
// Usage: bench_lammps_packing [--data FILE(.gz)] [--steps N] [--warmup N] [--threads T] [--run-threads R]
//                             [--tilt-deg A] [--inertia disc|sphere] [--every N]
// Prints parameters, git hash, throughput of the timed phase and, after it (untimed), the
// final kinetic energy and contacts per disc for the physics cross-check with LAMMPS.
// --tilt-deg tilts the body force by A degrees towards +x (the bed slides: the driven variant
// of bench_lammps_hooke.in's `tilt`); --inertia sphere gives each disc 2/5 m r^2 (LAMMPS
// fix nve/sphere without `disc`); --every N prints "THERMO step ke_translational_J mean_vx"
// every N steps from step 0 (warm-up included, as LAMMPS thermo; bench/lammps_thermo.in is the
// LAMMPS side), so the cross-check is one command each.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "bench_args.hpp"
#include "nipdem/core/wait_policy.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;

namespace {

// The numbers of params.inc (SI).
constexpr double kKn = 10.0;            // [N/m]
constexpr double kKt = 2.0 / 7.0 * kKn; // [N/m]
constexpr double kGn = 1.7e6;           // [1/s], times m_eff
constexpr double kGt = 0.5 * kGn;       // [1/s], times m_eff
constexpr double kMu = 0.5;
constexpr double kDt = 7.8e-9;          // [s]
constexpr double kG = 2.0e4;            // [m/s^2] in -y
constexpr double kSkin = 2.0e-6;        // [m]

struct Disc {
  double d, rho, x, y, vx = 0, vy = 0, w = 0;
};

struct Packing {
  double xlo = 0, xhi = 0, ylo = 0, yhi = 0;
  std::vector<Disc> discs;
};

// Reads a LAMMPS data file written by write_data with atom_style sphere:
//   Atoms # sphere:  id type diameter density x y z [ix iy iz]
//   Velocities:      id vx vy vz wx wy wz
// A name ending in .gz is piped through gzip -dc.
Packing read_lammps_data(const std::string& path) {
  const bool gz = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  FILE* f = gz ? popen(("gzip -dc '" + path + "'").c_str(), "r") : std::fopen(path.c_str(), "r");
  if (!f) throw std::runtime_error("cannot open " + path);
  Packing p;
  std::size_t natoms = 0;
  char line[512];
  enum { header, atoms, vels } sec = header;
  std::size_t seen_v = 0;
  std::vector<long> index_of_id;
  while (std::fgets(line, sizeof line, f)) {
    char* s = line;
    while (*s == ' ' || *s == '\t') ++s;
    if (*s == '\n' || *s == '\0' || *s == '#') continue;
    if (std::strncmp(s, "Atoms", 5) == 0) { sec = atoms; continue; }
    if (std::strncmp(s, "Velocities", 10) == 0) { sec = vels; continue; }
    if (sec == header) {
      double a, b;
      if (std::strstr(s, " atoms")) natoms = std::strtoul(s, nullptr, 10);
      else if (std::strstr(s, "xlo xhi") && std::sscanf(s, "%lf %lf", &a, &b) == 2) { p.xlo = a; p.xhi = b; }
      else if (std::strstr(s, "ylo yhi") && std::sscanf(s, "%lf %lf", &a, &b) == 2) { p.ylo = a; p.yhi = b; }
      continue;
    }
    char* e;
    const long id = std::strtol(s, &e, 10);
    if (e == s || id < 1 || static_cast<std::size_t>(id) > natoms) continue;  // not a data row
    if (sec == atoms) {
      Disc d{};
      std::strtol(e, &e, 10);  // type
      d.d = std::strtod(e, &e);
      d.rho = std::strtod(e, &e);
      d.x = std::strtod(e, &e);
      d.y = std::strtod(e, &e);
      if (index_of_id.empty()) index_of_id.assign(natoms + 1, -1);
      index_of_id[id] = static_cast<long>(p.discs.size());
      p.discs.push_back(d);
    } else {
      const long k = index_of_id.empty() ? -1 : index_of_id[id];
      if (k < 0) continue;
      Disc& d = p.discs[k];
      d.vx = std::strtod(e, &e);
      d.vy = std::strtod(e, &e);
      std::strtod(e, &e);  // vz
      std::strtod(e, &e);  // wx
      std::strtod(e, &e);  // wy
      d.w = std::strtod(e, &e);
      ++seen_v;
    }
  }
  if (gz) pclose(f); else std::fclose(f);
  if (p.discs.size() != natoms || natoms == 0)
    throw std::runtime_error("read " + std::to_string(p.discs.size()) + " atoms, header says " + std::to_string(natoms));
  (void)seen_v;
  return p;
}

// Disc-disc contacts per disc, counted like LAMMPS compute contact/atom (each touching pair
// counts for both discs; wall contacts are not counted).
double contacts_per_disc(const engine::Simulation& sim) {
  const auto& nl = sim.neighbor_list();
  const auto& d = sim.discs();
  const double L = sim.params().x_hi - sim.params().x_lo;
  std::int64_t n = 0;
  for (std::size_t i = 0; i + 1 < nl.row_start_.size(); ++i)
    for (int k = nl.row_start_[i]; k < nl.row_start_[i + 1]; ++k) {
      const int j = nl.nbr_[k];
      double dx = d.x[i] - d.x[j];
      dx -= L * std::nearbyint(dx / L);
      const double dy = d.y[i] - d.y[j];
      const double rs = d.r[i] + d.r[j];
      if (dx * dx + dy * dy < rs * rs) ++n;
    }
  return 2.0 * static_cast<double>(n) / static_cast<double>(d.x.size());
}

// User + system CPU time of this process [s] (all threads): less sensitive than wall time
// to other jobs on a shared machine.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void usage() {
  std::fprintf(stderr,
               "usage: bench_lammps_packing [--data FILE(.gz)] [--steps N=20000] [--warmup N=1000] "
               "[--threads T=1] [--run-threads R=0 (0: measured choice of T or 1)] [--tilt-deg A=0] [--inertia disc|sphere] [--every N=0]\n");
}

}  // namespace

int main(int argc, char** argv) {
  nipdem::apply_wait_policy(argv);  // may re-execute once (core/wait_policy.hpp)
  std::string data = "/work/shared/bench/lammps-2d-packing/packing.data.gz";
  long steps = 20000, warmup = 1000;
  int threads = 1;
  int run_threads = 0;
  double tilt_deg = 0.0;
  bool sphere_inertia = false;
  long every = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string k = argv[a];
    auto val = [&]() -> std::string {
      if (a + 1 >= argc) { usage(); std::exit(2); }
      return argv[++a];
    };
    try {
    if (k == "--data") data = val();
    else if (k == "--steps") steps = nipdem::bench::to_long(val());
    else if (k == "--warmup") warmup = nipdem::bench::to_long(val());
    else if (k == "--threads") threads = nipdem::bench::to_int(val());
    else if (k == "--run-threads") run_threads = nipdem::bench::to_int(val());
    else if (k == "--tilt-deg") tilt_deg = nipdem::bench::to_double(val());
    else if (k == "--every") every = nipdem::bench::to_long(val());
    else if (k == "--inertia") {
      const std::string v = val();
      if (v != "disc" && v != "sphere") { usage(); return 2; }
      sphere_inertia = v == "sphere";
    } else { usage(); return 2; }
    } catch (const std::exception& e) {  // a value that is not a number in full (bench_args.hpp)
      std::fprintf(stderr, "bench_lammps_packing: %s '%s' not accepted (%s)\n", k.c_str(), argv[a], e.what());
      usage();
      return 2;
    }
  }
  if (steps < 1 || warmup < 0 || threads < 1 || run_threads < 0 || run_threads > threads || every < 0 || !(std::fabs(tilt_deg) <= 90.0)) { usage(); return 2; }

  Packing pk;
  try {
    pk = read_lammps_data(data);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_lammps_packing: %s\n", e.what());
    return 2;
  }

  engine::EngineParams ep;
  ep.integrator = engine::Integrator::velocity_verlet;  // LAMMPS fix nve/sphere
  ep.dt = kDt;
  const double tilt = tilt_deg * 3.14159265358979323846 / 180.0;
  ep.gravity = {kG * std::sin(tilt), -kG * std::cos(tilt)};
  models::ContactParams cp;
  cp.k = kKn;
  cp.ks = kKt;
  cp.gamma = kGn;
  cp.gamma_t = kGt;
  cp.mu_s = cp.mu_d = kMu;
  cp.mass_proportional = true;
  ep.interactions = {{"disc-disc", cp, {}}, {"disc-wall", cp, {}}};
  ep.skin = kSkin;
  ep.periodic_x = true;
  ep.x_lo = pk.xlo;
  ep.x_hi = pk.xhi;
  ep.threads = threads;
  ep.run_threads = run_threads;
  geometry::Wall floor, lid;
  floor.kind = lid.kind = geometry::Wall::Kind::plane;
  floor.name = "floor"; floor.point = {0.0, pk.ylo}; floor.normal = {0.0, 1.0}; floor.interaction = 1;
  lid.name = "lid"; lid.point = {0.0, pk.yhi}; lid.normal = {0.0, -1.0}; lid.interaction = 1;
  engine::Simulation sim(ep, {floor, lid});
  for (const Disc& d : pk.discs) {
    engine::BodySpec s;
    s.offsets = {{0.0, 0.0}};
    s.radii = {0.5 * d.d};
    s.density = d.rho;           // mass of a sphere of that diameter (as LAMMPS read_data)
    s.sphere_inertia = sphere_inertia;  // default disc inertia m r^2 / 2 (fix nve/sphere disc)
    s.position = {d.x, d.y};
    s.velocity = {d.vx, d.vy};
    s.omega = d.w;
    sim.add_body(s);
  }
  const std::size_t n = sim.discs().x.size();

  std::printf("bench_lammps_packing git=%s waits=%s\n", kGitHash, nipdem::wait_policy().c_str());
  std::printf("  data=%s discs=%zu box x=[%g,%g] periodic, walls y=%g and y=%g\n", data.c_str(), n, pk.xlo, pk.xhi,
              pk.ylo, pk.yhi);
  std::printf("  kn=%g N/m kt=%g N/m gamma_n=%g 1/s*m_eff gamma_t=%g 1/s*m_eff mu=%g dt=%g s g=%g m/s^2 skin=%g m\n",
              kKn, kKt, kGn, kGt, kMu, kDt, kG, kSkin);
  std::printf("  threads=%d warmup=%ld steps=%ld tilt_deg=%g inertia=%s every=%ld\n", threads, warmup, steps, tilt_deg,
              sphere_inertia ? "sphere" : "disc", every);
  std::fflush(stdout);

  // Translational kinetic energy and mean x-velocity (LAMMPS thermo `ke`, reduce ave vx).
  auto thermo = [&](long step) {
    if (every <= 0 || step % every != 0) return;
    const auto& b = sim.bodies();
    double ke = 0.0, vx = 0.0;
    for (std::size_t i = 0; i < b.x.size(); ++i) {
      ke += 0.5 * b.mass[i] * (b.vx[i] * b.vx[i] + b.vy[i] * b.vy[i]);
      vx += b.vx[i];
    }
    std::printf("THERMO %ld %.9g %.9g\n", step, ke, vx / static_cast<double>(b.x.size()));
  };
  thermo(0);
  for (long s = 0; s < warmup; ++s) { sim.step(); thermo(s + 1); }
  const int builds0 = sim.neighbor_list().builds();
  const int takes0 = sim.pair_sublist_builds();
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (long s = 0; s < steps; ++s) { sim.step(); thermo(warmup + s + 1); }
  const auto t1 = std::chrono::steady_clock::now();
  const double cpu = cpu_seconds() - c0;
  const double wall = std::chrono::duration<double>(t1 - t0).count();
  const double rate = static_cast<double>(n) * static_cast<double>(steps) / wall;

  const auto& b = sim.bodies();
  double ke_t = 0.0, ke_r = 0.0;
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    ke_t += 0.5 * b.mass[i] * (b.vx[i] * b.vx[i] + b.vy[i] * b.vy[i]);
    ke_r += 0.5 * b.inertia[i] * b.omega[i] * b.omega[i];
  }
  std::printf("  wall_time_s=%.3f cpu_time_s=%.3f disc_steps_per_s=%.4g (per cpu-second %.4g) neighbor_builds=%d pairs_in_list=%zu sublist_takes=%d cross_part_entries=%lld\n",
              wall, cpu, rate, static_cast<double>(n) * static_cast<double>(steps) / cpu,
              sim.neighbor_list().builds() - builds0, sim.neighbor_list().pair_count(), sim.pair_sublist_builds() - takes0,
              static_cast<long long>(sim.pair_cross_entries()));
  std::printf("  final: ke_translational_J=%.6g ke_rotational_J=%.6g contacts_per_disc=%.4f (disc-disc, as "
              "LAMMPS contact/atom) all_contacts=%lld\n",
              ke_t, ke_r, contacts_per_disc(sim), static_cast<long long>(sim.contacts()));
  const auto& tt = sim.team_tuner();
  std::printf("  thread use: %s, %d threads at the end, %d probes (%d started by a slowdown), %d switches\n",
              tt.adaptive() ? "measured (run_threads=0)" : "fixed", tt.team(), tt.probes(), tt.early_probes(),
              tt.switches());
  std::printf("RESULT nipdem threads=%d steps=%ld wall_s=%.4f cpu_s=%.4f disc_steps_per_s=%.6g\n", threads, steps, wall, cpu, rate);
  return 0;
}
