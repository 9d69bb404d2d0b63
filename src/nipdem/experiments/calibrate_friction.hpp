// Friction coefficients mu_s, mu_d from a force-displacement record (thesis §4.3.1).
//
// Two set-ups (docs/calibration.md):
//  - plate (fig. 4.7): a resin sample plate with a weight is pulled over a resin substrate;
//    F_n = (m_sample + m_weight) g (eq. 4.3.1) and F_t = mu F_n (eq. 4.3.2).
//  - capstan (fig. 4.10): a flexible sample wrapped a quarter turn round the roller or drum
//    carries a hanging weight F_z = m g; F_t / F_z = exp(mu theta), theta = pi/2 (eq. 4.3.3).
// The record (columns x_m, force_N, in measurement order) has two parts, as in figs. 4.8-4.9:
// a slow stick-slip part x < stick_end (the static force is the force at which each stick
// breaks) and a fast sliding part x >= stick_end + transition (the dynamic force is its mean).
//
// Static force: each stick-slip peak is a local maximum followed within `window` samples by a
// drop of more than `min_drop_N`; its force is a straight-line fit to the last half of the
// loading ramp before it, evaluated at the peak (unbiased by the noise, unlike the raw maximum).
// F_s = mean over the peaks, standard error = sd / sqrt(n) (n >= 2), or the line fit's standard
// error at the peak for a single peak.
// Dynamic force: F_d = mean of the sliding part; standard error by batch means (B contiguous
// blocks, sd of block means / sqrt(B)) because the plateau's variations (sample thickness,
// §4.3.1) are correlated along x. Mass uncertainty enters by linear error propagation.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/core/constants.hpp"
#include "nipdem/experiments/calibrate_data.hpp"

namespace nipdem::calibrate {

enum class FrictionSetup { plate, capstan };
FrictionSetup parse_friction_setup(const std::string& s);  // "plate" | "capstan"; InputError otherwise
const char* to_string(FrictionSetup s);

struct FrictionOptions {
  FrictionSetup setup = FrictionSetup::plate;
  double sample_mass_kg = 0.026;   // plate: the sample plate (thesis: 26 g or 34 g); unused for capstan
  double weight_mass_kg = 0.211;   // plate: weight on the sample (211 g); capstan: the hanging weight
  double mass_std_kg = 0.0;        // standard uncertainty of the (total) mass [kg]
  double gravity_m_per_s2 = 9.81;
  double stick_end_m = 5e-3;       // end of the slow stick-slip part (thesis: first 5 mm)
  double transition_m = 2e-3;      // skipped after stick_end before the sliding plateau
  double wrap_angle_rad = constants::pi / 2;  // capstan wrap angle theta (eq. 4.3.3: pi/2)
  double min_drop_N = 0.0;         // slip detection threshold; 0 = 6 x the noise estimate
  int window = 5;                  // samples on each side of a peak
  int blocks = 10;                 // batch means for the plateau's standard error
  void validate() const;
};

struct StickPeak {
  double x_m = 0, force_N = 0, force_std_N = 0;
};

struct FrictionResult {
  double load_force_N = 0, load_force_std_N = 0;  // F_n (plate) or F_z (capstan)
  double static_force_N = 0, static_force_std_N = 0;
  double dynamic_force_N = 0, dynamic_force_std_N = 0;
  double mu_s = 0, mu_s_std = 0, mu_d = 0, mu_d_std = 0;
  double noise_N = 0;              // white-noise estimate of the force signal
  double min_drop_N = 0;           // threshold used
  std::vector<StickPeak> peaks;
  std::size_t n_stick = 0, n_slide = 0;
};

// Coefficient from a tangential force F [N] for the set-up: plate F / F_n (eq. 4.3.2),
// capstan ln(F / F_z) / theta (eq. 4.3.3).
double friction_coefficient(const FrictionOptions& o, double force_N, double load_force_N);
// Inverse: the force a coefficient mu produces.
double friction_force(const FrictionOptions& o, double mu, double load_force_N);
// F_n = (m_sample + m_weight) g (eq. 4.3.1) for plate, F_z = m_weight g for capstan.
double load_force(const FrictionOptions& o);

// Record columns: x_m (strictly increasing), force_N (> 0).
Record read_friction_record(const std::filesystem::path& path);
Record parse_friction_record(std::string_view text, const std::string& source);

FrictionResult calibrate_friction(const Record& r, const FrictionOptions& o);

// Forward model (tests and examples/calibration): a stick-slip sawtooth up to stick_end
// (ramp from the slip level to a peak of mu_s, each peak jittered by `peak_jitter` relative),
// an exponential settling to mu_d, a plateau with a correlated perturbation (Ornstein-Uhlenbeck
// along x: relative sd `wave_rel`, correlation length `corr_m`; the thickness variations of
// §4.3.1) and white noise `noise_N`.
struct FrictionSynth {
  double mu_s = 0.47, mu_d = 0.19;
  double x_end_m = 80e-3, dx_m = 20e-6;
  double ramp_m = 0.8e-3;          // loading length of one stick
  double slip_rel = 0.75;          // force after a slip, relative to the peak
  double peak_jitter = 0.02;
  double wave_rel = 0.03, corr_m = 1e-3;
  double noise_N = 0.005;
};
Record synthetic_friction_record(const FrictionSynth& s, const FrictionOptions& o, std::uint64_t seed);

// Writes OUT/friction.csv (record with its part), OUT/friction_peaks.csv, OUT/friction.png and
// returns the JSON object of the command (paths included).
nlohmann::json friction_report(const Record& r, const FrictionOptions& o, const FrictionResult& f,
                               const std::filesystem::path& out);

}  // namespace nipdem::calibrate
