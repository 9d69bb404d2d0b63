// Least-squares calibration of the probe circuit (thesis §4.7): fit R, Rd, C of
// models/probe_circuit.hpp to measured amplitude and phase versus frequency.
//
// Method: Levenberg–Marquardt in p = (ln R, ln Rd, ln C). Residuals are
//   (ln Vm_model - ln Vm_meas) / s_A   and   (phi_model - phi_meas) / s_phi,
// i.e. a relative amplitude error and an absolute phase error. When the noise levels are
// not given, s_A and s_phi are estimated from the residuals of a first fit (each block's
// RMS with its share of the degrees of freedom) and the fit is repeated with those weights.
// Uncertainties: covariance (J^T W J)^-1 at the optimum in log-parameters; the standard
// deviation of a parameter is value * sd(ln value) (linearised). Rd is only identifiable
// when 1/(w C) or R is not negligible next to it; for the thesis values (Rd = 1.8e24 ohm)
// the data carry no information on Rd beyond a lower bound. Therefore a profile-likelihood
// interval for Rd (Delta chi^2 = 3.84, 95 %) is always computed; when its upper end reaches
// the search box (1e30 ohm) Rd is reported as not identifiable, its standard deviation as
// infinite, and R, C uncertainties are taken from the fit with Rd fixed.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "nipdem/models/probe_circuit.hpp"

namespace nipdem::probe {

// Highest frequency accepted (data rows, `rc response --freq`): the probe is measured at
// 500-2000 Hz; below this bound no term of eq. 4.7.7 overflows for any circuit in the search box.
inline constexpr double kMaxFrequency_Hz = 1e12;

// --voltage of `rc response` and `calibrate rc` (`where`): the amplitude V of the applied
// V sin(wt), in [1e-6, 1e6] V. A negative V would be the same signal shifted by 180 deg; the
// phase is given relative to the applied signal, so it would give exactly the results of |V|:
// refused (InputError naming --voltage) rather than silently treated as |V|.
void check_amplitude(const std::string& where, double V);

// `rc response` -- the one check and computation of the CLI command and of Python's
// nipdem.rc_response: checks the circuit (ProbeCircuitParams::validate, then --R in [1e-3, 1e30],
// --Rd in [1e-3, 1e40], --C in [1e-24, 1], --Rm in [1e-3, 1e30]), the amplitude
// (check_amplitude) and the frequencies "F1:F2:STEP" (parse_frequency_range, F2 <=
// kMaxFrequency_Hz), throwing InputError naming `rc response` and the option; then solves
// eq. 4.7.7 at each frequency (every amplitude and phase finite).
std::vector<ProbeResponse> rc_response_table(const ProbeCircuitParams& p, double voltage_V, const std::string& freq);

struct RcDataPoint {
  double frequency_Hz = 0.0;
  double amplitude_V = 0.0;
  double phase_deg = 0.0;
};

// Reads a CSV with a header naming the columns frequency_Hz, amplitude_V, phase_deg (any
// order; extra columns ignored; '#' comment lines and blank lines skipped). Throws InputError
// naming the file, line and column for a missing column, a non-number, f <= 0 or f > kMaxFrequency_Hz, amplitude <= 0,
// |phase| >= 90 deg, or fewer than 3 rows.
std::vector<RcDataPoint> read_rc_csv(const std::filesystem::path& path);
std::vector<RcDataPoint> parse_rc_csv(const std::string& text, const std::string& source);

struct RcFitOptions {
  double voltage_V = 40.0;        // applied amplitude [V]
  double Rm_ohm = 1e4;            // measurement resistance [ohm]
  double particles = 1.0;         // measured amplitude = particles x single-particle amplitude
  double amplitude_rel_std = 0.0; // known relative amplitude noise [-]; 0 = estimate
  double phase_std_deg = 0.0;     // known phase noise [deg]; 0 = estimate
  int max_iterations = 500;
  void validate() const;
};

struct RcFitResult {
  double R_ohm = 0, Rd_ohm = 0, C_F = 0;
  double R_ohm_std = 0, Rd_ohm_std = 0, C_F_std = 0;  // linearised; Rd_ohm_std = inf if not identifiable
  double R_log_std = 0, Rd_log_std = 0, C_log_std = 0;  // sd of the natural logarithms
  double Rd_ohm_lower_95 = 0, Rd_ohm_upper_95 = 0;     // profile-likelihood interval (upper may be inf)
  bool Rd_identifiable = false;
  double corr_R_C = 0;            // correlation of ln R and ln C
  double amplitude_rel_std = 0;   // noise levels used for the weights
  double phase_std_deg = 0;
  double chi2 = 0;                // weighted, at the optimum
  int dof = 0;
  int iterations = 0;
  bool converged = false;         // false also when chi2 or sd(ln R), sd(ln C) is not finite or limit_hit is set
  double tau_s = 0;               // (R + Rm) C, the RC time of the circuit
  // Non-empty when R or C ended at the search box (R in [1, 1e30] ohm, C in [1e-30, 1] F): then
  // the values are the box, not a fit (e.g. amplitudes scaled by a wrong particle count); says which.
  std::string limit_hit;
};

RcFitResult fit_rc(const std::vector<RcDataPoint>& data, const RcFitOptions& opt = {});

}  // namespace nipdem::probe
