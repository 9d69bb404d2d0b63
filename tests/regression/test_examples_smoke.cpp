// Every shipped example config is also a smoke test (docs/ARCHITECTURE.md, "examples/"): each
// examples/*.toml and examples/patterns/*.toml is loaded, validated and run for a few steps by
// the CLI, and must exit 0 with a summary.json and the complete resolved config.toml. An
// example that a config change breaks (a renamed key, a value now out of range) fails here
// instead of in a user's hands. The calibration records and field maps have their own tests
// (test_calibration_examples, test_shipped_maps); the Python examples run in tests/python.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "../cli_run.hpp"

namespace fs = std::filesystem;

TEST(ExamplesSmoke, EveryExampleConfigRunsAFewSteps) {
  const fs::path src(NIPDEM_SOURCE_DIR);
  std::vector<fs::path> configs;
  for (const fs::path dir : {src / "examples", src / "examples" / "patterns"})
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().extension() == ".toml") configs.push_back(e.path());
  std::sort(configs.begin(), configs.end());
  ASSERT_GE(configs.size(), 7u) << "examples went missing";  // 3 nip configs + 4 print patterns today
  const fs::path tmp = fs::temp_directory_path() / ("nipdem_examples_smoke_" + std::to_string(::getpid()));
  for (const auto& cfg : configs) {
    const fs::path out = tmp / cfg.stem();
    // 2 us: a few dozen steps after set-up (the whole set-up path: preset overlay, validation,
    // initial assembly, field tables, print pattern); --force: no stale checkpoint interferes
    const auto r = nipdem::test::run_cli("run '" + cfg.string() + "' --set run.end_time_s=2e-6 --out '" + out.string() +
                                         "' --quiet --force", "examples_smoke");
    EXPECT_EQ(r.status, 0) << cfg << "\n" << r.err;
    EXPECT_TRUE(fs::exists(out / "summary.json")) << cfg;
    EXPECT_TRUE(fs::exists(out / "config.toml")) << cfg;
  }
  fs::remove_all(tmp);
}
