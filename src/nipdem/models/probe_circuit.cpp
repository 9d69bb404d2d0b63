#include "nipdem/models/probe_circuit.hpp"

#include <cmath>
#include <fmt/format.h>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"

namespace nipdem::probe {

void ProbeCircuitParams::validate() const {
  require_positive("probe circuit", "R_ohm", R_ohm);
  require_positive("probe circuit", "Rd_ohm", Rd_ohm);
  require_positive("probe circuit", "C_F", C_F);
  require_positive("probe circuit", "Rm_ohm", Rm_ohm);
}

double ProbeResponse::phase_deg() const { return phase_rad * 180.0 / constants::pi; }

ProbeResponse response(const ProbeCircuitParams& p, double V, double f) {
  p.validate();
  require_positive("probe circuit", "frequency_Hz", f);
  if (!std::isfinite(V)) throw_input("probe circuit", "voltage_V", fmt::format("{:g}", V), "must be finite");
  const double w = 2.0 * constants::pi * f;
  // eq. 4.7.7:  [A -B; B A] [a; b] = [Rm V; Rd C w Rm V]
  const double A = p.R_ohm + p.Rd_ohm + p.Rm_ohm;
  const double B = w * p.Rd_ohm * p.C_F * (p.R_ohm + p.Rm_ohm);
  const double r1 = p.Rm_ohm * V, r2 = p.Rd_ohm * p.C_F * w * p.Rm_ohm * V;
  const double det = A * A + B * B;
  ProbeResponse out;
  out.frequency_Hz = f;
  out.a_V = (A * r1 + B * r2) / det;
  out.b_V = (A * r2 - B * r1) / det;
  out.amplitude_V = std::hypot(out.a_V, out.b_V);   // eq. 4.7.6
  out.phase_rad = std::atan2(out.b_V, out.a_V);     // tan(phi) = b/a with a > 0 (for V > 0)
  if (V < 0.0) out.phase_rad = std::atan2(-out.b_V, -out.a_V);  // phase relative to the applied signal
  return out;
}

std::vector<double> parse_frequency_range(const std::string& spec, const std::string& where, const std::string& key) {
  const std::string allowed = "F1:F2:STEP in Hz with 0 < F1 <= F2, STEP > 0, at most 1e6 points";
  double v[3];
  std::size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t end = (i < 2) ? spec.find(':', pos) : spec.size();
    if (end == std::string::npos) throw_input(where, key, spec, "expected three fields separated by ':'", allowed);
    const std::string field = spec.substr(pos, end - pos);
    try {
      std::size_t used = 0;
      v[i] = std::stod(field, &used);
      if (used != field.size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw_input(where, key, spec, fmt::format("field '{}' is not a number", field), allowed);
    }
    pos = end + 1;
  }
  const double f1 = v[0], f2 = v[1], step = v[2];
  if (!(f1 > 0.0) || !(f2 >= f1) || !(step > 0.0) || !std::isfinite(f2) || !std::isfinite(step))
    throw_input(where, key, spec, "invalid frequency range", allowed);
  const double n = std::floor((f2 - f1) / step + 1e-9);
  if (n > 1e6) throw_input(where, key, spec, "too many frequencies", allowed);
  std::vector<double> out;
  for (long i = 0; i <= static_cast<long>(n); ++i) out.push_back(f1 + static_cast<double>(i) * step);
  return out;
}

}  // namespace nipdem::probe
