// The example records of examples/calibration/ are synthetic: each is made here by its
// calibration's forward model with a fixed seed (the recipe), and each must give back the
// parameters it was made with within the stated errors.
// Regenerate the files: NIPDEM_REGENERATE_EXAMPLES=1 build/tests/nipdem_tests --gtest_filter='CalibrationExamples.*'
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "nipdem/core/constants.hpp"
#include "nipdem/experiments/calibrate_adhesion.hpp"
#include "nipdem/experiments/calibrate_friction.hpp"
#include "nipdem/experiments/calibrate_magnetisation.hpp"
#include "nipdem/io/atomic_file.hpp"

using namespace nipdem;
using namespace nipdem::calibrate;
namespace fs = std::filesystem;

namespace {
const fs::path kDir = fs::path(NIPDEM_SOURCE_DIR) / "examples" / "calibration";

// Writes the file when regenerating; otherwise checks the shipped file holds the same numbers
// (relative 1e-12: shortest round-trip text, libm differences in the last bits allowed).
void check_or_write(const std::string& name, const Record& r, const std::string& recipe,
                    const std::function<Record(const fs::path&)>& read) {
  const fs::path p = kDir / name;
  const char* regen = std::getenv("NIPDEM_REGENERATE_EXAMPLES");
  if (regen && std::string(regen) == "1") {
    io::write_file_atomic(p, format_record(r, "SYNTHETIC DATA, not a measurement.\n" + recipe +
                                                  "\nMade by tests/unit/test_calibration_examples.cpp (regenerate: "
                                                  "NIPDEM_REGENERATE_EXAMPLES=1 build/tests/nipdem_tests "
                                                  "--gtest_filter='CalibrationExamples.*')."));
  }
  const Record f = read(p);
  ASSERT_EQ(f.rows(), r.rows()) << p;
  for (std::size_t j = 0; j < r.cols.size(); ++j)
    for (std::size_t i = 0; i < r.rows(); ++i)
      ASSERT_NEAR(f.cols[j][i], r.cols[j][i], 1e-12 * std::fabs(r.cols[j][i]) + 1e-300) << p << " row " << i;
}
}  // namespace

namespace {
// One friction example: made, checked against the shipped file, and calibrated back.
void friction_example(const std::string& name, const FrictionSynth& s, const FrictionOptions& o, std::uint64_t seed,
                      const std::string& recipe) {
  check_or_write(name, synthetic_friction_record(s, o, seed), recipe, read_friction_record);
  const FrictionResult f = calibrate_friction(read_friction_record(kDir / name), o);
  EXPECT_NEAR(f.mu_s, s.mu_s, 3 * f.mu_s_std) << name;  // 3 standard errors
  EXPECT_NEAR(f.mu_d, s.mu_d, 3 * f.mu_d_std) << name;
}
}  // namespace

TEST(CalibrationExamples, FrictionPlateAndCapstan) {
  FrictionSynth s;  // toner-toner, §4.3.1: mu_s 0.47, mu_d 0.19
  s.x_end_m = 40e-3;
  s.dx_m = 50e-6;
  friction_example("friction_plate.csv", s, FrictionOptions{}, 1,  // 26 g sample + 211 g weight
                   "Plate-pull record (fig. 4.7): mu_s = 0.47, mu_d = 0.19, sample 0.026 kg, weight 0.211 kg, g = 9.81,\n"
                   "stick-slip up to 5 mm, sticks of 0.8 mm, noise 0.005 N, seed 1.\n"
                   "Run: nipdem calibrate friction --data examples/calibration/friction_plate.csv --setup plate");
  FrictionSynth d = s;  // toner-DI drum, §4.3.1: mu_s 0.53, mu_d 0.34
  d.mu_s = 0.53;
  d.mu_d = 0.34;
  FrictionOptions cap;
  cap.setup = FrictionSetup::capstan;
  cap.weight_mass_kg = 0.1;
  friction_example("friction_capstan.csv", d, cap, 2,
                   "Capstan record (fig. 4.10, eq. 4.3.3, wrap pi/2): mu_s = 0.53, mu_d = 0.34, hanging weight 0.1 kg,\n"
                   "g = 9.81, stick-slip up to 5 mm, noise 0.005 N, seed 2.\n"
                   "Run: nipdem calibrate friction --data examples/calibration/friction_capstan.csv --setup capstan "
                   "--weight-mass-kg 0.1");
}

TEST(CalibrationExamples, AdhesionCentrifugalAndAfm) {
  const LogNormal truth{std::log(2e-9), 1.6};  // median 2 nN, s = 1.6 (fig. 4.18's wide spread)
  AdhesionOptions c;
  c.particle_mass_kg = 1.3e-12;
  c.rotor_radius_m = 0.05;
  c.initial_count = 1000;
  std::vector<double> w;
  for (int k = 0; k <= 20; ++k) w.push_back(std::sqrt(5e-11 * std::pow(2e4, k / 20.0) / (1.3e-12 * 0.05)));
  const Record a = synthetic_centrifugal_record(truth, c, w, 1000, 3);
  auto read_c = [](const fs::path& p) { return read_adhesion_record(p, AdhesionMethod::centrifugal); };
  check_or_write("adhesion_centrifugal.csv", a,
                 "Centrifugal detachment (fig. 4.17): 1000 particles of mass 1.3e-12 kg at r = 0.05 m, log-normal\n"
                 "adhesion with median 2e-9 N and s = 1.6, F_c = m omega^2 r from 5e-11 to 1e-6 N, seed 3.\n"
                 "Run: nipdem calibrate adhesion --data examples/calibration/adhesion_centrifugal.csv --method "
                 "centrifugal --particle-mass-kg 1.3e-12 --rotor-radius-m 0.05 --initial-count 1000",
                 read_c);
  const AdhesionResult ra = calibrate_adhesion(read_c(kDir / "adhesion_centrifugal.csv"), c);
  EXPECT_NEAR(ra.dist.mu_ln, truth.mu_ln, 3 * ra.mu_ln_std);  // 3 standard errors
  EXPECT_NEAR(ra.dist.sigma_ln, truth.sigma_ln, 3 * ra.sigma_ln_std);

  const Record b = synthetic_afm_record(truth, 40, 4);
  auto read_a = [](const fs::path& p) { return read_adhesion_record(p, AdhesionMethod::afm); };
  check_or_write("adhesion_afm.csv", b,
                 "AFM pull-off forces (fig. 4.16): 40 draws of a log-normal with median 2e-9 N and s = 1.6, seed 4.\n"
                 "Run: nipdem calibrate adhesion --data examples/calibration/adhesion_afm.csv --method afm",
                 read_a);
  AdhesionOptions afm;
  afm.method = AdhesionMethod::afm;
  const AdhesionResult rb = calibrate_adhesion(read_a(kDir / "adhesion_afm.csv"), afm);
  EXPECT_NEAR(rb.dist.mu_ln, truth.mu_ln, 3 * rb.mu_ln_std);  // 3 standard errors
}

TEST(CalibrationExamples, VsmBlackPigment) {
  const magnet::MagnetisationParams p = magnet::black_toner();  // FO2, Table 2.2
  const Record r = synthetic_vsm_record(p, {}, 0.6 / constants::mu0, 41, 0.01 * p.Ms_A_per_m, 5);
  check_or_write("vsm_black.csv", r,
                 "VSM loop of FO2 pigment (Table 2.2): Ms = 4.5e5 A/m, saturation flux 0.15 T, applied mu0 H from\n"
                 "0.6 T to -0.6 T and back (41 rows per branch), noise 1 % of Ms, no demagnetisation, seed 5.\n"
                 "Run: nipdem calibrate magnetisation --data examples/calibration/vsm_black.csv",
                 read_vsm_record);
  const MagnetisationFit f = calibrate_magnetisation(read_vsm_record(kDir / "vsm_black.csv"), {});
  EXPECT_NEAR(f.Ms_A_per_m, p.Ms_A_per_m, 3 * f.Ms_std_A_per_m);  // 3 standard errors
  EXPECT_NEAR(f.B_sat_T, p.B_sat_T, 3 * f.B_sat_std_T);
}
