// Adhesion-force distribution of toner on a substrate (thesis §4.4) and the config value it
// gives (`adhesion.drum_force_N` or `adhesion.roller_force_N`, docs/calibration.md).
//
// Distribution: log-normal, ln F_adh ~ N(mu, s^2); median F50 = exp(mu), spread s.
//  - centrifugal detachment (fig. 4.17): rows (omega, fraction remaining). A particle of mass
//    m on a substrate at radius r is removed once F_c = m omega^2 r exceeds its adhesion force,
//    so the fraction remaining is P(F_adh > F_c) = 1/2 erfc((ln F_c - mu) / (s sqrt 2)).
//    Fitted by Levenberg-Marquardt (analysis::levenberg_marquardt) in (mu, ln s) with binomial
//    weights sqrt(max(p(1-p), 1/N0)/N0), p the measured fraction, N0 the particles counted before
//    spinning. The fractions are nested (the same particles are counted again after every run),
//    so their errors are correlated and the least-squares covariance under-states the
//    uncertainty (by ~3x in tests). Standard errors therefore come from a parametric bootstrap
//    with a fixed seed: `bootstrap` records of N0 particles drawn from the fitted distribution
//    through the same forward model, each refitted; se = sd of the refitted parameters.
//  - AFM pull-off forces (fig. 4.16): one force per row. Maximum likelihood: mu = mean ln F,
//    s = sd ln F (n - 1); se(mu) = s / sqrt n, se(s) = s / sqrt(2 (n - 1)).
// Config value: the median, scaled to a d50 toner by F ∝ R (eq. 2.3.2, sphere-plane) when the
// measured particles' diameter and d50 are given; interval = exp(mu +- z se(mu)) x scale.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/calibrate_data.hpp"

namespace nipdem::calibrate {

struct LogNormal {
  double mu_ln = 0;     // mean of ln(F / 1 N)
  double sigma_ln = 1;  // sd of ln F [-]
  double median() const;            // exp(mu) [N]
  double mean() const;              // exp(mu + s^2/2) [N]
  double quantile(double p) const;  // [N], 0 < p < 1
  double survival(double F) const;  // P(F_adh > F)
};

enum class AdhesionMethod { centrifugal, afm };
const char* to_string(AdhesionMethod m);

struct AdhesionOptions {
  AdhesionMethod method = AdhesionMethod::centrifugal;
  double particle_mass_kg = 0;      // centrifugal: measured mass of one particle [kg]
  double rotor_radius_m = 0;        // centrifugal: distance of the substrate from the axis [m]
  double initial_count = 0;         // centrifugal: particles counted before spinning, N0 (required)
  int bootstrap = 200;              // centrifugal: parametric bootstrap resamples
  std::uint64_t seed = 1;           // centrifugal: bootstrap seed
  double measured_diameter_m = 0;   // diameter of the measured particles (0: no size scaling)
  double d50_m = 0;                 // toner d50 to scale to (with measured_diameter_m)
  std::string substrate = "drum";   // drum -> adhesion.drum_force_N, roller -> adhesion.roller_force_N
  double level = 0.95;              // interval level
  void validate() const;
};

// F_c = m omega^2 r [N] (§4.4, centrifugal force on a particle of mass m at radius r).
double centrifugal_force(double mass_kg, double omega_rad_per_s, double radius_m);

struct AdhesionResult {
  LogNormal dist;
  double mu_ln_std = 0, sigma_ln_std = 0;
  double median_N = 0, median_std_N = 0, median_lo_N = 0, median_hi_N = 0;
  double mean_N = 0, q10_N = 0, q90_N = 0;
  double scale = 1;                 // d50 / measured diameter (1 when not scaled)
  std::string config_key;
  double config_value_N = 0, config_lo_N = 0, config_hi_N = 0;
  double rms_residual = 0;          // centrifugal: of the fraction
  int iterations = 0;
  bool converged = true;
  int bootstrap_failed = 0;         // centrifugal: resamples whose fit failed (left out)
  std::vector<double> force_N;      // centrifugal: F_c per row; afm: the forces
};

// Records: centrifugal columns omega_rad_per_s (> 0, strictly increasing: the runs are made
// at increasing acceleration) and fraction_remaining in [0, 1]; afm column force_N (> 0).
Record parse_adhesion_record(std::string_view text, const std::string& source, AdhesionMethod m);
Record read_adhesion_record(const std::filesystem::path& path, AdhesionMethod m);

AdhesionResult calibrate_adhesion(const Record& r, const AdhesionOptions& o);

// Forward models. Centrifugal: `n0` particles with log-normal forces, fraction remaining after
// each omega (one draw per particle, so the counting noise is binomial and nested). AFM: n draws.
Record synthetic_centrifugal_record(const LogNormal& d, const AdhesionOptions& o, const std::vector<double>& omegas,
                                    int n0, std::uint64_t seed);
Record synthetic_afm_record(const LogNormal& d, int n, std::uint64_t seed);

// Writes OUT/adhesion.csv, OUT/adhesion.png; returns the command's JSON object.
nlohmann::json adhesion_report(const Record& r, const AdhesionOptions& o, const AdhesionResult& a,
                               const std::filesystem::path& out);

}  // namespace nipdem::calibrate
