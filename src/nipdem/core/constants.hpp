// Physical constants (SI, CODATA 2018).
#pragma once
#include <numbers>

namespace nipdem::constants {
inline constexpr double pi = std::numbers::pi;
inline constexpr double eps0 = 8.8541878128e-12;     // vacuum permittivity [F/m]
inline constexpr double mu0 = 1.25663706212e-6;      // vacuum permeability [H/m]
inline constexpr double g_standard = 9.80665;        // standard gravity [m/s^2]
}  // namespace nipdem::constants
