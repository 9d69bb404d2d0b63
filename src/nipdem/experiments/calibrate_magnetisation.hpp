// The two parameters of the linear-saturated magnetisation curve (thesis §4.5, Table 2.2,
// models/magnetisation.hpp) from a VSM record M(H) (fig. 4.20):
//   M(B) = Ms min(|B| / B_sat, 1) sign(B),  B = mu0 H_eff,  H_eff = H - N M.
// Columns H_A_per_m (applied field) and M_A_per_m (sample magnetisation), any order (a loop
// has an up and a down branch; the model is odd in H and has no hysteresis, so all rows are
// fitted together). `volume_fraction` < 1 converts the magnetisation of a toner sample to
// that of its pigment (M_pigment = M / eta, as eq. 4.5.1 uses it).
//
// Demagnetisation: the thesis (§4.5) uses the bulk VSM curve against the EXTERNAL field as it
// is, because in the dense DI toner assembly the field of the surrounding pigment is part of the
// bulk measurement (no extra term as in eq. 2.4.30). That is N = 0, the default. N > 0 fits the
// curve against the internal field H - N M of a sample of demagnetising factor N (1/3 for a
// sphere): the intrinsic curve of an isolated particle. docs/calibration.md states the effect:
// Ms is unchanged, B_sat(N) = B_sat(0) - mu0 N Ms.
//
// Fit: Levenberg-Marquardt (analysis::levenberg_marquardt) in (ln Ms, ln B_sat), equal
// weights, analytic Jacobian; standard errors from the fit covariance (scaled by the residual
// variance). The record must reach saturation and have >= 2 rows on the linear part.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nipdem/experiments/calibrate_data.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::calibrate {

struct MagnetisationOptions {
  double demag_factor = 0.0;     // N in [0, 1]; 0 = bulk curve against the external field (§4.5)
  double volume_fraction = 1.0;  // pigment fraction of the measured sample (1: pigment itself)
  void validate() const;
};

struct MagnetisationFit {
  double Ms_A_per_m = 0, Ms_std_A_per_m = 0;
  double B_sat_T = 0, B_sat_std_T = 0;
  double corr = 0;             // correlation of ln Ms and ln B_sat
  double chi_linear = 0;       // mu0 Ms / B_sat: slope of the linear part [-]
  double rms_residual_A_per_m = 0;
  int n_linear = 0, n_saturated = 0;
  int iterations = 0;
  bool converged = false;
};

Record parse_vsm_record(std::string_view text, const std::string& source);
Record read_vsm_record(const std::filesystem::path& path);

MagnetisationFit calibrate_magnetisation(const Record& r, const MagnetisationOptions& o);

// Forward model: applied fields H_max -> -H_max -> H_max (`n` rows per branch) through a sample
// whose intrinsic curve is `p` (Ms, B_sat) with demagnetising factor o.demag_factor, magnetisation
// times o.volume_fraction, plus white noise noise_A_per_m.
Record synthetic_vsm_record(const magnet::MagnetisationParams& p, const MagnetisationOptions& o, double H_max_A_per_m,
                            int n, double noise_A_per_m, std::uint64_t seed);

// Writes OUT/magnetisation.csv and OUT/magnetisation.png; returns the command's JSON object.
nlohmann::json magnetisation_report(const Record& r, const MagnetisationOptions& o, const MagnetisationFit& f,
                                    const std::filesystem::path& out);

}  // namespace nipdem::calibrate
