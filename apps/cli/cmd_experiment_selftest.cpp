// `nipdem experiment selftest`: a test harness for the ensemble machinery (threads, MPI,
// resume, failure reporting), not a physics experiment. Each realization is a seeded random
// walk of --steps standard-normal increments; its statistics are deterministic for a given
// --seed, so serial, --jobs N and `mpirun -np P ... --mpi` runs must print identical
// "results". Used by tests/regression/test_mpi_ensemble.cpp; see docs/ensembles.md.
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/experiments/ensemble.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  std::size_t realizations = 8;
  int jobs = 1;
  bool mpi = false;
  std::uint64_t seed = 1;
  std::size_t steps = 1000;
  std::string out;
  bool no_resume = false;
  std::vector<std::size_t> fail_index;
  int sleep_ms = 0;
  bool json = false;
};

nlohmann::json random_walk(std::uint64_t seed, std::size_t steps) {
  nipdem::Rng rng(seed);
  double x = 0, max_abs = 0, sum_sq = 0;
  for (std::size_t k = 0; k < steps; ++k) {
    x += rng.normal();
    max_abs = std::max(max_abs, std::abs(x));
    sum_sq += x * x;
  }
  return {{"final_position", x}, {"max_abs_position", max_abs}, {"mean_square_position", sum_sq / steps}};
}

void run_selftest(const Opts& o) {
  std::unique_ptr<nipdem::ensemble::MpiSession> mpi;
  if (o.mpi) mpi = std::make_unique<nipdem::ensemble::MpiSession>();  // MPI_Init only in --mpi mode
  if (o.steps == 0) nipdem::throw_input("experiment selftest", "steps", "0", "must be at least 1");

  nipdem::ensemble::Options eo;
  eo.count = o.realizations;
  eo.seed = o.seed;
  eo.jobs = o.jobs;
  eo.dir = o.out;
  eo.resume = !o.no_resume;
  eo.mpi = o.mpi;
  const auto fails = o.fail_index;
  const std::size_t steps = o.steps;
  const int sleep_ms = o.sleep_ms;
  auto task = [fails, steps, sleep_ms](std::size_t i, std::uint64_t seed) {
    if (sleep_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms));
    for (auto f : fails)
      if (f == i) throw std::runtime_error("injected failure (--fail-index " + std::to_string(i) + ")");
    return random_walk(seed, steps);
  };
  const auto s = nipdem::ensemble::run(task, eo);
  if (!s.is_root) return;  // only rank 0 reports

  nlohmann::json results = nlohmann::json::array(), failures = nlohmann::json::array();
  double sum_final = 0, sum_final_sq = 0;
  std::size_t n_ok = 0;
  for (const auto& r : s.records) {
    nlohmann::json j{{"index", r.index}, {"seed", r.seed}, {"ok", r.ok}};
    if (r.ok) {
      for (auto& [k, v] : r.result.items()) j[k] = v;
      const double xf = r.result.at("final_position").get<double>();
      sum_final += xf;
      sum_final_sq += xf * xf;
      ++n_ok;
    } else {
      j["error"] = r.error;
      failures.push_back({{"index", r.index}, {"error", r.error}});
    }
    results.push_back(std::move(j));
  }
  nlohmann::json out{{"harness", "ensemble selftest (seeded random walks; not a physics result)"},
                     {"realizations", o.realizations},
                     {"seed", o.seed},
                     {"steps", o.steps},
                     {"jobs", o.jobs},
                     {"mpi", o.mpi},
                     {"mpi_ranks", s.ranks},
                     {"n_ok", s.n_ok},
                     {"n_failed", s.n_failed},
                     {"n_resumed", s.n_resumed},
                     {"n_run", s.n_run},
                     {"ran_indices", s.ran_indices},
                     {"results", results},
                     {"failures", failures},
                     {"mean_final_position", n_ok ? sum_final / n_ok : 0.0},
                     {"mean_square_final_position", n_ok ? sum_final_sq / n_ok : 0.0},
                     {"expected_mean_square_final_position", static_cast<double>(o.steps)},
                     {"out_dir", o.out.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.out)}};
  if (o.json) {
    nipdem::cli::print_json(out.dump());
  } else {
    std::printf("ensemble selftest: %zu realizations, seed %llu, %d job(s), %d rank(s)\n", o.realizations,
                static_cast<unsigned long long>(o.seed), o.jobs, s.ranks);
    std::printf("  ok %zu, failed %zu, resumed %zu, computed now %zu\n", s.n_ok, s.n_failed, s.n_resumed, s.n_run);
    std::printf("  <x_final^2> = %.4g (expected %zu for unit steps)\n", n_ok ? sum_final_sq / n_ok : 0.0, o.steps);
    for (const auto& f : failures)
      std::printf("  FAILED realization %zu: %s\n", f["index"].get<std::size_t>(), f["error"].get<std::string>().c_str());
  }
  if (s.n_failed > 0)
    throw std::runtime_error(std::to_string(s.n_failed) + " realization(s) failed (see \"failures\"); rerun with the same "
                             "--out to retry only those");
}

nipdem::cli::Register reg([](CLI::App& app) {
  auto* exp = nipdem::cli::group(app, "experiment");
  auto* sub = exp->add_subcommand(
      "selftest", "Test harness of the ensemble machinery (threads, MPI, resume) with seeded random walks");
  sub->group("");  // a test harness: hidden from the user's help (it still runs, with its own --help)
  auto o = std::make_shared<Opts>();
  sub->add_option("--realizations", o->realizations, "number of realizations")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--jobs", o->jobs, "threads (per MPI rank)")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_flag("--mpi", o->mpi, "spread realizations over MPI ranks (run under mpirun)");
  sub->add_option("--seed", o->seed, "base seed")->capture_default_str();
  sub->add_option("--steps", o->steps, "random-walk steps per realization")->capture_default_str();
  sub->add_option("--out", o->out, "folder for per-realization results (enables resume)");
  sub->add_flag("--no-resume", o->no_resume, "recompute realizations already in --out");
  sub->add_option("--fail-index", o->fail_index, "make these realizations throw (tests failure reporting)")->delimiter(',');
  sub->add_option("--sleep-ms", o->sleep_ms, "sleep per realization [ms] (to test interruption)")->capture_default_str();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o] { run_selftest(*o); });
});

}  // namespace
