// Ensembles of independent realizations / sweep points (CLI.md: --jobs, --mpi, --seed).
//
//   ensemble::Options o;  o.count = 50;  o.seed = 7;  o.jobs = 2;  o.dir = out / "edge";
//   auto sum = ensemble::run([&](std::size_t i, std::uint64_t seed) {
//     return nlohmann::json{{"coverage", simulate_line(seed)}};
//   }, o);
//   for (auto& r : sum.records) if (r.ok) use(r.result);   // index order, on rank 0
//
// * Seeds: realization i gets realization_seed(seed, i), independent of the number of threads
//   or ranks, so serial, threaded and MPI runs give identical results.
// * Resume: with a `dir`, every finished realization is written atomically to
//   dir/realizations/<index>.json ({"index","seed","ok","result"|"error","wall_s"}). A rerun
//   skips the indices whose file says ok with the same seed (a file made with another seed is
//   an InputError: results would be mixed); failed ones are retried.
// * Failures: a task that throws is recorded (ok = false, error = what()) in its file and in
//   the summary; it is never silently dropped. The caller decides the exit status.
// * MPI (only with opts.mpi; needs NIPDEM_HAVE_MPI and an MpiSession alive): index i runs on
//   rank i mod size (each rank with `jobs` threads); records are gathered on rank 0 in index
//   order. Other ranks get an empty `records` and is_root = false. Requires a file system
//   shared by the ranks when `dir` is used.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nipdem::ensemble {

using Task = std::function<nlohmann::json(std::size_t index, std::uint64_t seed)>;

// Seed of realization `index` derived from the base seed (Rng::stream).
std::uint64_t realization_seed(std::uint64_t base_seed, std::size_t index);

struct Options {
  std::size_t count = 0;          // realizations 0 .. count-1
  std::uint64_t seed = 1;         // base seed
  int jobs = 1;                   // threads (per rank)
  std::filesystem::path dir;      // empty: keep results in memory only (no resume)
  bool resume = true;             // skip realizations already finished in dir
  bool mpi = false;               // spread over MPI ranks (see above)
  // Called (from worker threads, serialised) after each realization finishes on this rank.
  std::function<void(std::size_t done, std::size_t total_on_rank)> progress;
};

struct Record {
  std::size_t index = 0;
  std::uint64_t seed = 0;
  bool ok = false;
  bool resumed = false;           // loaded from dir, not recomputed in this run
  nlohmann::json result;          // task output when ok
  std::string error;              // what() when failed
  double wall_s = 0;              // wall time of the computation
  int rank = 0;                   // MPI rank that computed it (0 without MPI)
  std::string git_hash;           // build that computed it ("" in records written before it was kept)
};

struct Summary {
  std::vector<Record> records;    // index order (all indices on rank 0; empty on other ranks)
  std::size_t n_ok = 0, n_failed = 0, n_resumed = 0, n_run = 0;
  std::vector<std::size_t> ran_indices;  // computed in this run (not resumed), sorted
  int ranks = 1;
  bool is_root = true;
};

// Runs the ensemble. Throws InputError for bad options (count 0, jobs < 1, mpi without MPI
// support or without an initialised MPI, resume file with another seed).
Summary run(const Task& task, const Options& opts);

// Record <-> JSON (the per-realization file format).
nlohmann::json to_json(const Record& r);
Record record_from_json(const nlohmann::json& j);
std::filesystem::path realization_path(const std::filesystem::path& dir, std::size_t index);

// RAII MPI lifetime for a CLI command: initialises MPI (MPI_THREAD_FUNNELED) if it is not yet
// initialised and finalises it in the destructor if it did the init. Create it only in --mpi
// mode. Without MPI support the constructor throws InputError.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  bool owns_ = false;
  int rank_ = 0, size_ = 1;
};

// True if this binary was built with MPI.
bool mpi_available();

}  // namespace nipdem::ensemble
