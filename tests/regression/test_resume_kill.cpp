// Resume exact on disk (issue 21): a run killed with SIGKILL at many moments, half of them between
// a temp file's write and its rename (fault injection NIPDEM_FAULT_KILL_AT_WRITE, io/atomic_file),
// then resumed with --resume, leaves exactly the files of an uninterrupted run, byte for byte:
// particle frames, particles.pvd, frames.json, timeseries.csv, removals.csv, config.toml; no temp
// file is left behind. summary.json agrees except for wall-clock fields and "resumed"; the final
// checkpoints hold the same physical state (their neighbour lists may hold different
// non-touching pairs, depending on when each was rebuilt, so they are compared after loading).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../cli_run.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/nip_config.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> m;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) m[fs::relative(e.path(), dir).string()] = nipdem::io::read_file(e.path(), nipdem::io::kMaxCheckpointBytes);
  return m;
}
nlohmann::json stable_summary(const std::string& text) {
  auto j = nlohmann::json::parse(text);
  for (const char* k : {"wall_time_s", "steps_this_session", "neighbor_list_builds_this_session", "dipole_list_builds_this_session", "pair_sublist_builds_this_session", "disc_steps_per_s", "wall_s_per_simulated_ms", "resumed"}) j.erase(k);
  return j;
}
}  // namespace

TEST(ResumeOnDisk, KilledAtManyMomentsThenResumedGivesTheUninterruptedFiles) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_killresume_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const std::string cfg = std::string(NIPDEM_SOURCE_DIR) + "/data/presets/black.toml";
  const std::string sets =
      " --quiet --set geometry.window_x_min_m=-100e-6 --set geometry.window_x_max_m=100e-6 --set collision.stiffness_scale=0.01"
      " --set output.vtk=true --set magnet.dipole_dipole=true --set run.end_time_s=1.2e-5 --set run.output_interval_s=2e-6"
      " --set run.checkpoint_interval_s=4e-6";
  const std::string nip = std::string(NIPDEM_CLI_PATH) + " run " + cfg + sets + " --out ";
  std::vector<std::string> overrides;  // the same --set list, for loading the checkpoints
  for (std::size_t at = sets.find("--set "); at != std::string::npos; at = sets.find("--set ", at + 1)) {
    const auto b = at + 6, e = sets.find(' ', b);
    overrides.push_back(sets.substr(b, e == std::string::npos ? std::string::npos : e - b));
  }
  const auto ref = nipdem::test::run_cli_command(nip + (d / "ref").string(), "killresume");
  ASSERT_EQ(ref.status, 0) << ref.err;
  const auto want = files_of(d / "ref");
  // 7 snapshots x 4 files, 4 checkpoints x 2 files, config and summary: ~38 writes
  int killed = 0;
  for (int n = 1; n <= 37; n += 3) {
    const std::string mode = (n / 3) % 2 == 0 ? "before" : "after";
    SCOPED_TRACE("killed at write " + std::to_string(n) + " (" + mode + " the rename)");
    const fs::path out = d / ("k" + std::to_string(n));
    const auto k = nipdem::test::run_cli_command("NIPDEM_FAULT_KILL_AT_WRITE=" + std::to_string(n) + ":" + mode + " " + nip + out.string(), "killresume");
    ASSERT_TRUE(k.status == -1 || k.status == 128 + 9) << "not killed: " << k.status << " " << k.err;
    ++killed;
    const auto r = nipdem::test::run_cli_command(nip + out.string() + " --resume", "killresume");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto got = files_of(out);
    std::string names_want, names_got;
    for (const auto& [f, _] : want) names_want += f + " ";
    for (const auto& [f, _] : got) names_got += f + " ";
    ASSERT_EQ(names_got, names_want) << "the same files, no temp file left";
    for (const auto& [f, text] : want) {
      if (f == "summary.json") {
        EXPECT_EQ(stable_summary(got.at(f)), stable_summary(text));
      } else if (f != "checkpoint.bin") {
        EXPECT_TRUE(got.at(f) == text) << f << " differs";
      }
    }
    // the final checkpoints: the same physical state
    nipdem::nip::NipRun a(nipdem::nip::load_nip_config(cfg, overrides));
    nipdem::nip::NipRun b(nipdem::nip::load_nip_config(cfg, overrides));
    a.restore(want.at("checkpoint.bin"), "ref");
    b.restore(got.at("checkpoint.bin"), "resumed");
    EXPECT_EQ(a.sim().time(), b.sim().time());
    const auto& ba = a.sim().bodies();
    const auto& bb = b.sim().bodies();
    ASSERT_EQ(ba.x.size(), bb.x.size());
    for (std::size_t i = 0; i < ba.x.size(); ++i) {
      ASSERT_EQ(ba.x[i], bb.x[i]);
      ASSERT_EQ(ba.vy[i], bb.vy[i]);
      ASSERT_EQ(ba.omega[i], bb.omega[i]);
    }
  }
  EXPECT_GE(killed, 12);
  fs::remove_all(d);
}
