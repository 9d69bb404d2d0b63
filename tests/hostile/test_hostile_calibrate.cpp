// Hostile input to the chapter-4 calibrations `calibrate restitution`, `friction`, `adhesion` and
// `magnetisation` (issue 21, docs/reliability.md): options at 1e308 / 1e-300 or of the other
// set-up, and combinations of in-range options whose result would be null, degenerate or not a
// value the config accepts. Each must end with exit 2 and a message naming the options (and the
// record) at fault, quickly; before, they printed null / 1e300 / 1e-308, blamed the record, ran
// 1e8 integration steps into exit 1, or ignored the option. One test per class, one row per case.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "support/hostile.hpp"

namespace fs = std::filesystem;

namespace {
constexpr int kBoundSeconds = 60;  // wall-clock bound of one refused input (each takes < 1 s)

using nipdem::test::hostile::Case;

const std::string kEx = std::string(NIPDEM_SOURCE_DIR) + "/examples/calibration/";
const std::string kPlate = kEx + "friction_plate.csv";
const std::string kCapstan = kEx + "friction_capstan.csv";
const std::string kCentrifugal = kEx + "adhesion_centrifugal.csv";
const std::string kAfm = kEx + "adhesion_afm.csv";
const std::string kVsm = kEx + "vsm_black.csv";

// The committed example commands (examples/calibration/*.csv, docs/calibration.md).
const std::string kDrop = "calibrate restitution --y0 1e-3 --radius 1e-3 --density 1500 --viscosity 1.8e-5 --json";
const std::string kCentrifugalRun = "calibrate adhesion --data " + kCentrifugal + " --method centrifugal --initial-count 1000";

fs::path scratch(const std::string& name) { return nipdem::test::hostile::scratch("nipdem_hostile_cal_", name); }

void expect_refused(const std::vector<Case>& cases, const std::string& tag) {
  nipdem::test::hostile::expect_cases(cases, tag, {.max_seconds = 10.0, .no_null = true});
}
}  // namespace

// ---- restitution: an option outside its physical range ----
TEST(HostileCalibrate, RestitutionOptionsOutsideTheirPhysicalRangeAreRefused) {
  expect_refused({
      {kDrop + " --y1 5e-4 --air-density 1e308", {"--air-density", "1000"}},  // was exit 1 after 5 s
      {kDrop + " --y1 1e-300 --air-density 1e308", {"--y1"}},                // was exit 0, Schiller-Naumann null
      {kDrop + " --y1 1e-300", {"--y1", "1e-09"}},                           // was exit 0, e_n ~ 1e-148
      {kDrop + " --y1 5e-4 --air-density 1e4", {"--air-density"}},
  }, "hostile_cal_rest_range");
}

// ---- restitution: in-range options whose Schiller-Naumann cross-check cannot be integrated ----
TEST(HostileCalibrate, RestitutionCrossCheckThatCannotBeIntegratedIsRefusedNamingTheOptions) {
  expect_refused({
      // a 5 um toner particle falling 100 m: 9.5e8 RK4 steps (was exit 1 after ~20 s)
      {"calibrate restitution --y0 100 --y1 5e-7 --radius 5e-6 --density 1500 --viscosity 1.8e-5 --json",
       {"--y0", "--radius", "--viscosity", "steps"}},
      // a light sphere in a dense gas: drag too stiff for the explicit step (was exit 1)
      {"calibrate restitution --y0 1 --y1 0.5 --radius 0.01 --density 1 --viscosity 1e-5 --air-density 1e3 --json",
       {"--air-density", "--viscosity", "Schiller-Naumann"}},
  }, "hostile_cal_rest_sn");
}

// ---- friction: load options outside their physical range ----
TEST(HostileCalibrate, FrictionLoadOptionsOutsideTheirPhysicalRangeAreRefused) {
  const fs::path d = scratch("fr_range");
  const std::string run = "calibrate friction --data " + kPlate + " --json --out " + (d / "out").string();
  expect_refused({
      {run + " --weight-mass-kg 1e308", {"--weight-mass-kg", "1000"}},        // was normal_force_N null, mu 0
      {run + " --gravity-m-per-s2 1e308", {"--gravity-m-per-s2", "1000"}},    // was mu ~ 1e-308
      {run + " --gravity-m-per-s2 1e-300", {"--gravity-m-per-s2"}},           // was mu ~ 1e300
      {run + " --mass-std-kg 1e3", {"--mass-std-kg", "0.237"}},               // was mu_s_std ~ 2000
  }, "hostile_cal_fr_range");
  fs::remove_all(d);
}

// ---- friction: in-range options giving a coefficient no friction measurement has ----
TEST(HostileCalibrate, FrictionCoefficientsThatDoNotFitTheRecordAreRefused) {
  const fs::path d = scratch("fr_mu");
  const std::string out = " --json --out " + (d / "out").string();
  expect_refused({
      {"calibrate friction --data " + kPlate + " --gravity-m-per-s2 1e-3" + out, {"--gravity-m-per-s2", "mu_s"}},
      {"calibrate friction --data " + kCapstan + " --setup capstan --weight-mass-kg 0.1 --wrap-angle-rad 1e-3" + out,
       {"--wrap-angle-rad", "mu_s"}},
  }, "hostile_cal_fr_mu");
  fs::remove_all(d);
}

// ---- adhesion: centrifugal options and size scaling outside their physical range ----
TEST(HostileCalibrate, AdhesionOptionsOutsideTheirPhysicalRangeAreRefusedNamingTheOption) {
  const fs::path d = scratch("ad_range");
  const std::string out = " --json --out " + (d / "out").string();
  const std::string run = kCentrifugalRun + out;
  expect_refused({
      {run + " --particle-mass-kg 1.3e-12 --rotor-radius-m 1e308", {"--rotor-radius-m"}},  // was 3.95e300 N
      {run + " --particle-mass-kg 1e308 --rotor-radius-m 0.05", {"--particle-mass-kg"}},   // blamed fraction_remaining
      {run + " --particle-mass-kg 1.3e-12 --rotor-radius-m 1e-300", {"--rotor-radius-m"}},  // was 4e-308 N
      {run + " --particle-mass-kg 1.3e-12 --rotor-radius-m 0.05 --measured-diameter-m 1e-300 --d50-m 8e-6",
       {"--measured-diameter-m"}},  // was 1.6e286 N
      {"calibrate adhesion --data " + kAfm + " --method afm --measured-diameter-m 0 --d50-m 0" + out,
       {"--measured-diameter-m"}},  // explicit 0 was ignored
  }, "hostile_cal_ad_range");
  fs::remove_all(d);
}

// ---- adhesion: in-range options giving a config value the config does not accept ----
TEST(HostileCalibrate, AdhesionConfigValueTheConfigDoesNotAcceptIsRefused) {
  const fs::path d = scratch("ad_cfg");
  const std::string run = kCentrifugalRun + " --json --out " + (d / "out").string();
  expect_refused({
      {run + " --particle-mass-kg 1e-3 --rotor-radius-m 10", {"--particle-mass-kg", "--rotor-radius-m", "adhesion.drum_force_N"}},
      {run + " --particle-mass-kg 1e-18 --rotor-radius-m 1e-3", {"--particle-mass-kg", "--rotor-radius-m", "1e-15"}},
  }, "hostile_cal_ad_cfg");
  fs::remove_all(d);
}

// ---- magnetisation: a volume fraction that scales M past any pigment ----
TEST(HostileCalibrate, MagnetisationVolumeFractionAndUnacceptableResultsAreRefused) {
  const fs::path d = scratch("mag");
  const std::string run = "calibrate magnetisation --data " + kVsm + " --json --out " + (d / "out").string();
  expect_refused({
      {run + " --volume-fraction 1e-300", {"--volume-fraction"}},  // blamed the record's M_A_per_m
      {run + " --volume-fraction 1e-10", {"--volume-fraction"}},   // was Ms = 4.5e15 A/m
      {run + " --volume-fraction 0.01", {"--volume-fraction", "vsm_black.csv", "1e+07"}},  // Ms 4.5e7 > config's 1e7
  }, "hostile_cal_mag");
  fs::remove_all(d);
}

// ---- an option the chosen set-up or method does not use: refused, never ignored silently ----
TEST(HostileCalibrate, OptionsTheSetupOrMethodDoesNotUseAreRefused) {
  const fs::path d = scratch("unused");
  const std::string out = " --json --out " + (d / "out").string();
  expect_refused({
      {"calibrate friction --data " + kPlate + " --wrap-angle-rad 1" + out, {"--wrap-angle-rad", "capstan"}},
      {"calibrate friction --data " + kCapstan + " --setup capstan --weight-mass-kg 0.1 --sample-mass-kg 0.02" + out,
       {"--sample-mass-kg", "plate"}},
      {"calibrate adhesion --data " + kAfm + " --method afm --seed 3" + out, {"--seed", "centrifugal"}},
      {"calibrate adhesion --data " + kAfm + " --method afm --particle-mass-kg 1e-12" + out, {"--particle-mass-kg", "centrifugal"}},
  }, "hostile_cal_unused");
  fs::remove_all(d);
}
