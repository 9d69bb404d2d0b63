// `nipdem ldc verify [--json]`: reruns the LDC verification problems of thesis §3.8-3.10.
// `nipdem ldc solve SETUP.{json,toml} [--json]`: solves one disc configuration (see docs/ldc.md).
#include <cstdint>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
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

void run_solve(const std::string& path, bool as_json) {
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
  auto solver = named([&] { return std::make_unique<LdcSolver>(p); });
  const SolveStats& st = named([&]() -> const SolveStats& { return solver->solve(discs); });
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
  struct Opts { std::string path; bool json = false; };
  auto opts = std::make_shared<Opts>();
  sol->add_option("setup", opts->path, "setup file (.json or .toml, see docs/ldc.md)")->required();
  sol->add_flag("--json", opts->json, "print one JSON object");
  sol->callback([opts] { run_solve(opts->path, opts->json); });
});
}  // namespace
