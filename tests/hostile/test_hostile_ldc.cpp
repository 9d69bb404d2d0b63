// Hostile input for `nipdem ldc solve` (issue 21, docs/reliability.md): setup files nested
// 100,000 deep, scales that overflow the solve (permittivity, side potentials, charges, radii, box
// corners of 1e308 or 1e-300), a solve that diverges, a disc too small for its grid, a large grid.
// Each refused input must end with the expected exit status, a message on stderr naming the file /
// key, no signal and no time-out; never a crash or an exit 0 with null or diverged results.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "support/hostile.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
constexpr int kBoundSeconds = 60;
const std::string kTag = "hostile_ldc";

using nipdem::test::hostile::Case;

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_ldc_", name); }
using nipdem::test::hostile::write;

// The setup of docs/ldc.md on a 40 x 40 grid, with `disc` as its one disc and `extra` keys first.
std::string setup(const std::string& extra = "", const std::string& disc = R"("x_m": 5e-4, "y_m": 5e-4, "radius_m": 5e-6, "charge_C_per_m": 1e-10)",
                  const std::string& box = R"("x_min_m": 0, "x_max_m": 1e-3, "y_min_m": 0, "y_max_m": 1e-3)",
                  const std::string& top_V = "500", int cells = 40) {
  return "{" + extra + R"("box": {)" + box + R"(, "cells_x": )" + std::to_string(cells) + R"(, "cells_y": )" +
         std::to_string(cells) + R"(},
 "boundary": {"bottom": {"kind": "dirichlet", "value_V": 0}, "top": {"kind": "dirichlet", "value_V": )" + top_V + R"(},
              "left": {"kind": "neumann"}, "right": {"kind": "neumann"}},
 "tolerance": 1e-8, "local_radius_factor": 3, "safety_m": 0, "fd_refinement": 4,
 "discs": [{)" + disc + "}]}";
}

// Every case ends with `status`, stdout empty, stderr naming each needle in at most `max_err` bytes.
void expect_status(const std::vector<Case>& cases, int status, std::size_t max_err = 2000) {
  nipdem::test::hostile::expect_cases(cases, kTag, {.status = status, .bound_s = kBoundSeconds, .stdout_empty = true, .max_err = max_err});
}
}  // namespace

// ---- nesting: 100,000 '[' crashed the reader (stack overflow in the message's value.dump());
// 50,000 printed the whole value; a huge key was quoted in full ----
TEST(HostileLdc, DeeplyNestedOrHugeValuesAreRefusedInOneShortLine) {
  const fs::path d = scratch("nesting");
  auto nest = [](int n) { return std::string(n, '[') + std::string(n, ']'); };
  const std::string deep = write(d / "deep.json", R"({"tolerance": )" + nest(100000) + R"(, "discs": []})");
  const std::string deep50 = write(d / "deep50.json", R"({"tolerance": )" + nest(50000) + R"(, "discs": []})");
  const std::string deep_discs = write(d / "deep_discs.json", R"({"discs": )" + nest(100000) + "}");
  const std::string deep_box = write(d / "deep_box.json", R"({"box": )" + nest(100000) + R"(, "discs": []})");
  const std::string deep_key = write(d / "deep_key.json", R"({"box": {"x_min_m": )" + nest(100000) + R"(}, "discs": []})");
  const std::string deep_toml = write(d / "deep.toml", "discs = []\ntolerance = " + nest(200) + "\n");
  std::string many;
  for (int i = 0; i < 20000; ++i) many += "1, ";
  const std::string wide = write(d / "wide.json", R"({"tolerance": [)" + many + R"(3], "discs": []})");
  const std::string long_key = write(d / "long_key.json", "{\"" + std::string(100000, 'k') + R"(": 1, "discs": []})");
  expect_status({
      {"ldc solve " + deep, {"deep.json", "nested too deeply"}},
      {"ldc solve " + deep50, {"deep50.json", "nested too deeply"}},
      {"ldc solve " + deep_discs, {"deep_discs.json", "nested too deeply"}},
      {"ldc solve " + deep_box, {"deep_box.json", "nested too deeply"}},
      {"ldc solve " + deep_key, {"deep_key.json", "nested too deeply"}},
      {"ldc solve " + deep_toml, {"deep.toml", "nested too deeply"}},
      {"ldc solve " + wide, {"wide.json", "tolerance", "must be a number"}},
      {"ldc solve " + long_key, {"long_key.json", "unknown key"}},
  }, 2, 400);
  fs::remove_all(d);
}

// ---- scales: each of these ran to exit 0 with null potentials or forces (or exit 1) ----
TEST(HostileLdc, ScalesThatWouldOverflowTheSolveAreRefusedNamingTheKey) {
  const fs::path d = scratch("scales");
  const std::string disc = R"("x_m": 5e-4, "y_m": 5e-4, )";
  const std::string huge_box = R"("x_min_m": -1e308, "x_max_m": 1e308, "y_min_m": -1e308, "y_max_m": 1e308)";
  const std::string tiny_box = R"("x_min_m": 0, "x_max_m": 1e-300, "y_min_m": 0, "y_max_m": 1e-300)";
  auto file = [&](const char* name, const std::string& text) { return "ldc solve " + write(d / name, text) + " --json"; };
  expect_status({
      {file("eps_big.json", setup(R"("permittivity_F_per_m": 1e308, )")), {"eps_big.json", "permittivity_F_per_m", "1000"}},
      {file("eps_tiny.json", setup(R"("permittivity_F_per_m": 1e-300, )")), {"eps_tiny.json", "permittivity_F_per_m", "1e-12"}},
      {file("top_big.json", setup("", disc + R"("radius_m": 5e-6, "charge_C_per_m": 1e-10)", R"("x_min_m": 0, "x_max_m": 1e-3, "y_min_m": 0, "y_max_m": 1e-3)", "1e308")),
       {"top_big.json", "boundary.top.value_V", "1e+09"}},
      {file("top_neg.json", setup("", disc + R"("radius_m": 5e-6, "charge_C_per_m": 1e-10)", R"("x_min_m": 0, "x_max_m": 1e-3, "y_min_m": 0, "y_max_m": 1e-3)", "-1e308")),
       {"top_neg.json", "boundary.top.value_V"}},
      {file("charge.json", setup("", disc + R"("radius_m": 5e-6, "charge_C_per_m": 1e308)")), {"charge.json", "discs[0].charge_C_per_m", "1000"}},
      {file("radius.json", setup("", disc + R"("radius_m": 1e-300, "charge_C_per_m": 1e-10)")), {"radius.json", "discs[0].radius_m", "1e-09"}},
      {file("huge_box.json", setup("", R"("x_m": 0, "y_m": 0, "radius_m": 1, "charge_C_per_m": 1e-10)", huge_box)), {"huge_box.json", "box.x_min_m"}},
      {file("tiny_box.json", setup("", R"("x_m": 5e-301, "y_m": 5e-301, "radius_m": 1e-301, "charge_C_per_m": 1e-10)", tiny_box)),
       {"tiny_box.json", "box.x_max_m"}},
  }, 2);
  fs::remove_all(d);
}

// ---- a solve that does not converge is not a result: a disc of radius 0.4 mm in the 1 mm box
// diverged (force 5.7e92 N/m, exit 0); so is one stopped after 2 iterations ----
TEST(HostileLdc, ASolveThatDoesNotConvergeIsAFailureNotAResult) {
  const fs::path d = scratch("converge");
  const std::string big = write(d / "big_disc.json", setup("", R"("x_m": 5e-4, "y_m": 5e-4, "radius_m": 4e-4, "charge_C_per_m": 1e-10)"));
  const std::string few = write(d / "few.json", setup(R"("max_iterations": 2, )"));
  expect_status({
      {"ldc solve " + big + " --json", {"big_disc.json", "did not converge", "max_iterations = 200", "diverges"}},
      {"ldc solve " + few + " --json", {"few.json", "did not converge", "max_iterations = 2"}},
      {"ldc solve " + few, {"few.json", "did not converge"}},
  }, 1);
  fs::remove_all(d);
}

// ---- a disc far smaller than a coarse cell next to the box side (the documented keys with every
// optional one left out: the default box is 1 m with 20 cells): exit 1 "singular" after 4 s ----
TEST(HostileLdc, ADiscTooSmallForItsGridIsRefusedUpFront) {
  const fs::path d = scratch("small");
  const std::string minimal = write(d / "minimal.json", R"({"discs": [{"x_m": 5e-4, "y_m": 5e-4, "radius_m": 5e-6, "charge_C_per_m": 1e-10}]})");
  const std::string corner = write(d / "corner.json", setup("", R"("x_m": 2e-5, "y_m": 5e-4, "radius_m": 1e-8, "charge_C_per_m": 1e-10)",
                                                          R"("x_min_m": 0, "x_max_m": 1e-3, "y_min_m": 0, "y_max_m": 1e-3)", "500", 2));
  const auto t0 = std::chrono::steady_clock::now();
  expect_status({
      {"ldc solve " + minimal + " --json", {"minimal.json", "discs[0].radius_m", "too small", "cells"}},
      {"ldc solve " + corner, {"corner.json", "discs[0].radius_m", "too small"}},
  }, 2);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 3.0) << "not refused up front";
  fs::remove_all(d);
}

// ---- a large grid: minutes of silent factorisation at 2048 x 2048 cells; now a line on stderr
// says what it does (not with --quiet), and the result is unchanged ----
TEST(HostileLdc, ALargeGridSaysWhatItIsDoing) {
  const fs::path d = scratch("large");
  const std::string large = write(d / "large.json", setup("", R"("x_m": 5e-4, "y_m": 5e-4, "radius_m": 5e-6, "charge_C_per_m": 1e-10)",
                                                          R"("x_min_m": 0, "x_max_m": 1e-3, "y_min_m": 0, "y_max_m": 1e-3)", "500", 520));
  auto r = nipdem::test::run_cli_bounded("ldc solve " + large + " --json", kTag, kBoundSeconds);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("factorising the coarse matrix of 520 x 520 cells"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("\"converged\":true"), std::string::npos) << r.out;
  const std::string out = r.out;
  r = nipdem::test::run_cli_bounded("ldc solve " + large + " --json --quiet", kTag, kBoundSeconds);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, out);
  fs::remove_all(d);
}
