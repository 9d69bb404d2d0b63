// Hostile input at the command line (issue 21, docs/reliability.md): every bad input below must
// end with exit 2, a message on stderr naming the file / option / key at fault, no signal, and
// within a time bound; never a crash, a hang or a run that "succeeds" with nonsense. One test
// per class of input; each case is one row (arguments, what stderr must name).
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "support/hostile.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
constexpr int kBoundSeconds = 60;  // wall-clock bound of one refused input (they take < 1 s alone)

using nipdem::test::hostile::Case;

const std::string kSrc = NIPDEM_SOURCE_DIR;
const std::string kBlack = kSrc + "/data/presets/black.toml";
// A small, quick nip (a run that is wrongly accepted finishes instead of hanging the suite).
const std::string kSmall = " --set geometry.window_x_min_m=-100e-6 --set geometry.window_x_max_m=100e-6"
                           " --set collision.stiffness_scale=0.01 --set output.vtk=false --quiet";

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_", name); }
using nipdem::test::hostile::write;

void expect_refused(const std::vector<Case>& cases, const std::string& tag) {
  nipdem::test::hostile::expect_cases(cases, tag, {.max_seconds = kBoundSeconds});
}
}  // namespace

// ---- input files that are not what they claim: folders, devices, FIFOs, huge or binary files ----
TEST(HostileCli, InputFilesThatAreNotRegularFilesOrTooLargeAreRefused) {
  const fs::path d = scratch("files");
  const std::string dir = (d / "a_folder").string();
  fs::create_directories(dir);
  const std::string fifo = (d / "a_fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);  // reading it would block forever
  const std::string huge = (d / "huge.toml").string();
  { std::ofstream(huge).put('#'); }
  fs::resize_file(huge, 300ull << 20);  // sparse: 300 MiB without using the disk
  std::string bin(4096, '\0');
  nipdem::Rng rng(3);
  for (auto& ch : bin) ch = static_cast<char>(static_cast<unsigned char>(rng.uniform(0, 255.99)));
  const std::string binary = write(d / "binary.toml", bin);
  const std::string out = " --out " + (d / "out").string();
  expect_refused({
      {"run " + dir + out, {dir, "folder"}},
      {"run /dev/zero" + out, {"/dev/zero", "not a regular file"}},
      {"run /dev/null" + out, {"/dev/null", "not a regular file"}},
      {"run " + fifo + out, {fifo, "not a regular file"}},
      {"run " + huge + out, {huge, "larger than"}},
      {"run " + binary + out, {binary}},
      {"run " + (d / "missing.toml").string() + out, {"missing.toml", "cannot open"}},
      {"field probe --x 0 --y 1e-4 --map /dev/zero", {"/dev/zero", "not a regular file"}},
      {"field probe --x 0 --y 1e-4 --map " + dir, {dir, "folder"}},
      {"calibrate rc --data /dev/zero --json", {"/dev/zero"}},
      {"calibrate friction --data " + fifo, {fifo, "not a regular file"}},
      {"ldc solve " + dir, {dir, "folder"}},
      {"experiment reduction --config " + dir + " --time 1e-5 --quiet --out " + (d / "x").string(), {dir, "folder"}},
  }, "hostile_files");
  fs::remove_all(d);
}

// ---- config keys: NaN, infinity, 1e308, negative, wrong type, unknown, out of range ----
TEST(HostileCli, BadConfigValuesAreRefusedNamingTheKey) {
  const fs::path d = scratch("keys");
  const std::string run = "run " + kBlack + " --out " + (d / "out").string() + kSmall;
  expect_refused({
      {run + " --set run.dt_s=1e-300", {"run.dt_s", "contact time"}},
      {run + " --set run.dt_s=nan", {"run.dt_s"}},
      {run + " --set run.dt_s=-1e-9", {"run.dt_s"}},
      {run + " --set run.dt_s=1e308", {"run.dt_s"}},
      {run + " --set run.end_time_s=1e-13", {"run.end_time_s", "time step"}},
      {run + " --set run.end_time_s=nan", {"run.end_time_s"}},
      {run + " --set run.end_time_s=-1", {"run.end_time_s"}},
      {run + " --set run.end_time_s=1e308", {"run.end_time_s"}},
      {run + " --set run.output_interval_s=1e-9", {"run.output_interval_s", "time step"}},
      {run + " --set run.checkpoint_interval_s=1e-9", {"run.checkpoint_interval_s", "time step"}},
      {run + " --set run.output_interval_s=inf", {"run.output_interval_s"}},
      {run + " --set run.seed=-1", {"run.seed"}},
      {run + " --set run.seed=1.5", {"run.seed"}},
      {run + " --set run.seed=-2e291", {"run.seed"}},  // a float for an integer key: UB in its conversion (fuzz_config)
      {run + " --set run.threads=1e300", {"run.threads"}},
      {run + " --set run.threads=0", {"run.threads"}},
      {run + " --set run.threads=100000", {"run.threads"}},
      {run + " --set run.dt_fraction_of_contact_time=nan", {"run.dt_fraction_of_contact_time"}},
      {run + " --set geometry.gap_m=nan", {"geometry.gap_m"}},
      {run + " --set geometry.gap_m=-1e-4", {"geometry.gap_m"}},
      {run + " --set geometry.gap_m=1e308", {"geometry.gap_m"}},
      {run + " --set geometry.drum_radius_m=inf", {"geometry.drum_radius_m"}},
      {run + " --set geometry.window_x_min_m=-1e308", {"geometry.window_x_min_m"}},
      {run + " --set geometry.drum_surface_speed_m_per_s=nan", {"geometry.drum_surface_speed_m_per_s"}},
      {run + " --set collision.stiffness_scale=0", {"collision.stiffness_scale"}},
      {run + " --set collision.stiffness_scale=nan", {"collision.stiffness_scale"}},
      {run + " --set inflow.layer_thickness_m=1", {"inflow.layer_thickness_m"}},
      {run + " --set inflow.area_fraction=nan", {"inflow.area_fraction"}},
      {run + " --set adhesion.cohesion_ratio=nan", {"adhesion.cohesion_ratio"}},
      {run + " --set run.dt_s=\\\"fast\\\"", {"run.dt_s"}},
      {run + " --set run.no_such_key=1", {"run.no_such_key"}},
      {run + " --set run.dt_s", {"--set", "KEY=VALUE"}},
      {run + " --set magnet.field=\\\"map\\\"", {"magnet.map_file"}},
      {run + " --set magnet.field=\\\"sideways\\\"", {"magnet.field"}},
      // about 1e9 particles: refused on the memory estimate, before anything is allocated
      {"run " + kBlack + " --out " + (d / "big").string() + " --quiet --set geometry.window_x_min_m=-0.01 --set geometry.window_x_max_m=0.01"
       " --set geometry.gap_m=5e-3 --set toner.d_small_m=2e-6 --set toner.d50_m=3e-6 --set run.dt_fraction_of_contact_time=0.005",
       {"geometry.window_x_min_m", "memory"}},
  }, "hostile_keys");
  fs::remove_all(d);
}

// ---- command-line options: NaN, inf, negative counts, wrapped seeds, out-of-range values ----
TEST(HostileCli, BadOptionsAreRefusedNamingTheOption) {
  const fs::path d = scratch("opts");
  const std::string out = " --quiet --out " + (d / "o").string();
  expect_refused({
      {"field probe --x nan --y 1e-4", {"--x"}},
      {"field probe --x 0 --y inf", {"--y"}},
      {"field probe --x 2 --y 1e-4", {"--x", "[-1, 1]"}},
      {"field probe --x 0 --y 1e-4 --tip-depth -5e-6", {"--tip-depth"}},
      {"field probe --x 0 --y 1e-4 --br 100", {"--br"}},
      {"field probe --x 0 --y 1e-4 --radius 0", {"--radius"}},
      {"field probe --x 0 --y 1e-4 --radius 1", {"--radius"}},
      {"field probe --x 0 --y 1e-4 --preset green", {"--preset", "green"}},
      {"field line --y 1e-4 --x0 -1e308 --out " + (d / "l.csv").string(), {"--x0"}},
      {"field export --x1 inf --out " + (d / "e.csv").string(), {"--x1"}},
      {"field export --x0 -5 --out " + (d / "e.csv").string(), {"--x0"}},
      {"field export --x1 1e300 --out " + (d / "e.csv").string(), {"--x1"}},
      {"field export --nx 100000 --ny 100000 --out " + (d / "e.csv").string(), {"--nx"}},
      {"field export --nx -3 --out " + (d / "e.csv").string(), {"--nx"}},
      {"field export --preset green --out " + (d / "e.csv").string(), {"--preset"}},
      {"experiment reduction --seed -1 --time 1e-5" + out, {"--seed"}},
      {"experiment reduction --seed 010 --time 1e-5" + out, {"--seed"}},
      {"experiment reduction --time nan" + out, {"--time"}},
      {"experiment reduction --pile-width nan --time 1e-5" + out, {"--pile-width"}},
      {"experiment reduction --pile-height -1 --time 1e-5" + out, {"--pile-height"}},
      {"experiment reduction --r nan --time 1e-5" + out, {"--r"}},
      {"experiment reduction --r 1,,2 --time 1e-5" + out, {"--r"}},
      {"experiment reduction --jobs 0 --time 1e-5" + out, {"--jobs"}},
      {"experiment front-position --gap 1e308" + out, {"--gap"}},
      {"experiment front-position --max-time nan" + out, {"--max-time"}},
      {"experiment front-position --min-time 1e308" + out, {"--min-time"}},
      {"experiment vo-level --line-length 0" + out, {"--line-length"}},
      {"experiment vo-level --line-start 1e308" + out, {"--line-start"}},
      {"experiment vo-level --seeds 0" + out, {"--seeds"}},
      {"experiment vo-level --step 0" + out, {"--step"}},
      {"experiment edge-sharpness --realizations 1" + out, {"--realizations"}},
      {"experiment edge-sharpness --bootstrap -1" + out, {"--bootstrap"}},
      {"force electric --radius nan --voltage 100 --gap 1e-6 --json", {"--radius"}},
      {"force electric --radius -1 --voltage 100 --gap 1e-6 --json", {"radius"}},
      {"force dipole --moment nan --distance 1e-5 --angle 0 --json", {"--moment"}},
      {"force dipole --moment 1e-13 --distance 1e-4 --angle 0 --pigments 3 --samples -5 --json", {"samples", "-5"}},
      // results that would overflow to null in the JSON (exit 0 before)
      {"force electric --radius 1e300 --voltage 100 --gap 1e-6 --json", {"--radius"}},
      {"force electric --radius 5e-6 --voltage 1e308 --gap 1e-6 --json", {"--voltage"}},
      {"force electric --radius 5e-6 --voltage 100 --gap 1e300 --json", {"--gap"}},
      {"force dipole --moment 1e300 --distance 1e-4 --angle 0 --json", {"--moment"}},
      {"force dipole --moment 1e-13 --distance 1e300 --angle 0 --json", {"--distance"}},
      {"calibrate restitution --y0 1e-3 --y1 1e-3 --radius 1e300 --density 1500 --viscosity 1.8e-5 --json", {"--radius"}},
      {"rc response --R 1e300 --Rd 1e300 --C 1e300 --voltage 1e300 --freq 1:10:1 --json", {"rc response"}},
      {"params collision --preset nope --json", {"nope"}},
      {"rc response --R nan --Rd 1e6 --C 1e-12 --voltage 1 --freq 1:10:1 --json", {"--R"}},
      {"calibrate restitution --y0 inf --y1 1e-3 --radius 5e-6 --density 1500 --viscosity 1.8e-5 --json", {"--y0"}},
  }, "hostile_opts");
  fs::remove_all(d);
}

// ---- damaged data files: field maps, LDC setups, print patterns, CSVs ----
TEST(HostileCli, DamagedDataFilesAreRefusedNamingTheFile) {
  const fs::path d = scratch("data");
  const std::string map_text = nipdem::io::read_file(kSrc + "/examples/fields/knife_black_25um.csv");
  const std::string truncated = write(d / "truncated.csv", map_text.substr(0, map_text.size() * 2 / 3));
  std::string nan_map = map_text;  // line 3 (after the comment and the header) becomes a NaN row
  const auto row3 = nan_map.find('\n', nan_map.find("x_m")) + 1;
  nan_map.replace(row3, nan_map.find('\n', row3) - row3, "nan,0,0.1,0.2");
  const std::string with_nan = write(d / "nan.csv", nan_map);
  // scattered points: nx ~ ny ~ rows, a grid of rows^2 nodes if it were allocated first
  std::string scattered = "x_m,y_m,Bx_T,By_T\n";
  for (int i = 0; i < 20000; ++i) scattered += std::to_string(i * 1e-6) + "," + std::to_string(i * 1e-6) + ",0,0\n";
  const std::string diag = write(d / "scattered.csv", scattered);
  const std::string header_only = write(d / "header.csv", "x_m,y_m,Bx_T,By_T\n");
  const std::string cells = write(d / "cells.json", R"({"box": {"cells_x": 2147483647, "cells_y": 2147483647}, "discs": []})");
  const std::string cells_big = write(d / "cells_big.json", R"({"box": {"cells_x": 1000000000000, "cells_y": 20}, "discs": []})");
  const std::string box_nan = write(d / "box.toml", "discs = []\n[box]\nx_min_m = nan\n");
  const std::string bad_json = write(d / "bad.json", R"({"box": {"cells_x": 20, )");
  const std::string pbm_text = nipdem::io::read_file(kSrc + "/examples/patterns/dots.pbm");
  const std::string pbm = write(d / "dots.pbm", pbm_text.substr(0, pbm_text.size() - 20));
  std::string pat = nipdem::io::read_file(kSrc + "/examples/patterns/bitmap.toml");
  const std::string pattern_cfg = write(d / "pattern.toml", pat);
  const std::string rc = write(d / "rc.csv", "frequency_Hz,amplitude_V,phase_deg\n100,1,");
  const std::string out = " --quiet --out " + (d / "o").string();
  // cohesion reports for `calibrate cohesion-joint`: truncated, a negative count, a string number,
  // r = 1e308, and a reduction sweep where a report belongs
  const std::string report_dir = kSrc + "/docs/results/2026-12-04-reduction-sweep-F10nN/";
  const std::string report = nipdem::io::read_file(report_dir + "calibration/color.json");
  const std::string good_report = report_dir + "calibration/black.json";
  const std::string rep_trunc = write(d / "rep_trunc.json", report.substr(0, report.size() / 2));
  auto rep_with = [&](const char* name, const std::string& from, const std::string& to) {
    std::string t = report;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) t.replace(at, from.size(), to);
    return write(d / name, t);
  };
  const std::string rep_neg = rep_with("rep_neg.json", "\"removed_mean\":8.0", "\"removed_mean\":-8.0");
  const std::string rep_str = rep_with("rep_str.json", "\"removed_mean\":8.0", "\"removed_mean\":\"8\"");
  const std::string rep_huge = rep_with("rep_huge.json", "\"r\":3.0", "\"r\":1e308");
  expect_refused({
      {"calibrate cohesion-joint " + good_report + "," + rep_trunc + out, {"rep_trunc.json", "not a JSON document"}},
      {"calibrate cohesion-joint " + good_report + "," + rep_neg + out, {"rep_neg", "rows[0]", ">= 0"}},
      {"calibrate cohesion-joint " + good_report + "," + rep_str + out, {"rep_str.json", "removed_mean"}},
      {"calibrate cohesion-joint " + good_report + "," + report_dir + "color_s1/reduction.json" + out, {"reduction.json", "cohesion"}},
      {"calibrate cohesion-joint " + good_report + "," + rep_huge + out, {"rep_huge", "rows[6]", "1e+06"}},
      {"calibrate cohesion-joint " + good_report + "," + good_report + out, {"same file name"}},
  }, "hostile_cohesion");
  expect_refused({
      {"field probe --x 0 --y 1e-4 --map " + truncated, {"truncated.csv"}},
      {"field probe --x 0 --y 1e-4 --map " + with_nan, {"nan.csv:3", "NaN"}},
      {"field probe --x 0 --y 1e-4 --map " + diag, {"scattered.csv"}},
      {"field probe --x 0 --y 1e-4 --map " + header_only, {"header.csv", "no data rows"}},
      {"run " + kBlack + " --out " + (d / "m").string() + kSmall + " --set magnet.field=\\\"map\\\" --set magnet.map_file=\\\"" + truncated + "\\\"",
       {"truncated.csv"}},
      {"ldc solve " + cells, {"cells.json", "cells_x"}},
      {"ldc solve " + cells_big, {"cells_x"}},
      {"ldc solve " + box_nan, {"box.toml", "x_min_m"}},
      {"ldc solve " + bad_json, {"bad.json", "invalid JSON"}},
      {"run " + kBlack + " --out " + (d / "p").string() + kSmall + " --set electric.enabled=true --set print.pattern=\\\"pbm\\\" "
       "--set print.file=\\\"" + pbm + "\\\" --set print.row=1 --set print.pixel_pitch_m=42e-6",
       {"dots.pbm"}},
      {"calibrate rc --data " + rc + " --json", {"rc.csv", "line 2"}},
  }, "hostile_data");
  (void)pattern_cfg;
  fs::remove_all(d);
}

// ---- resume: damaged or foreign checkpoints, end times that leave nothing to run ----
TEST(HostileCli, ResumeRefusesDamagedCheckpointsAndEmptyWork) {
  const fs::path d = scratch("resume");
  const std::string base = "run " + kBlack + kSmall + " --set run.checkpoint_interval_s=2e-6 --set run.output_interval_s=2e-6";
  const fs::path good = d / "good";
  {
    const auto r = nipdem::test::run_cli_bounded(base + " --out " + good.string() + " --set run.end_time_s=4e-6", "hostile_resume", 300);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const std::string blob = nipdem::io::read_file(good / "checkpoint.bin", nipdem::io::kMaxCheckpointBytes);
  auto variant = [&](const std::string& name, const std::function<void(const fs::path&)>& damage) {
    const fs::path v = d / name;
    fs::create_directories(v);
    for (const auto& e : fs::directory_iterator(good))
      if (e.is_regular_file()) fs::copy_file(e.path(), v / e.path().filename());
    damage(v);
    return v;
  };
  std::vector<Case> cases;
  auto resume = [&](const fs::path& v, const std::string& end = "1e-5") { return base + " --out " + v.string() + " --set run.end_time_s=" + end + " --resume"; };
  const std::string ck = "checkpoint.bin";
  {
    const auto v = variant("trunc", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / ck, blob.substr(0, blob.size() / 2)); });
    cases.push_back({resume(v), {(v / ck).string(), "truncated"}});
  }
  {
    const auto v = variant("append", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / ck, blob + "garbage"); });
    cases.push_back({resume(v), {(v / ck).string(), "appended"}});
  }
  nipdem::Rng rng(21);
  for (int k = 0; k < 4; ++k) {
    const auto at = static_cast<std::size_t>(rng.uniform(0, static_cast<double>(blob.size())));
    const auto v = variant("flip" + std::to_string(k), [&](const fs::path& p) {
      std::string b = blob;
      b[std::min(at, b.size() - 1)] ^= 0x04;
      nipdem::io::write_file_atomic(p / ck, b);
    });
    cases.push_back({resume(v), {(v / ck).string()}});
  }
  {
    const auto v = variant("old", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / ck, "NIPDEMRUN3" + blob.substr(10)); });
    cases.push_back({resume(v), {(v / ck).string(), "older nipdem"}});
  }
  {
    const auto v = variant("empty", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / ck, ""); });
    cases.push_back({resume(v), {(v / ck).string(), "not a nipdem checkpoint"}});
  }
  {
    const auto v = variant("folder", [&](const fs::path& p) { fs::remove(p / ck); fs::create_directories(p / ck); });
    cases.push_back({resume(v), {(v / ck).string(), "folder"}});
  }
  {
    const auto v = variant("series", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / "timeseries.csv", "time_s,bodies\nxyz,3\n"); });
    cases.push_back({resume(v), {"timeseries.csv:2"}});
  }
  {
    const auto v = variant("frames", [&](const fs::path& p) { nipdem::io::write_file_atomic(p / "frames.json", "[[0.0, "); });
    cases.push_back({resume(v), {"frames.json"}});
  }
  // end time at or before the checkpoint's time: nothing to run is an error, not a success
  cases.push_back({resume(variant("same_end", [](const fs::path&) {}), "4e-6"), {"run.end_time_s", "checkpoint"}});
  cases.push_back({resume(variant("earlier_end", [](const fs::path&) {}), "1e-6"), {"run.end_time_s", "checkpoint"}});
  // another configuration
  cases.push_back({resume(variant("other_cfg", [](const fs::path&) {})) + " --set adhesion.cohesion_ratio=3", {"different configuration"}});
  // --out that is a file, or a folder that cannot be created (exit 1 before)
  cases.push_back({base + " --out " + (good / "summary.json").string(), {"summary.json", "--out"}});
  cases.push_back({base + " --out /proc/nipdem_cannot_be_here", {"/proc/nipdem_cannot_be_here", "--out"}});
  expect_refused(cases, "hostile_resume");
  fs::remove_all(d);
}
