// Ensemble runner: deterministic seeds, threads, resume, failure recording.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <mutex>
#include <set>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/experiments/ensemble.hpp"
#include "nipdem/experiments/experiment.hpp"
#include "nipdem/io/atomic_file.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;
namespace fs = std::filesystem;

namespace {
// A deterministic stochastic computation: mean of 1000 uniforms from the realization's seed.
nlohmann::json walk(std::size_t i, std::uint64_t seed) {
  Rng r(seed);
  double s = 0;
  for (int k = 0; k < 1000; ++k) s += r.uniform();
  return {{"index_seen", i}, {"mean", s / 1000}};
}
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}
}  // namespace

TEST(AnalysisEnsemble, ThreadedEqualsSerialAndSeedsAreIndependentOfJobs) {
  ensemble::Options o;
  o.count = 23;
  o.seed = 42;
  const auto serial = ensemble::run(walk, o);
  o.jobs = 4;
  const auto threaded = ensemble::run(walk, o);
  ASSERT_EQ(serial.records.size(), 23u);
  ASSERT_EQ(threaded.records.size(), 23u);
  std::set<std::uint64_t> seeds;
  for (std::size_t i = 0; i < 23; ++i) {
    EXPECT_EQ(serial.records[i].index, i);
    EXPECT_EQ(threaded.records[i].index, i);
    EXPECT_EQ(serial.records[i].seed, ensemble::realization_seed(42, i));
    EXPECT_EQ(serial.records[i].result, threaded.records[i].result);  // bitwise equal doubles
    seeds.insert(serial.records[i].seed);
  }
  EXPECT_EQ(seeds.size(), 23u);  // distinct streams
  EXPECT_EQ(threaded.n_ok, 23u);
  EXPECT_EQ(threaded.n_run, 23u);
  EXPECT_EQ(threaded.n_resumed, 0u);
}

TEST(AnalysisEnsemble, ResumeSkipsFinishedRealizations) {
  const fs::path dir = fresh_dir("resume");
  std::mutex m;
  std::vector<std::size_t> calls;
  auto task = [&](std::size_t i, std::uint64_t seed) {
    {
      std::lock_guard<std::mutex> l(m);
      calls.push_back(i);
    }
    return walk(i, seed);
  };
  ensemble::Options o;
  o.count = 12;
  o.seed = 3;
  o.jobs = 3;
  o.dir = dir;
  const auto first = ensemble::run(task, o);
  ASSERT_EQ(calls.size(), 12u);
  for (std::size_t i = 0; i < 12; ++i) ASSERT_TRUE(fs::exists(ensemble::realization_path(dir, i)));

  // Simulate an interrupted run: three results are missing.
  for (std::size_t i : {1u, 7u, 11u}) fs::remove(ensemble::realization_path(dir, i));
  calls.clear();
  const auto second = ensemble::run(task, o);
  std::sort(calls.begin(), calls.end());
  EXPECT_EQ(calls, (std::vector<std::size_t>{1, 7, 11}));
  EXPECT_EQ(second.ran_indices, (std::vector<std::size_t>{1, 7, 11}));
  EXPECT_EQ(second.n_resumed, 9u);
  for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(second.records[i].result, first.records[i].result) << i;

  // Nothing left to do: no calls at all.
  calls.clear();
  const auto third = ensemble::run(task, o);
  EXPECT_TRUE(calls.empty());
  EXPECT_EQ(third.n_resumed, 12u);

  // Another base seed in the same folder would mix results: refused.
  o.seed = 4;
  EXPECT_THROW(ensemble::run(task, o), InputError);
  fs::remove_all(dir);
}

// A study resumed by another build mixes builds; each realization file says which computed it,
// and a record written before the key existed reads back as "" (reported as "unrecorded").
TEST(AnalysisEnsemble, EachRealizationRecordsTheBuildThatComputedIt) {
  const fs::path dir = fresh_dir("builds");
  ensemble::Options o;
  o.count = 4;
  o.seed = 9;
  o.dir = dir;
  ensemble::run(walk, o);
  // Realization 2 as an older build wrote it (no git_hash), realization 3 from another build.
  auto rewrite = [&](std::size_t i, const char* hash) {
    const fs::path f = ensemble::realization_path(dir, i);
    auto j = nlohmann::json::parse(io::read_file(f));
    EXPECT_EQ(j.at("git_hash").get<std::string>(), kGitHash);
    if (hash) j["git_hash"] = hash;
    else j.erase("git_hash");
    io::write_file_atomic(f, j.dump());
  };
  rewrite(2, nullptr);
  rewrite(3, "0123456789ab");
  fs::remove(ensemble::realization_path(dir, 0));
  const auto s = ensemble::run(walk, o);
  ASSERT_EQ(s.records.size(), 4u);
  EXPECT_EQ(s.records[0].git_hash, kGitHash);  // recomputed now
  EXPECT_EQ(s.records[1].git_hash, kGitHash);  // resumed, from this build
  EXPECT_EQ(s.records[2].git_hash, "");
  EXPECT_EQ(s.records[3].git_hash, "0123456789ab");
  fs::remove_all(dir);
}

TEST(AnalysisEnsemble, MetaCountsTheRealizationsOfEachBuild) {
  ensemble::Summary s;
  for (const char* h : {"aaa", "", "aaa", "bbb"}) {
    s.records.emplace_back();
    s.records.back().git_hash = h;
  }
  const auto m = experiments::meta(experiments::ExperimentOptions{}, &s);
  const auto b = m.at("realization_builds");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0], (nlohmann::json{{"git_hash", "aaa"}, {"realizations", 2}}));
  EXPECT_EQ(b[1], (nlohmann::json{{"git_hash", "unrecorded"}, {"realizations", 1}}));
  EXPECT_EQ(b[2], (nlohmann::json{{"git_hash", "bbb"}, {"realizations", 1}}));
  EXPECT_EQ(m.at("git_hash").get<std::string>(), kGitHash);
  EXPECT_FALSE(experiments::meta(experiments::ExperimentOptions{}).contains("realization_builds"));
}

TEST(AnalysisEnsemble, FailedRealizationIsRecordedReportedAndRetried) {
  const fs::path dir = fresh_dir("fail");
  std::atomic<int> calls{0};
  auto flaky = [&](std::size_t i, std::uint64_t seed) {
    ++calls;
    if (i == 2) throw std::runtime_error("solver diverged at step 17");
    return walk(i, seed);
  };
  ensemble::Options o;
  o.count = 5;
  o.jobs = 2;
  o.dir = dir;
  const auto s = ensemble::run(flaky, o);
  EXPECT_EQ(s.n_ok, 4u);
  EXPECT_EQ(s.n_failed, 1u);
  ASSERT_EQ(s.records.size(), 5u);
  EXPECT_FALSE(s.records[2].ok);
  EXPECT_EQ(s.records[2].error, "solver diverged at step 17");
  const auto j = nlohmann::json::parse(io::read_file(ensemble::realization_path(dir, 2)));
  EXPECT_FALSE(j.at("ok").get<bool>());
  EXPECT_EQ(j.at("error").get<std::string>(), "solver diverged at step 17");

  // Rerun with the bug fixed: only the failed realization runs again.
  calls = 0;
  const auto fixed = ensemble::run(walk, o);
  EXPECT_EQ(fixed.ran_indices, (std::vector<std::size_t>{2}));
  EXPECT_EQ(fixed.n_failed, 0u);
  fs::remove_all(dir);
}

TEST(AnalysisEnsemble, BadOptions) {
  ensemble::Options o;
  EXPECT_THROW(ensemble::run(walk, o), InputError);  // count 0
  o.count = 3;
  o.jobs = 0;
  EXPECT_THROW(ensemble::run(walk, o), InputError);
  o.jobs = 1;
  o.mpi = true;  // no MpiSession (or no MPI at all)
  EXPECT_THROW(ensemble::run(walk, o), InputError);
}
