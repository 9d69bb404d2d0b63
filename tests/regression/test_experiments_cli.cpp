// Experiment commands: bad sweep specifications exit 2 with clear messages; a tiny
// reduction run produces the documented JSON keys and files (its analysis code is tested on
// known input in tests/unit/test_analysis_*.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "../cli_run.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
using Res = nipdem::test::CliResult;
Res cli(const std::string& args) { return nipdem::test::run_cli(args, "exp"); }
}  // namespace

TEST(ExperimentCli, BadSweepSpecificationsExitTwo) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_bad_" + std::to_string(::getpid()));
  struct C { std::string args, needle; };
  for (const C& c : {C{"experiment reduction --r 1,abc", "--r"}, C{"experiment front-position --gap -1e-6", "--gap"},
                     C{"experiment front-position --gap 150e-6 --sleeve-speed x", "--sleeve-speed"},
                     C{"experiment reduction --preset purple", "unknown preset"},
                     C{"experiment edge-sharpness --realizations 1", "--realizations"},
                     C{"experiment front-position --set geometry.gap_mm=1", "geometry.gap_mm"},
                     C{"experiment vo-level --line-start 5", "start_m"},
                     C{"experiment edge-sharpness --line-start 5", "start_m"},
                     C{"experiment edge-sharpness --extra-time -1", "--extra-time"},
                     C{"experiment edge-sharpness --margin 0", "--margin"},
                     C{"calibrate cohesion --target-speed 7.6e-4 --r-min 10 --r-max 1", "--r-max"},
                     C{"calibrate cohesion --target-speed 7.6e-4 --points 1", "--points"},
                     C{"calibrate cohesion --r-min 1", "--target-speed"},
                     C{"experiment reduction --pits half", "--pits"},
                     C{"experiment vo-level --coarse-step 1.2", "coarse_step_V"},
                     // a key the experiment sets itself is refused, not silently replaced
                     C{"experiment reduction --set geometry.gap_m=-1", "--set geometry.gap_m"},
                     C{"experiment reduction --set adhesion.cohesion_ratio=3", "use --r instead"},
                     C{"experiment front-position --set geometry.gap_m=1e-4", "use --gap instead"},
                     C{"experiment vo-level --set print.voltage_V=20", "use --v0 and --step instead"},
                     C{"experiment edge-sharpness --set print.start_m=1e-3", "use --line-start instead"},
                     C{"experiment edge-sharpness --set run.seed=7", "use --seed instead"}}) {
    SCOPED_TRACE(c.args);
    const auto r = cli(c.args + " --out " + d.string() + " --quiet");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
  }
  fs::remove_all(d);
}

TEST(ExperimentCli, TinyReductionRunReportsCountsAndSeries) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_red_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const auto r = cli("experiment reduction --r 1 --time 2e-5 --pile-width 100e-6 --pile-height 40e-6 --set collision.stiffness_scale=0.01 --json --quiet --out " + d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["points"].size(), 1u);
  const auto& p = j["points"][0];
  EXPECT_GT(p["initial_particles"].get<int>(), 10);
  EXPECT_GE(p["removed"].get<int>(), 0);
  EXPECT_EQ(p["lost"].get<int>(), 0);
  EXPECT_EQ(j["pits"], "empty");  // a clean sleeve upstream of the pile: nothing is brought in
  EXPECT_EQ(p["brought_in_pits"].get<int>(), 0);
  EXPECT_TRUE(fs::exists(d / "reduction.csv"));
  EXPECT_TRUE(fs::exists(d / "reduction.json"));
  EXPECT_EQ(p["series_csv"].get<std::string>(), (d / "reduction_r1.csv").string());
  EXPECT_TRUE(fs::exists(d / "reduction_r1.csv"));
  // resumable: a rerun loads the finished point instead of recomputing it
  const auto again = cli("experiment reduction --r 1 --time 2e-5 --pile-width 100e-6 --pile-height 40e-6 --set collision.stiffness_scale=0.01 --json --quiet --out " + d.string());
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["points"], j["points"]);
  fs::remove_all(d);
}

// A tiny clean-state run (colour, 400 um window, 1 ms): the front is reported with the window's
// particle balance over its steady part. The counters obey conservation (particles at the end =
// all inserted - all removed, at the last sample), and a window that takes in toner while
// letting none out is flagged "filling" with a warning instead of passing as a steady state.
// The scenario is pinned to the pre-calibration adhesion and pits (r = 1, 0.1 nN, 15 um), where
// this tiny window settles within ~1 ms (1.2 ms allowed: at 1 ms the steadiness test is marginal,
// 3.1 standard errors of drift against 3, and flips with the last bits of a run); the test is about
// the bookkeeping, not those values.
TEST(ExperimentCli, TinyFrontPositionReportsTheWindowsParticleBalance) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_front_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const auto r = cli("experiment front-position --preset color --gap 100e-6 --set collision.stiffness_scale=0.01 "
                     "--set inflow.layer_thickness_m=15e-6 --set geometry.window_x_min_m=-200e-6 "
                     "--set geometry.window_x_max_m=200e-6 --set adhesion.cohesion_ratio=1 --set adhesion.roller_force_N=1e-10 "
                     "--set geometry.roughness.height_m=15e-6 --min-time 8e-4 --max-time 1.2e-3 --quiet --json --out " + d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["points"].size(), 1u);
  const auto& p = j["points"][0];
  const auto rj = nlohmann::json::parse(nipdem::io::read_file(d / "front_position" / "realizations" / "0.json"));
  const auto& series = rj["result"]["series_t_front_back_m_in_out"];
  ASSERT_GE(series.size(), 40u);
  const auto& last = series.back();
  EXPECT_NEAR(last[0].get<double>(), p["simulated_s"].get<double>(), 1e-12);
  EXPECT_EQ(p["particles_at_end"].get<long>(), last[3].get<long>() - last[4].get<long>());  // conservation
  ASSERT_TRUE(p["steady"].get<bool>()) << p.dump();
  EXPECT_GT(p["inflow_steady"].get<long>(), 0);  // the drum keeps bringing toner
  // ~1 ms is far too short for the assembly to reach the window's end: nothing leaves but what
  // the drum carries out at once, so the window is filling and says so
  EXPECT_LT(p["outflow_over_inflow_steady"].get<double>(), 0.5);
  EXPECT_TRUE(p["filling"].get<bool>());
  EXPECT_EQ(j["n_filling"], 1);
  EXPECT_NE(r.err.find("still filling"), std::string::npos) << r.err;
  const auto csv = nipdem::io::read_file(d / "front_position.csv");
  EXPECT_EQ(csv.rfind("gap_m,sleeve_speed_m_per_s,front_m,front_std_m,steady,outflow_over_inflow_steady\n", 0), 0u) << csv;
  fs::remove_all(d);
}

// An r given twice is two seeds of one point: each keeps its own time series (the second used
// to overwrite the first's reduction_r1.csv).
TEST(ExperimentCli, RepeatedCohesionRatioKeepsEachSeedsSeries) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_red2_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const auto r = cli("experiment reduction --r 1,1 --time 1e-5 --pile-width 100e-6 --pile-height 40e-6 --set collision.stiffness_scale=0.01 --json --quiet --out " + d.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["points"].size(), 2u);
  EXPECT_NE(j["points"][0]["seed"], j["points"][1]["seed"]);
  for (int i = 0; i < 2; ++i) {
    const fs::path f = d / ("reduction_r1_i" + std::to_string(i) + ".csv");
    EXPECT_EQ(j["points"][i]["series_csv"].get<std::string>(), f.string());
    EXPECT_TRUE(fs::exists(f)) << f;
  }
  EXPECT_FALSE(fs::exists(d / "reduction_r1.csv"));
  fs::remove_all(d);
}

// Two tiny printed lines (120 um window, 20 um line): every realization observes the drum up to
// line end + margin (drum still in the window at the end is unobserved, not uncovered), the JSON
// reports the coverage at the range ends, and a folder whose realization lacks that record (made
// by an older nipdem with a shorter run) is rejected with exit 2 instead of being averaged.
TEST(ExperimentCli, TinyEdgeSharpnessObservesTheWholeAnalysisRange) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_edge_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const std::string cmd = "experiment edge-sharpness --realizations 2 --line-start 0 --line-length 20e-6 --margin 20e-6 "
                          "--set geometry.window_x_min_m=-60e-6 --set geometry.window_x_max_m=60e-6 "
                          "--set collision.stiffness_scale=0.01 --set print.voltage_V=35 --json --quiet --out " + d.string();
  const auto r = cli(cmd);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["realizations"], 2);
  EXPECT_EQ(j["voltage_V"].get<double>(), 35.0);  // the configuration's print voltage, not a fixed one
  for (int i = 0; i < 2; ++i) {
    const auto rj = nlohmann::json::parse(nipdem::io::read_file(d / "edge_sharpness" / "realizations" / (std::to_string(i) + ".json")));
    EXPECT_GE(rj["result"]["s_observed_m"].get<double>(), 40e-6 - 1e-6);  // line end + margin, within a bin
  }
  // lines.csv: a header and one row per line, with that line's seed and printed count
  const auto lines = nipdem::io::read_file(d / "lines.csv");
  EXPECT_EQ(lines.rfind("index,seed,ok,wall_s,printed,s_observed_um,covered_bin_starts_um\n", 0), 0u) << lines;
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 3);
  const auto r1 = nlohmann::json::parse(nipdem::io::read_file(d / "edge_sharpness" / "realizations" / "1.json"));
  const std::string head1 = "\n1," + std::to_string(r1["seed"].get<std::uint64_t>()) + ",1,";
  const auto at = lines.find(head1);
  ASSERT_NE(at, std::string::npos) << lines;
  const auto wall_end = lines.find(',', at + head1.size());  // after wall_s comes printed
  EXPECT_EQ(lines.substr(wall_end + 1, lines.find(',', wall_end + 1) - wall_end - 1),
            std::to_string(r1["result"]["printed"].get<long>())) << lines;
  if (j.contains("error")) {
    EXPECT_FALSE(j.contains("coverage_at_range_end"));  // nothing printed: nothing to fit
  } else {
    EXPECT_TRUE(j.contains("coverage_at_range_end"));
    EXPECT_TRUE(j["warnings"].is_array());
  }
  auto r0 = nlohmann::json::parse(nipdem::io::read_file(d / "edge_sharpness" / "realizations" / "0.json"));
  r0["result"].erase("s_observed_m");
  nipdem::io::write_file_atomic(d / "edge_sharpness" / "realizations" / "0.json", r0.dump());
  const auto again = cli(cmd);
  EXPECT_EQ(again.status, 2);
  EXPECT_NE(again.err.find("s_observed_m"), std::string::npos) << again.err;
  fs::remove_all(d);
}

// A Vo scan keeps each finished line (OUT/vo_level/lines/<index>.json): a seed interrupted in
// the middle of its scan goes on from its last finished line and ends with the same trace; a
// damaged file is set aside with a warning and its lines are run again.
TEST(ExperimentCli, InterruptedVoScanResumesFromItsFinishedLines) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_exp_vo_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const std::string cmd = "experiment vo-level --seeds 1 --v0 0 --step 10 --vmax 30 --line-start 0 --line-length 20e-6 "
                          "--set inflow.prefill=false --set geometry.window_x_min_m=-100e-6 --set geometry.window_x_max_m=100e-6 "
                          "--set collision.stiffness_scale=0.01 --json --quiet --out " + d.string();
  const auto first = cli(cmd);
  ASSERT_EQ(first.status, 0) << first.err;
  const auto j1 = nlohmann::json::parse(first.out);
  const auto trace = j1["per_seed"][0]["trace_V_printed"];
  ASSERT_GE(trace.size(), 3u);  // a scan of several lines
  EXPECT_EQ(j1["per_seed"][0]["lines_resumed"], 0);
  const fs::path memo = d / "vo_level" / "lines" / "0.json";
  auto m = nlohmann::json::parse(nipdem::io::read_file(memo));
  ASSERT_EQ(m["lines_V_printed"], trace);
  // Interrupted after two lines: the seed's result is missing, its memo holds two lines.
  fs::remove(d / "vo_level" / "realizations" / "0.json");
  m["lines_V_printed"].erase(m["lines_V_printed"].begin() + 2, m["lines_V_printed"].end());
  nipdem::io::write_file_atomic(memo, m.dump());
  const auto second = cli(cmd);
  ASSERT_EQ(second.status, 0) << second.err;
  const auto j2 = nlohmann::json::parse(second.out);
  EXPECT_EQ(j2["per_seed"][0]["trace_V_printed"], trace);
  EXPECT_EQ(j2["per_seed"][0]["lines_resumed"], 2);
  EXPECT_EQ(j2["vo_mean_V"], j1["vo_mean_V"]);
  EXPECT_EQ(nlohmann::json::parse(nipdem::io::read_file(memo))["lines_V_printed"], trace);
  // A damaged memo is not trusted: warning, every line again, the same trace.
  fs::remove(d / "vo_level" / "realizations" / "0.json");
  nipdem::io::write_file_atomic(memo, "{\"seed\": 1, \"lines_V_printed\": [[0");
  const auto third = cli(cmd);
  ASSERT_EQ(third.status, 0) << third.err;
  EXPECT_NE(third.err.find("unreadable"), std::string::npos) << third.err;
  const auto j3 = nlohmann::json::parse(third.out);
  EXPECT_EQ(j3["per_seed"][0]["trace_V_printed"], trace);
  EXPECT_EQ(j3["per_seed"][0]["lines_resumed"], 0);
  fs::remove_all(d);
}

// `calibrate cohesion` on tiny reduction runs: an unreachable target is reported (exit 1, JSON
// with a hint) without losing the runs; a target between the two round-0 speeds is bracketed
// on the rerun (round 0 resumed, not recomputed) and refined inside the bracket.
TEST(ExperimentCli, CohesionCalibrationBracketsATargetBetweenItsSpeeds) {
  const fs::path d = fs::temp_directory_path() / ("nipdem_cal_coh_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const std::string common = "calibrate cohesion --preset color --r-min 1 --r-max 100 --points 2 --rounds 2 --time 4e-4 "
                             "--pile-width 100e-6 --pile-height 40e-6 --set collision.stiffness_scale=0.01 --json --quiet --out " + d.string();
  const auto miss = cli(common + " --target-speed 1");
  ASSERT_EQ(miss.status, 1) << miss.err;
  EXPECT_NE(miss.err.find("not bracketed"), std::string::npos) << miss.err;
  const auto j0 = nlohmann::json::parse(nipdem::io::read_file(d / "cohesion.json"));
  EXPECT_FALSE(j0["bracketed"].get<bool>());
  ASSERT_EQ(j0["rounds"].size(), 1u);
  const auto& p = j0["rounds"][0]["points"];
  ASSERT_EQ(p.size(), 2u);
  const double v1 = p[0]["reduction_speed_m_per_s"].get<double>(), v100 = p[1]["reduction_speed_m_per_s"].get<double>();
  ASSERT_NE(v1, v100);
  const auto hit = cli(common + " --target-speed " + std::to_string(0.5 * (v1 + v100)));
  ASSERT_EQ(hit.status, 0) << hit.err;
  const auto j = nlohmann::json::parse(hit.out);
  ASSERT_TRUE(j["bracketed"].get<bool>());
  EXPECT_EQ(j["rounds"][0]["points"], p);  // resumed: identical speeds
  ASSERT_EQ(j["rounds"].size(), 2u);
  for (const auto& q : j["rounds"][1]["points"]) {  // inside round 0's bracket [1, 100]
    EXPECT_GT(q["r"].get<double>(), 1.0);
    EXPECT_LT(q["r"].get<double>(), 100.0);
  }
  const double r = j["r_fit"].get<double>();
  EXPECT_GE(r, j["bracket"][0].get<double>());
  EXPECT_LE(r, j["bracket"][1].get<double>());
  EXPECT_TRUE(fs::exists(d / "cohesion.png"));
  EXPECT_TRUE(fs::exists(d / "round_1" / "reduction.csv"));
  fs::remove_all(d);
}
