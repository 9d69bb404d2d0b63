// Probe circuit of the charge-model calibration (thesis §4.7, fig. 4.27, eqs. 4.7.1–4.7.7).
//
// Imaging roller at V1 = V sin(wt) -- R (toner assembly) -- node V2 (toner at the drum) --
// [Rd (SiOx leak) parallel to C (toner–probe capacity)] -- node V3 (probe) -- Rm -- ground.
// The measured voltage is Vm = V3 = Vm sin(wt + phi) with (eqs. 4.7.6–4.7.7)
//   (R+Rd+Rm) a - b w Rd C (R+Rm) = Rm V,
//   (R+Rd+Rm) b + a w Rd C (R+Rm) = Rd C w Rm V,
//   Vm = sqrt(a^2 + b^2),  tan(phi) = b/a,
// i.e. a + i b = V Rm (1 + i w Rd C) / ((R+Rd+Rm) + i w Rd C (R+Rm)). a > 0 always, so
// phi in (-90, 90) deg; phi > 0 is a lead of the measured voltage over the applied one.
//
// Units: R, Rd, Rm [ohm]; C [F]; V [V] (amplitude); f [Hz]. Thesis values: black toner
// R = 5.9e11, C = 3.9e-16, Rd = 1.8e24; colour R = 6.3e11, C = 2.8e-16, Rd = 1.8e24;
// Rm = 1e4 (10 kOhm). The amplitude is that of one particle: a measured probe amplitude
// must be divided by the number of particles on the probe (~1e5, §4.7).
#pragma once
#include <string>
#include <vector>

namespace nipdem::probe {

struct ProbeCircuitParams {
  double R_ohm = 5.9e11;   // toner-assembly resistance [ohm]
  double Rd_ohm = 1.8e24;  // SiOx-layer resistance [ohm]
  double C_F = 3.9e-16;    // toner–probe capacity [F]
  double Rm_ohm = 1e4;     // measurement resistance [ohm]
  // Throws InputError naming "probe circuit" and the key unless all are positive and finite.
  void validate() const;
};

struct ProbeResponse {
  double frequency_Hz = 0.0;
  double amplitude_V = 0.0;  // Vm of eq. 4.7.6
  double phase_rad = 0.0;    // phi of eq. 4.7.6 (lead > 0)
  double a_V = 0.0, b_V = 0.0;  // in-phase and quadrature parts, eq. 4.7.7
  double phase_deg() const;
};

// Solves eq. 4.7.7 for one frequency. V_amplitude [V] (any sign, finite), f [Hz] > 0.
ProbeResponse response(const ProbeCircuitParams& p, double V_amplitude, double frequency_Hz);

// Parses "F1:F2:STEP" (Hz): F1, F2, STEP > 0, F2 >= F1; includes F2 when it is reached
// within 1e-9 STEP. Throws InputError naming `key` otherwise (also for > 1e6 points).
std::vector<double> parse_frequency_range(const std::string& spec, const std::string& where = "rc response",
                                          const std::string& key = "--freq");

}  // namespace nipdem::probe
