// `nipdem ldc verify --json` follows the CLI.md contract: table keys, row keys, nulls.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace {
std::string run(const std::string& args, int* rc) {
  FILE* f = popen((std::string(NIPDEM_CLI_PATH) + " " + args + " 2>/dev/null").c_str(), "r");
  std::string s;
  char buf[4096];
  while (f && std::fgets(buf, sizeof buf, f)) s += buf;
  const int st = f ? pclose(f) : -1;
  *rc = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return s;
}
std::set<std::string> keys(const nlohmann::json& o) {
  std::set<std::string> k;
  for (auto it = o.begin(); it != o.end(); ++it) k.insert(it.key());
  return k;
}
}  // namespace

TEST(LdcCli, VerifyJsonHasContractKeys) {
  int rc = -1;
  const auto j = nlohmann::json::parse(run("ldc verify --json", &rc));
  ASSERT_EQ(rc, 0);
  EXPECT_EQ(keys(j), (std::set<std::string>{"table_3_1", "table_3_2", "table_3_3", "table_3_4", "fig_3_6"}));
  ASSERT_EQ(j["table_3_1"].size(), 14u);
  EXPECT_EQ(keys(j["table_3_1"][0]), (std::set<std::string>{"i", "kappa_eps0", "kappa_eps005"}));
  for (const auto& r : j["table_3_2"]) {
    EXPECT_EQ(keys(r), (std::set<std::string>{"H", "i", "delta", "rho"}));
    EXPECT_EQ(r["rho"].is_null(), r["i"].get<int>() == 1);
  }
  const double coarsest = j["table_3_3"][0]["H"].get<double>();
  for (const auto& r : j["table_3_3"]) {
    EXPECT_EQ(keys(r), (std::set<std::string>{"H", "i", "kappa", "sigma"}));
    EXPECT_EQ(r["sigma"].is_null(), r["H"].get<double>() == coarsest);
  }
  for (const auto& r : j["table_3_4"]) EXPECT_EQ(keys(r), (std::set<std::string>{"i", "nu", "tau"}));
  EXPECT_TRUE(j["table_3_4"][0]["tau"].is_null());
  EXPECT_EQ(keys(j["fig_3_6"]), (std::set<std::string>{"charge_error_1", "charge_error_2"}));
}

TEST(LdcCli, MissingSetupFileExitsTwo) {
  int rc = -1;
  run("ldc solve /nonexistent/nipdem_ldc_setup.json", &rc);
  EXPECT_EQ(rc, 2);
}

TEST(LdcCli, SolveReadsToml) {
  // Same keys as the JSON setup; a grounded-box disc gives one JSON object with its potential.
  const auto path = std::filesystem::temp_directory_path() / "nipdem_test_ldc_setup.toml";
  std::ofstream(path) << "permittivity_F_per_m = 1.0\n[box]\ncells_x = 40\ncells_y = 40\n"
                         "[[discs]]\nx_m = 0.5\ny_m = 0.5\nradius_m = 0.05\ncharge_C_per_m = 1.0\n";
  int rc = -1;
  const auto j = nlohmann::json::parse(run("ldc solve " + path.string() + " --json", &rc));
  EXPECT_EQ(rc, 0);
  ASSERT_EQ(j["discs"].size(), 1u);
  // g = q/(2π) ln(r_in/R) with the inner radius 0.5390 of the unit square: 0.3784 (2 % tolerance:
  // coarse grid H = 1/40 with R = 2H).
  EXPECT_NEAR(j["discs"][0]["potential_V"].get<double>(), 0.3784, 0.02 * 0.3784);
  std::ofstream(path) << "x = [";
  run("ldc solve " + path.string(), &rc);
  EXPECT_EQ(rc, 2);
}
