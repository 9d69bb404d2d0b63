// Verification problems of thesis §3.8-3.10, shared by `nipdem ldc verify` and the validation
// tests. All are dimensionless (ε = 1). The thesis states its charges as \oint du/dn = q with n
// pointing out of the particle; in the physical convention of problem.hpp that is charge -q.
#pragma once
#include <optional>

#include <nlohmann/json.hpp>
#include <vector>

namespace nipdem::ldc::verify {

// Table 3.1: problem 3.8.1 with the square hole (0.45,0.55)^2, H = 1/20, h = H/2, Ωl = (0.25,0.75)^2,
// finite-difference local solution, linear interpolation on Γ, without (ε = 0) and with (ε = 0.05)
// safety region. κ_i = max |u^H_i - u^h_i| at the coarse nodes of Ωl.
struct Table31Row { int i; double kappa_eps0, kappa_eps005; };
std::vector<Table31Row> table_3_1(int iterations = 14);

// Problem 3.8.1 with the disc R1 = 0.05 at (0.5,0.5), R2 = 0.25, analytic local solution,
// trigonometric interpolation, u_guess = 0.1. One run per coarse grid 1/H.
struct DiscRun {
  double H;
  std::vector<double> delta;  // δ_i, i = 1.. (change of u^H on Γ between coarse solves i and i+1)
  std::vector<double> kappa;  // κ_i, i = 1..
};
DiscRun disc_run(int cells, int iterations);

// Table 3.2: δ_i and ρ_i = δ_i/δ_{i-1} (none for i = 1), i = 1..rows.
struct Table32Row { double H; int i; double delta; std::optional<double> rho; };
std::vector<Table32Row> table_3_2(const std::vector<int>& cells = {20, 40, 80, 160}, int rows = 4);

// Table 3.3: κ_i for i = 12..14 and σ^H = κ^{H/2}_i / κ^H_i (none for the coarsest H).
struct Table33Row { double H; int i; double kappa; std::optional<double> sigma; };
std::vector<Table33Row> table_3_3(const std::vector<int>& cells = {20, 40, 80, 160}, int first = 12, int last = 14);

// §3.7 analytic convergence factor log(R3/R2)/log(R3/R1) for R1 = 0.05, R2 = 0.25 and an outer
// radius R3. `effective_outer_radius` measures the R3 for which the domain of problem 3.8.1 acts
// like a grounded circle: R3 = R1 exp(2π ∂g/∂(-q)) from two converged LDC solves (H = 1/80).
double analytic_rate(double r3);
double effective_outer_radius();

// Table 3.4: Schwarz process for discs at (0.41,0.5) and (0.59,0.5), R11 = R21 = 0.05,
// R12 = R22 = 0.1, q1 = 2, q2 = 1, u = 0 on the outer parts of Γ. ν_i and τ_i = ν_i/ν_{i-1}.
struct Table34Row { int i; double nu; std::optional<double> tau; };
// `samples` = 2N+1 points per Γ (the thesis does not say how many it used; docs/ldc.md).
std::vector<Table34Row> table_3_4(int rows = 10, int samples = 2049);
// Asymptotic factor of the same process: ratio of successive max-norm errors after `sweeps`
// sweeps of the homogeneous error iteration (q = 0, zero outer data, error 1 on Γ*_1 initially).
double schwarz_rate(int samples, int sweeps = 30);

// Independent estimate of the asymptotic Schwarz factor of Table 3.4's geometry, without the
// trigonometric interpolation: the error map e2|Γ*1 -> e1|Γ*2 -> e2|Γ*1 (eqs. 3.9.7-3.9.8) is an
// integral operator T with the positive kernel of the annulus with a floating, uncharged inner
// disc (closed form below), discretised by the midpoint rule on `nodes` points per arc. For a
// positive operator, min_x (Tf)(x)/f(x) <= ρ(T) <= max_x (Tf)(x)/f(x) for every positive f
// (Collatz-Wielandt); with f = T1 this brackets the spectral radius, i.e. the asymptotic
// contraction of any error of one sign. The ratio is taken over the inner 80 % of Γ*1 (the
// midpoint rule is inaccurate within a few nodes of the points where the two circles cross);
// at the crossing points themselves the ratio tends to corner_limit = (1 - α/π)², α the angle of
// the overlap lens there (local half-plane analysis). `lower` is the reliable number (converged
// in n); `upper` misses the neighbourhood of the crossing points and is only indicative.
struct SchwarzBounds { double lower, upper, corner_limit; };
SchwarzBounds schwarz_rate_bounds(int nodes = 1600);

// Fig. 3.6: problem 3.10.7 (unit square, u = 0 on the boundary, discs at (0.4,0.5) and (0.6,0.5),
// R = 0.05, q1 = q2 = 1) by finite differences with h = 1/cells and the flux condition 3.10.6.
// charge_error_k = |Q_k - q_k|/|q_k| with Q_k the discrete flux through a node box around disc k.
struct Fig36 { double charge_error_1, charge_error_2, g1, g2; };
Fig36 fig_3_6(int cells = 80);

// Everything `nipdem ldc verify` reports, computed once; to_json is its --json document (keys of
// docs/cli-contract.md), shared by the CLI and the Python module.
struct Report {
  std::vector<Table31Row> t31;
  std::vector<Table32Row> t32;
  std::vector<Table33Row> t33;
  std::vector<Table34Row> t34;
  Fig36 f36;
};
Report run_all();
nlohmann::json to_json(const Report& r);

}  // namespace nipdem::ldc::verify
