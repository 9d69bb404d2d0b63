// Ensemble machinery end to end through the CLI (`nipdem experiment selftest`):
// MPI (mpirun -np 2 --mpi) gathers exactly the threaded result, an interrupted (SIGKILL) run
// resumes without redoing finished realizations, failures exit 1 and are reported.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace {

struct ShellRun {
  int status = -1;
  std::string out;
};
ShellRun sh(const std::string& cmd) {
  ShellRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 8192> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}
std::string cli() { return std::string(NIPDEM_CLI_PATH); }
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_reg_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}
// The parts of the selftest JSON that must not depend on how the work was spread.
nlohmann::json invariant(const nlohmann::json& j) {
  return {{"results", j.at("results")},
          {"mean_final_position", j.at("mean_final_position")},
          {"mean_square_final_position", j.at("mean_square_final_position")},
          {"n_ok", j.at("n_ok")},
          {"seed", j.at("seed")}};
}

}  // namespace

TEST(AnalysisMpiEnsemble, MpirunGatherEqualsThreadedResult) {
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "mpirun not found; MPI test skipped";
#ifndef NIPDEM_HAVE_MPI
  FAIL() << "mpirun is installed but nipdem was built without MPI (CMake did not find MPI C++)";
#endif
  const std::string args = " experiment selftest --realizations 11 --steps 2000 --seed 17 --json";
  const ShellRun threaded = sh(cli() + args + " --jobs 2 2>/dev/null");
  ASSERT_EQ(threaded.status, 0);
  const ShellRun mpi = sh("mpirun --allow-run-as-root --oversubscribe -np 2 " + cli() + args + " --mpi 2>/dev/null");
  ASSERT_EQ(mpi.status, 0) << mpi.out;
  // Exactly one JSON document on stdout (only rank 0 prints).
  const auto jt = nlohmann::json::parse(threaded.out);
  const auto jm = nlohmann::json::parse(mpi.out);
  EXPECT_EQ(jm.at("mpi_ranks").get<int>(), 2);
  EXPECT_EQ(jt.at("results").size(), 11u);
  EXPECT_EQ(invariant(jm), invariant(jt));  // bitwise-equal doubles: same seeds, same code
}

TEST(AnalysisMpiEnsemble, MpiResumeUsesSharedFolder) {
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "mpirun not found; MPI test skipped";
#ifndef NIPDEM_HAVE_MPI
  FAIL() << "mpirun is installed but nipdem was built without MPI (CMake did not find MPI C++)";
#endif
  const fs::path dir = fresh_dir("mpi_resume");
  const std::string args = " experiment selftest --realizations 6 --steps 500 --json --out " + dir.string();
  const ShellRun first = sh(cli() + args + " 2>/dev/null");
  ASSERT_EQ(first.status, 0);
  fs::remove(dir / "realizations" / "4.json");
  fs::remove(dir / "realizations" / "5.json");
  const ShellRun again = sh("mpirun --allow-run-as-root --oversubscribe -np 2 " + cli() + args + " --mpi 2>/dev/null");
  ASSERT_EQ(again.status, 0);
  const auto j = nlohmann::json::parse(again.out);
  EXPECT_EQ(j.at("ran_indices"), nlohmann::json::array({4, 5}));  // one on each rank
  EXPECT_EQ(invariant(j), invariant(nlohmann::json::parse(first.out)));
  fs::remove_all(dir);
}

TEST(AnalysisMpiEnsemble, KilledRunResumesWithoutRedoingFinishedRealizations) {
  // Reference: the complete ensemble without interruption.
  const std::string base = " experiment selftest --realizations 20 --steps 500 --seed 5 --jobs 1 --json";
  const ShellRun ref = sh(cli() + base + " 2>/dev/null");
  ASSERT_EQ(ref.status, 0);
  // Interrupted run: >= 100 ms per realization (>= 2 s in all), SIGKILL after 1 s, so at most
  // 10 and (unless start-up takes 0.9 s) at least 1 realization finished.
  const fs::path dir = fresh_dir("killed");
  const std::string slow = cli() + base + " --sleep-ms 100 --out " + dir.string();
  const ShellRun killed = sh("timeout -s KILL 1 " + slow + " >/dev/null 2>&1; echo $?");
  ASSERT_EQ(killed.out, "137\n") << "the run was expected to be killed";
  std::size_t finished = 0;
  for (std::size_t i = 0; i < 20; ++i)
    if (fs::exists(dir / "realizations" / (std::to_string(i) + ".json"))) ++finished;
  ASSERT_GT(finished, 0u);
  ASSERT_LE(finished, 10u);
  // Resume (no sleep needed): only the missing realizations run, results equal the reference.
  const ShellRun resumed = sh(cli() + base + " --out " + dir.string() + " 2>/dev/null");
  ASSERT_EQ(resumed.status, 0);
  const auto j = nlohmann::json::parse(resumed.out);
  EXPECT_EQ(j.at("n_resumed").get<std::size_t>(), finished);
  EXPECT_EQ(j.at("n_run").get<std::size_t>(), 20 - finished);
  for (const auto& i : j.at("ran_indices"))
    EXPECT_GE(i.get<std::size_t>(), finished) << "finished realization " << i << " was recomputed";  // --jobs 1: in order
  EXPECT_EQ(invariant(j), invariant(nlohmann::json::parse(ref.out)));
  fs::remove_all(dir);
}

TEST(AnalysisMpiEnsemble, FailedRealizationExitsOneAndIsReported) {
  const fs::path dir = fresh_dir("failcli");
  const std::string base = cli() + " experiment selftest --realizations 5 --steps 100 --jobs 2 --json --out " + dir.string();
  const ShellRun bad = sh(base + " --fail-index 1,3 2>/dev/null");
  EXPECT_EQ(bad.status, 1);
  const auto j = nlohmann::json::parse(bad.out);
  EXPECT_EQ(j.at("n_failed").get<int>(), 2);
  ASSERT_EQ(j.at("failures").size(), 2u);
  EXPECT_EQ(j.at("failures")[0].at("index").get<int>(), 1);
  EXPECT_NE(j.at("failures")[0].at("error").get<std::string>().find("injected failure"), std::string::npos);
  const ShellRun retry = sh(base + " 2>/dev/null");
  EXPECT_EQ(retry.status, 0);
  EXPECT_EQ(nlohmann::json::parse(retry.out).at("ran_indices"), nlohmann::json::array({1, 3}));
  // Bad usage exits 2.
  EXPECT_EQ(sh(cli() + " experiment selftest --realizations 0 --json 2>/dev/null").status, 2);
  fs::remove_all(dir);
}
