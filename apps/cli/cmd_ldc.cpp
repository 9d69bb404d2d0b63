// `nipdem ldc verify [--json]`: reruns the LDC verification problems of thesis §3.8-3.10.
// `nipdem ldc solve SETUP.{json,toml} [--json]`: solves one disc configuration (see docs/ldc.md).
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/solvers/ldc/ldc_solver.hpp"
#include "nipdem/solvers/ldc/setup_file.hpp"
#include "nipdem/solvers/ldc/verify.hpp"
#include "registry.hpp"

namespace {
using nlohmann::json;
namespace lv = nipdem::ldc::verify;

void run_verify(bool as_json) {
  const lv::Report rep = lv::run_all();
  if (as_json) {
    nipdem::cli::print_json(lv::to_json(rep).dump());
    return;
  }
  const auto& t31 = rep.t31; const auto& t32 = rep.t32; const auto& t33 = rep.t33; const auto& t34 = rep.t34;
  const auto& f36 = rep.f36;
  std::printf("Table 3.1  kappa_i, square hole, H = 1/20, h = H/2\n%4s %12s %12s\n", "i", "eps=0", "eps=0.05");
  for (const auto& r : t31) std::printf("%4d %12.3e %12.3e\n", r.i, r.kappa_eps0, r.kappa_eps005);
  std::printf("\nTable 3.2  delta_i on Gamma, analytic local solution\n%8s %4s %12s %12s\n", "H", "i", "delta", "rho");
  for (const auto& r : t32) {
    std::printf("%8s %4d %12.3e ", ("1/" + std::to_string(int(std::lround(1 / r.H)))).c_str(), r.i, r.delta);
    if (r.rho) std::printf("%12.3e\n", *r.rho); else std::printf("%12s\n", "-");
  }
  std::printf("\nTable 3.3  kappa_i and sigma = kappa(H/2)/kappa(H)\n%8s %4s %12s %12s\n", "H", "i", "kappa", "sigma");
  for (const auto& r : t33) {
    std::printf("%8s %4d %12.3e ", ("1/" + std::to_string(int(std::lround(1 / r.H)))).c_str(), r.i, r.kappa);
    if (r.sigma) std::printf("%12.3e\n", *r.sigma); else std::printf("%12s\n", "-");
  }
  std::printf("\nTable 3.4  Schwarz process, nu_i and tau_i\n%4s %12s %12s\n", "i", "nu", "tau");
  for (const auto& r : t34) {
    std::printf("%4d %12.3e ", r.i, r.nu);
    if (r.tau) std::printf("%12.3e\n", *r.tau); else std::printf("%12s\n", "-");
  }
  std::printf("\nFig. 3.6  finite-difference local solution, relative charge error\n");
  std::printf("  disc 1: %.3e   disc 2: %.3e   (g1 = %.6f, g2 = %.6f)\n", f36.charge_error_1, f36.charge_error_2, f36.g1,
              f36.g2);
}

// Progress of `ldc solve` on stderr (CLI.md: long runs show progress): a line before the
// factorisation of a large coarse grid (one opaque step: 100 s CPU, 3.4 GB at 2048 x 2048 cells),
// then, once the solve has taken 2 s, one line every 5 s with the iteration and its changes.
class SolveProgress {
 public:
  explicit SolveProgress(bool enabled) : enabled_(enabled), start_(clock::now()), last_(start_) {}
  double elapsed_s() const { return std::chrono::duration<double>(clock::now() - start_).count(); }
  void say(const std::string& line) {
    if (enabled_) std::fprintf(stderr, "ldc solve: %s\n", line.c_str());
  }
  void iteration(const nipdem::ldc::SolveStats& st, int max_iterations) {
    const auto now = clock::now();
    if (!enabled_ || std::chrono::duration<double>(now - start_).count() < 2.0 ||
        (printed_ && std::chrono::duration<double>(now - last_).count() < 5.0))
      return;
    printed_ = true;
    last_ = now;
    std::fprintf(stderr, "ldc solve: iteration %d of at most %d, change of the disc potentials %.3e V, %.1f s\n",
                 st.iterations, max_iterations, st.potential_change.empty() ? 0.0 : st.potential_change.back(),
                 elapsed_s());
  }

 private:
  using clock = std::chrono::steady_clock;
  bool enabled_, printed_ = false;
  clock::time_point start_, last_;
};

void run_solve(const std::string& path, bool as_json, bool quiet) {
  using namespace nipdem::ldc;
  const std::string text = nipdem::io::read_file(path);
  const bool is_toml = path.size() > 5 && path.compare(path.size() - 5, 5, ".toml") == 0;
  const Setup setup = parse_setup(text, path, is_toml);
  const Params& p = setup.params;
  const std::vector<Disc>& discs = setup.discs;
  // The solver names its component ("ldc"); a setup error must name the file as well.
  auto named = [&](const auto& f) {
    try {
      return f();
    } catch (const nipdem::InputError& e) {
      throw nipdem::InputError(path + ": " + e.what());
    }
  };
  SolveProgress progress(!quiet);
  const double nodes = double(p.cells_x + 1) * double(p.cells_y + 1);
  const bool large = nodes > 2.5e5;
  named([&] { validate(p); });  // before saying anything about the grid
  if (large)
    progress.say(fmt::format("factorising the coarse matrix of {} x {} cells ({:.2g} nodes; at 2048 x 2048 cells this "
                             "takes about 100 s of CPU and 3.4 GB)...", p.cells_x, p.cells_y, nodes));
  auto solver = named([&] { return std::make_unique<LdcSolver>(p); });
  if (large) progress.say(fmt::format("factorised in {:.1f} s", progress.elapsed_s()));
  solver->set_progress([&](const SolveStats& st) { progress.iteration(st, p.max_iterations); });
  const SolveStats& st = named([&]() -> const SolveStats& { return solver->solve(discs); });
  if (!st.converged) {
    // Not a result: the potentials and forces of an unfinished (or diverging) iteration. A failure
    // of the solver on this geometry, not an invalid value (exit 1), so nothing goes to stdout.
    const auto& pc = st.potential_change;
    const double last = pc.empty() ? 0.0 : pc.back(), first = pc.empty() ? 0.0 : pc.front();
    const bool diverged = !(last < first) && pc.size() > 1;
    throw std::runtime_error(fmt::format(
        "{}: the LDC iteration did not converge within max_iterations = {} (change of the disc potentials in the "
        "last iteration {:.3g} V, in the first {:.3g} V; stop test: below tolerance = {:g} times the largest "
        "potential){}; no result printed",
        path, p.max_iterations, last, first, p.tolerance,
        diverged ? ": it diverges for this geometry (seen for a large disc whose local domain is cut by the box "
                   "sides, e.g. radius 0.4 mm in a 1 mm box, whatever the grid)"
                 : ": raise max_iterations or tolerance"));
  }
  // Within validate()'s ranges every result is finite; should one not be, it is refused naming the
  // values it was computed from rather than printed as null.
  for (int k = 0; k < solver->disc_count(); ++k) {
    const auto f = solver->force(k);
    if (!std::isfinite(solver->potential(k)) || !std::isfinite(f.x) || !std::isfinite(f.y))
      nipdem::throw_input(path, fmt::format("discs[{}]", k),
                          fmt::format("potential {} V, force ({}, {}) N/m", solver->potential(k), f.x, f.y),
                          "result not finite: check the scales permittivity_F_per_m, boundary.*.value_V, "
                          "discs[].radius_m and discs[].charge_C_per_m");
  }
  json out;
  out["iterations"] = st.iterations;
  out["converged"] = st.converged;
  out["discs"] = json::array();
  for (int k = 0; k < solver->disc_count(); ++k) {
    const auto f = solver->force(k);
    out["discs"].push_back({{"potential_V", solver->potential(k)},
                            {"force_N_per_m", {f.x, f.y}},
                            {"method", to_string(solver->method(k))}});
  }
  if (as_json) {
    nipdem::cli::print_json(out.dump());
    return;
  }
  std::printf("LDC: %d iterations, converged: %s\n%4s %14s %14s %14s  %s\n", st.iterations, st.converged ? "yes" : "no",
              "k", "g [V]", "Fx [N/m]", "Fy [N/m]", "local method");
  for (int k = 0; k < solver->disc_count(); ++k) {
    const auto f = solver->force(k);
    std::printf("%4d %14.6e %14.6e %14.6e  %s\n", k, solver->potential(k), f.x, f.y, to_string(solver->method(k)));
  }
}

nipdem::cli::Register reg([](CLI::App& app) {
  auto* ldc = nipdem::cli::group(app, "ldc");
  auto* ver = ldc->add_subcommand("verify", "Rerun the verification problems of thesis 3.8-3.10");
  auto vjson = std::make_shared<bool>(false);
  ver->add_flag("--json", *vjson, "print one JSON object");
  ver->callback([vjson] { run_verify(*vjson); });

  auto* sol = ldc->add_subcommand("solve", "Solve one disc configuration given in a JSON or TOML setup file");
  struct Opts { std::string path; bool json = false, quiet = false; };
  auto opts = std::make_shared<Opts>();
  sol->add_option("setup", opts->path, "setup file (.json or .toml, see docs/ldc.md)")->required();
  sol->add_flag("--json", opts->json, "print one JSON object");
  sol->add_flag("--quiet", opts->quiet, "no progress on stderr");
  sol->callback([opts] { run_solve(opts->path, opts->json, opts->quiet); });
});
}  // namespace
