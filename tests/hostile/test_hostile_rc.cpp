// Hostile input to the RC tools and the force calculators (issue 21, docs/reliability.md):
// `calibrate rc`, `rc response`, `rc charge`, `force electric`, `force dipole`. Every input below
// was accepted with exit 0 and a nonsense or silently altered result, took minutes, or was
// refused with a message naming the wrong option; each must now end with exit 2 and a message
// on stderr naming the option / file / key at fault (and its range), quickly. One test per class
// of defect; each case is one row (arguments, what stderr must name).
#include <gtest/gtest.h>

#include <cmath>
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
constexpr int kBoundSeconds = 30;  // wall-clock bound of one refused input (each takes well under 1 s)

using nipdem::test::hostile::Case;

const std::string kSrc = NIPDEM_SOURCE_DIR;
const std::string kLine = kSrc + "/examples/patterns/line.toml";
const std::string kResponse = "rc response --R 5.9e11 --Rd 1.8e24 --C 3.9e-16 --freq 500:2000:500 --json";
const std::string kElectric = "force electric --radius 5e-6 --voltage 100 --gap 1e-6 --json";
const std::string kDipole = "force dipole --moment 3.7e-11 --distance 13e-6 --angle 0 --json";

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_rc_", name); }

// A valid 20-row probe measurement: the thesis' black toner (R = 5.9e11 ohm, C = 3.9e-16 F,
// Rd = 1.8e24 ohm, Rm = 1e4 ohm, 40 V) at 100..2000 Hz, amplitudes of 1e5 particles x `scale`
// with +-1 % ripple. Rows given in `replace` (0-based data row -> text) are substituted.
std::string rc_csv(double scale, const std::vector<std::pair<int, std::string>>& replace = {}) {
  std::string s = "frequency_Hz,amplitude_V,phase_deg\n";
  const double R = 5.9e11, C = 3.9e-16, Rm = 1e4, V = 40.0, pi = 3.14159265358979323846;
  for (int i = 0; i < 20; ++i) {
    std::string row;
    for (const auto& [k, text] : replace)
      if (k == i) row = text;
    if (row.empty()) {
      const double f = 100.0 * (i + 1), w = 2 * pi * f;
      const double amp = V * Rm * w * C / std::hypot(1.0, w * (R + Rm) * C) * 1e5 * scale * (1.0 + 0.01 * (i % 3 - 1));
      const double phase = std::atan(1.0 / (w * (R + Rm) * C)) * 180.0 / pi;
      char buf[128];
      std::snprintf(buf, sizeof buf, "%g,%.6g,%.6g", f, amp, phase);
      row = buf;
    }
    s += row + "\n";
  }
  return s;
}

void expect_refused(const std::vector<Case>& cases, const std::string& tag) {
  nipdem::test::hostile::expect_cases(cases, tag, {.bound_s = kBoundSeconds, .stdout_empty = true});
}
}  // namespace

// ---- calibrate rc: data and options out of range; a fit stuck at its search box or with no
// finite chi2 claimed "converged" with exit 0 (R = C = Rd = 1, chi2 null; R = 1e30, C = 1e-30) ----
TEST(HostileRc, CalibrateRcRefusesDataAndOptionsTheFitCannotUse) {
  const fs::path d = scratch("cal");
  auto file = [&](const std::string& name, const std::string& text) {
    nipdem::io::write_file_atomic(d / name, text);
    return (d / name).string();
  };
  const std::string good = file("good.csv", rc_csv(1.0));
  const std::string huge_f = file("huge_f.csv", rc_csv(1.0, {{3, "1e300,0.0013,72"}}));
  const std::string tiny = file("tiny.csv", rc_csv(1e-290));  // amplitudes ~1e-292: only C below the search box fits
  // the fit must work on the good file (else the cases below prove nothing)
  {
    const auto r = nipdem::test::run_cli_bounded("calibrate rc --data " + good + " --particles 1e5 --json", "hostile_rc_cal", kBoundSeconds);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\"converged\":true"), std::string::npos) << r.out;
  }
  const std::string cal = "calibrate rc --json --data ";
  expect_refused({
      {cal + huge_f, {"huge_f.csv", "line 5", "frequency_Hz", "1e+12"}},
      {cal + good + " --particles 1e308", {"--particles", "1e+12"}},
      {cal + good + " --particles 0.5", {"--particles", "[1, 1e+12]"}},
      {cal + good + " --Rm 1e308", {"--Rm", "1e+30"}},
      {cal + good + " --voltage 1e300", {"--voltage", "1e+06"}},
      {cal + good + " --voltage -40", {"--voltage", "positive"}},
      {cal + good + " --amplitude-rel-std 100", {"--amplitude-rel-std", "[0, 10]"}},
      {cal + good + " --phase-std-deg 95", {"--phase-std-deg", "[0, 90]"}},
      // a measured amplitude at or above particles x voltage: no passive divider gives it
      {cal + good + " --voltage 1e-3", {"good.csv", "amplitude_V", "--particles x --voltage"}},
      // the fit ends at the search box: the values would be the box, not a fit
      {cal + tiny, {"tiny.csv", "--particles", "search range"}},
  }, "hostile_rc_cal");
  fs::remove_all(d);
}

// ---- explicit options that were silently ignored or replaced (exit 0 with other results) ----
TEST(HostileRc, ExplicitOptionsWithoutEffectOrWithAReplacedValueAreRefused) {
  expect_refused({
      {"rc charge --json --pattern " + kLine + " --t-end -1", {"--t-end", "(0, inf)"}},
      {"rc charge --json --pattern " + kLine + " --t-end 0", {"--t-end", "(0, inf)"}},
      {"rc charge --json --pattern " + kLine + " --Rd 1e20", {"--Rd", "--contact"}},
      {kElectric + " --layer-thickness -1", {"--layer-thickness", "--dielectric-layer"}},
      {kElectric + " --layer-permittivity 3", {"--layer-permittivity", "--dielectric-layer"}},
      {kElectric + " --approx-coefficient 0.5", {"--approx-coefficient", "--model approx"}},
      {kElectric + " --model series --approx-coefficient 0.5", {"--approx-coefficient", "--model approx"}},
      {kResponse + " --voltage -5", {"--voltage", "positive"}},
      {kDipole + " --samples 0", {"--samples", "[1, 1e7]"}},  // ignored with one pigment, still validated
  }, "hostile_rc_explicit");
}

// ---- exit 2, but the message blamed other options, named an internal key or printed 0.000000 ----
TEST(HostileRc, MessagesNameTheOptionGivenAndItsRange) {
  expect_refused({
      {kElectric + " --model approx --approx-coefficient 1e308", {"'--approx-coefficient'", "[0.001, 100]"}},
      {kElectric + " --dielectric-layer --layer-thickness 1e308", {"'--layer-thickness'", "[0, 0.01]"}},
      {kElectric + " --dielectric-layer --layer-permittivity 1e-300", {"'--layer-permittivity'", "[1, 100000]"}},
      {kElectric + " --dielectric-layer --layer-permittivity 0", {"'--layer-permittivity'"}},
      {kResponse + " --voltage 5 --Rm 1e308", {"'--Rm'", "[0.001, 1e+30]"}},
      {"rc response --R 5.9e11 --Rd 1.8e24 --C 3.9e-16 --voltage 5 --freq 1:1e300:1e299 --json", {"'--freq'", "1e+12 Hz"}},
      {"rc charge --json --pattern " + kLine + " --dt 1e-300", {"'--dt' = 1e-300", "output rows"}},
      {"rc charge --json --pattern " + kLine + " --C 0", {"'--C'", "[1e-24, 1]"}},
      {"rc charge --json --pattern " + kLine + " --drum-speed 1e300", {"'--drum-speed'", "[1e-06, 100]"}},  // hung before
      {"force dipole --moment -1 --distance 13e-6 --angle 0 --json", {"'--moment'", "(0, 0.001]"}},
      {"force dipole --moment 3.7e-11 --distance 13e-6 --angle 1e308 --json", {"'--angle'", "[-50000, 50000]"}},
      {"force dipole --moment 3.7e-11 --distance 11e-6 --angle 0 --json", {"'--distance'", "--radius"}},
      {kDipole + " --pigments 0", {"'--pigments'", "[1, 1000000]"}},
  }, "hostile_rc_names");
}

// ---- work without progress: 1e11 pigment-pair forces (~15 minutes) were accepted ----
TEST(HostileRc, ForceDipoleRefusesWorkBeyondTenSeconds) {
  expect_refused({
      {kDipole + " --pigments 1000 --samples 100000", {"--pigments, --samples", "1e+09"}},
      {kDipole + " --pigments 100000 --samples 1", {"--pigments, --samples", "1e+09"}},
      {kDipole + " --pigments 40000 --samples 1", {"--pigments, --samples", "1e+09"}},
  }, "hostile_rc_dipole");
}
