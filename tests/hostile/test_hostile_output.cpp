// Hostile output paths and damaged run folders (docs/reliability.md): an --out that is a folder,
// a FIFO or empty; a run folder whose files were deleted, replaced by folders or by valid JSON
// of another shape; cluster templates and roughness values that would break far from their key.
// Each must end with exit 2 naming the path, file or key, leave what was there untouched and no
// temp file behind, within a time bound.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "support/hostile.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
constexpr int kBoundSeconds = 60;

using nipdem::test::hostile::Case;

const std::string kSrc = NIPDEM_SOURCE_DIR;
const std::string kBlack = kSrc + "/data/presets/black.toml";
const std::string kSmall = " --set geometry.window_x_min_m=-100e-6 --set geometry.window_x_max_m=100e-6"
                           " --set collision.stiffness_scale=0.01 --quiet";

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_out_", name); }

void expect_refused(const std::vector<Case>& cases, const std::string& tag) {
  nipdem::test::hostile::expect_cases(cases, tag, {});
}

// Names in `dir` (not recursive) that look like a temp file of write_file_atomic.
std::vector<std::string> temp_files(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) out.push_back(e.path().string());
  return out;
}
}  // namespace

// ---- output paths that cannot be replaced by a file: a folder, a FIFO, nothing ----
TEST(HostileOutput, OutputPathsThatAreNotFilesAreRefusedAndLeftAlone) {
  const fs::path d = scratch("paths");
  const fs::path fifo = d / "fifo", folder = d / "folder";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);  // a device node (e.g. /dev/null) is the same case for a root user
  fs::create_directories(folder);
  const fs::path csv = d / "g.csv";
  nipdem::io::write_file_atomic(csv, "a_m,b_N\n1,2\n2,3\n");
  expect_refused({{"field export --out " + fifo.string(), {fifo.string(), "not a regular file"}},
                  {"plot " + csv.string() + " --x a_m --y b_N --out " + fifo.string(), {fifo.string(), "not a regular file"}},
                  {"plot " + csv.string() + " --x a_m --y b_N --out " + folder.string(), {folder.string(), "folder"}},
                  {"field export --out " + folder.string(), {folder.string(), "folder"}},
                  {"field export --out ''", {"output path is empty"}},
                  {"field line --out " + fifo.string(), {fifo.string()}}},
                 "hostile_out_paths");
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
  EXPECT_TRUE(fs::is_directory(folder));
  EXPECT_TRUE(temp_files(d).empty()) << temp_files(d).front();
  EXPECT_TRUE(temp_files(folder).empty());
  fs::remove_all(d);
}

// ---- resume: files of the run folder deleted or replaced by folders; render of foreign JSON ----
TEST(HostileOutput, DamagedRunFoldersAreRefusedNamingTheFile) {
  const fs::path d = scratch("run");
  const std::string base = "run " + kBlack + kSmall + " --set run.checkpoint_interval_s=2e-6 --set run.output_interval_s=2e-6";
  const fs::path good = d / "good";
  {
    const auto r = nipdem::test::run_cli_bounded(base + " --out " + good.string() + " --set run.end_time_s=4e-6", "hostile_out_run", 300);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  ASSERT_TRUE(fs::exists(good / "frames.json"));
  auto variant = [&](const std::string& name, const std::function<void(const fs::path&)>& damage) {
    const fs::path v = d / name;
    fs::copy(good, v, fs::copy_options::recursive);
    damage(v);
    return v;
  };
  auto resume = [&](const fs::path& v) { return base + " --out " + v.string() + " --set run.end_time_s=1e-5 --resume"; };
  std::vector<Case> cases;
  // The rows and snapshots before the checkpoint would be lost (exit 0 with a shorter file before).
  for (const char* f : {"timeseries.csv", "frames.json"}) {
    const auto v = variant(std::string("no_") + f, [&](const fs::path& p) { fs::remove(p / f); });
    cases.push_back({resume(v), {(v / f).string(), "missing"}});
  }
  {  // an output the run replaces at each checkpoint is a folder now (exit 1, "cannot rename", before)
    const auto v = variant("removals_folder", [](const fs::path& p) {
      fs::remove(p / "removals.csv");
      fs::create_directories(p / "removals.csv");
    });
    cases.push_back({resume(v), {(v / "removals.csv").string(), "folder"}});
  }
  // render: valid JSON of another shape (a raw json type_error, exit 1, before), a negative scale
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"obj", "{\"a\":1}"}, {"short", "[[0.0]]"}, {"numbers", "[1,2]"}, {"string", "\"x\""}, {"swapped", "[[\"f.vtp\", 0.0]]"}}) {
    const auto v = variant("frames_" + name, [&](const fs::path& p) { nipdem::io::write_file_atomic(p / "frames.json", text); });
    cases.push_back({"render " + v.string(), {(v / "frames.json").string()}});
  }
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"array", "[1]"}, {"no_geometry", "{\"time_s\":1}"}, {"empty_geometry", "{\"geometry\":{}}"}, {"not_json", "{\"geometry\":"}}) {
    const auto v = variant("summary_" + name, [&](const fs::path& p) { nipdem::io::write_file_atomic(p / "summary.json", text); });
    cases.push_back({"render " + v.string(), {(v / "summary.json").string()}});
  }
  cases.push_back({"render " + good.string() + " --color-max -1", {"--color-max"}});
  cases.push_back({"render " + good.string() + " --color-max nan", {"--color-max"}});
  expect_refused(cases, "hostile_out_run");
  // and the good folder still renders
  const auto r = nipdem::test::run_cli_bounded("render " + good.string(), "hostile_out_run", 120);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(good / "frames" / "frame_000000.png"));
  fs::remove_all(d);
}

// ---- configuration values that broke far from their key ----
TEST(HostileOutput, ClusterTemplatesAndRoughnessAreCheckedWhereTheyAreRead) {
  const fs::path d = scratch("config");
  auto cluster_file = [&](const std::string& name, const std::string& discs) {
    const fs::path p = d / (name + ".toml");
    nipdem::io::write_file_atomic(p, "[[template]]\nname = \"odd\"\ndiscs = " + discs + "\n");
    return p.string();
  };
  const std::string run = "run " + kBlack + kSmall + " --set run.end_time_s=1e-6 --set output.vtk=false --out " + (d / "out").string();
  auto with_cluster = [&](const std::string& file) { return run + " --set toner.cluster_file='\"" + file + "\"' --set toner.cluster='\"odd\"'"; };
  const std::string far = cluster_file("far", "[[0.0, 0.0, 1.0], [1e300, 0.0, 1.0]]");
  const std::string tiny = cluster_file("tiny", "[[0.0, 0.0, 1.0], [1.0, 0.0, 1e-9]]");
  // (before: "run.end_time_s ... dt = inf s", or a time step of 0)
  expect_refused({{with_cluster(far), {far, "template[0].discs", "too far apart"}},
                  {with_cluster(tiny), {tiny, "template[0].discs", "1000x"}},
                  {run + " --set geometry.roughness.spacing_m=1e-12", {"geometry.roughness.spacing_m", "1e-9"}}},
                 "hostile_out_config");
  // Pyramids side by side (spacing 0, inside the documented range): a valid roller, which runs
  // (exit 2 "arc length s must increase" before).
  const auto r = nipdem::test::run_cli_bounded(run + " --set geometry.roughness.spacing_m=0", "hostile_out_config", 300);
  EXPECT_EQ(r.status, 0) << r.err;
  fs::remove_all(d);
}

// ---- integer options that carry a range check are plain integers too ----
TEST(HostileOutput, IntegerOptionsWithARangeAreStillPlainDecimal) {
  // CLI::Range's description changed the option's type name ("INT in [1 - 256]"), so the check
  // for plain decimal integers skipped it: --jobs 010 was read as octal 8 and accepted.
  expect_refused({{"experiment vo-level --jobs 010", {"--jobs", "octal"}},
                  {"experiment edge-sharpness --jobs 0x10", {"--jobs"}}},
                 "hostile_out_int");
}
