#include "nipdem/experiments/ensemble.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <mutex>
#include <thread>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/version.hpp"
#include "nipdem/io/atomic_file.hpp"

#ifdef NIPDEM_HAVE_MPI
#include <mpi.h>
#endif

namespace nipdem::ensemble {

namespace fs = std::filesystem;

std::uint64_t realization_seed(std::uint64_t base_seed, std::size_t index) {
  return Rng::stream(base_seed, index).next_u64();
}

fs::path realization_path(const fs::path& dir, std::size_t index) {
  return dir / "realizations" / (std::to_string(index) + ".json");
}

nlohmann::json to_json(const Record& r) {
  nlohmann::json j{{"index", r.index}, {"seed", r.seed}, {"ok", r.ok}, {"wall_s", r.wall_s}, {"rank", r.rank}};
  if (!r.git_hash.empty()) j["git_hash"] = r.git_hash;
  if (r.ok) j["result"] = r.result;
  else j["error"] = r.error;
  return j;
}

Record record_from_json(const nlohmann::json& j) {
  Record r;
  r.index = j.at("index").get<std::size_t>();
  r.seed = j.at("seed").get<std::uint64_t>();
  r.ok = j.at("ok").get<bool>();
  r.wall_s = j.value("wall_s", 0.0);
  r.rank = j.value("rank", 0);
  r.git_hash = j.value("git_hash", std::string());
  if (r.ok) r.result = j.at("result");
  else r.error = j.value("error", std::string("unknown error"));
  return r;
}

bool mpi_available() {
#ifdef NIPDEM_HAVE_MPI
  return true;
#else
  return false;
#endif
}

MpiSession::MpiSession() {
#ifdef NIPDEM_HAVE_MPI
  int init = 0;
  MPI_Initialized(&init);
  if (!init) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    owns_ = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  throw InputError("--mpi: this nipdem was built without MPI (install OpenMPI and reconfigure)");
#endif
}

MpiSession::~MpiSession() {
#ifdef NIPDEM_HAVE_MPI
  if (owns_) {
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Finalize();
  }
#endif
}

namespace {

// Tries to load a finished realization; returns true if it can be skipped.
bool try_resume(const fs::path& dir, std::size_t index, std::uint64_t seed, Record& out) {
  const fs::path p = realization_path(dir, index);
  std::error_code ec;
  if (!fs::exists(p, ec)) return false;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(io::read_file(p));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nipdem: warning: %s unreadable (%s); recomputing realization %zu\n", p.c_str(), e.what(),
                 index);
    return false;
  }
  Record r;
  try {
    r = record_from_json(j);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nipdem: warning: %s malformed (%s); recomputing realization %zu\n", p.c_str(), e.what(), index);
    return false;
  }
  if (r.index != index || r.seed != seed)
    throw_input(p.string(), "seed", std::to_string(r.seed),
                fmt::format("realization {} was made with another base seed or index (this run: seed {}); use a new "
                            "output folder or the original --seed",
                            index, seed));
  if (!r.ok) return false;  // failed before: retry
  r.resumed = true;
  out = std::move(r);
  return true;
}

}  // namespace

Summary run(const Task& task, const Options& opts) {
  const std::string where = "ensemble";
  if (opts.count == 0) throw_input(where, "realizations", "0", "nothing to run", ">= 1");
  if (opts.jobs < 1) throw_input(where, "jobs", std::to_string(opts.jobs), "must be at least 1", ">= 1");
  if (!task) throw std::invalid_argument("ensemble::run: empty task");

  int rank = 0, size = 1;
  if (opts.mpi) {
#ifdef NIPDEM_HAVE_MPI
    int init = 0;
    MPI_Initialized(&init);
    if (!init) throw InputError("ensemble: --mpi given but MPI is not initialised (create an MpiSession first)");
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
#else
    throw InputError("--mpi: this nipdem was built without MPI (install OpenMPI and reconfigure)");
#endif
  }

  // This rank's indices, round-robin.
  std::vector<Record> mine;
  std::vector<std::size_t> todo;  // positions in `mine` still to compute
  std::string resume_error;
  try {
    for (std::size_t i = static_cast<std::size_t>(rank); i < opts.count; i += static_cast<std::size_t>(size)) {
      Record r;
      r.index = i;
      r.seed = realization_seed(opts.seed, i);
      r.rank = rank;
      if (!opts.dir.empty() && opts.resume && try_resume(opts.dir, i, r.seed, r)) {
        mine.push_back(std::move(r));
        continue;
      }
      todo.push_back(mine.size());
      mine.push_back(std::move(r));
    }
  } catch (const InputError& e) {
    resume_error = e.what();
  }
#ifdef NIPDEM_HAVE_MPI
  if (opts.mpi && size > 1) {  // all ranks stop together, so none waits forever in the gather
    int bad = resume_error.empty() ? 0 : 1, any_bad = 0;
    MPI_Allreduce(&bad, &any_bad, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any_bad && resume_error.empty()) resume_error = "ensemble: another MPI rank found invalid resume data";
  }
#endif
  if (!resume_error.empty()) throw InputError(resume_error);

  std::atomic<std::size_t> next{0};
  std::mutex progress_mutex;
  std::size_t done = 0;
  auto worker = [&] {
    while (true) {
      const std::size_t k = next.fetch_add(1);
      if (k >= todo.size()) break;
      Record& r = mine[todo[k]];
      const auto t0 = std::chrono::steady_clock::now();
      try {
        r.result = task(r.index, r.seed);
        r.ok = true;
      } catch (const std::exception& e) {
        r.ok = false;
        r.error = e.what();
      } catch (...) {
        r.ok = false;
        r.error = "unknown exception (not derived from std::exception)";
      }
      r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      r.git_hash = kGitHash;  // a resumed study may mix builds: each realization says which ran it
      if (!opts.dir.empty()) {
        try {
          io::write_file_atomic(realization_path(opts.dir, r.index), to_json(r).dump(1) + "\n");
        } catch (const std::exception& e) {
          // Keep the result in memory and report that it could not be saved.
          if (r.ok) {
            r.ok = false;
            r.error = std::string("result computed but not saved: ") + e.what();
          }
        }
      }
      std::lock_guard<std::mutex> lock(progress_mutex);
      ++done;
      if (opts.progress) opts.progress(done, todo.size());
    }
  };
  const int nthreads = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(opts.jobs), std::max<std::size_t>(todo.size(), 1)));
  if (nthreads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int k = 0; k < nthreads; ++k) pool.emplace_back(worker);
    for (auto& th : pool) th.join();
  }

  Summary s;
  s.ranks = size;
  s.is_root = rank == 0;
  std::vector<Record> all;
#ifdef NIPDEM_HAVE_MPI
  if (opts.mpi && size > 1) {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& r : mine) {
      auto j = to_json(r);
      j["resumed"] = r.resumed;
      arr.push_back(std::move(j));
    }
    const std::string buf = arr.dump();
    int len = static_cast<int>(buf.size());
    std::vector<int> lens(rank == 0 ? size : 0), displs(rank == 0 ? size : 0);
    MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::string recv;
    if (rank == 0) {
      int total = 0;
      for (int k = 0; k < size; ++k) {
        displs[k] = total;
        total += lens[k];
      }
      recv.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(buf.data(), len, MPI_CHAR, recv.data(), lens.data(), displs.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
    if (rank == 0) {
      for (int k = 0; k < size; ++k) {
        const auto part = nlohmann::json::parse(recv.substr(static_cast<std::size_t>(displs[k]), static_cast<std::size_t>(lens[k])));
        for (const auto& j : part) {
          Record r = record_from_json(j);
          r.resumed = j.value("resumed", false);
          all.push_back(std::move(r));
        }
      }
    }
  } else {
    all = std::move(mine);
  }
#else
  all = std::move(mine);
#endif
  if (!s.is_root) return s;
  std::sort(all.begin(), all.end(), [](const Record& a, const Record& b) { return a.index < b.index; });
  for (const auto& r : all) {
    if (r.ok) ++s.n_ok;
    else ++s.n_failed;
    if (r.resumed) ++s.n_resumed;
    else s.ran_indices.push_back(r.index);
  }
  s.n_run = s.ran_indices.size();
  s.records = std::move(all);
  return s;
}

}  // namespace nipdem::ensemble
