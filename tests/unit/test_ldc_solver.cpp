// Unit tests of the LDC electrostatic solver (thesis ch. 3): building blocks against exact
// solutions, and the full solver against analytic 2D electrostatics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/solvers/ldc/annulus.hpp"
#include "nipdem/solvers/ldc/coarse_grid.hpp"
#include "nipdem/solvers/ldc/ldc_solver.hpp"
#include "nipdem/solvers/ldc/local_fd.hpp"

using namespace nipdem;
using namespace nipdem::ldc;

namespace {
constexpr double pi = constants::pi;
constexpr double eps0 = constants::eps0;

// Green's function of -Δ in the square [0,L]^2 with u = 0 on the boundary, by its sine series
// in x (closed form in y); converges like exp(-nπ|y-y0|/L).
double square_green(double L, Vec2 x, Vec2 x0) {
  double s = 0.0;
  const double yl = std::min(x.y, x0.y) / L, yg = std::max(x.y, x0.y) / L;
  for (int n = 1; n < 4000; ++n) {
    const double k = n * pi;
    const double f = 0.5 *
                     (std::exp(k * (yl - yg)) - std::exp(-k * (yl + yg)) - std::exp(k * (yl + yg - 2)) +
                      std::exp(-k * (2 - yl + yg))) /
                     (1 - std::exp(-2 * k));
    s += 2.0 * std::sin(k * x.x / L) * std::sin(k * x0.x / L) * f / k;
  }
  return s;
}

Params grounded_box(double L, int cells) {
  Params p;
  p.x_max_m = p.y_max_m = L;
  p.cells_x = p.cells_y = cells;
  return p;  // all sides Dirichlet 0 by default
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Input validation

TEST(LdcInput, InvalidSetupsThrowInputError) {
  Params p = grounded_box(1e-3, 20);
  const Disc ok{{5e-4, 5e-4}, 2e-5, 1e-10};
  {
    Params bad = p;
    bad.cells_x = 0;
    EXPECT_THROW(LdcSolver{bad}, InputError);
  }
  {
    Params bad = p;
    bad.x_max_m = 0.0;
    EXPECT_THROW(LdcSolver{bad}, InputError);
  }
  {
    Params bad = p;
    bad.left.kind = bad.right.kind = bad.top.kind = bad.bottom.kind = SideKind::neumann;
    EXPECT_THROW(LdcSolver{bad}, InputError);
  }
  LdcSolver s(p);
  const Disc outside{{1.1e-3, 5e-4}, 2e-5, 0};
  const Disc crossing{{1e-5, 5e-4}, 2e-5, 0};
  const Disc zero_r{{5e-4, 5e-4}, 0.0, 0};
  const Disc neg_r{{5e-4, 5e-4}, -1e-5, 0};
  const Disc overlap{{5.3e-4, 5e-4}, 2e-5, 0};
  EXPECT_THROW(s.solve(std::span<const Disc>(&outside, 1)), InputError);
  EXPECT_THROW(s.solve(std::span<const Disc>(&crossing, 1)), InputError);
  EXPECT_THROW(s.solve(std::span<const Disc>(&zero_r, 1)), InputError);
  EXPECT_THROW(s.solve(std::span<const Disc>(&neg_r, 1)), InputError);
  const Disc two[2] = {ok, overlap};
  EXPECT_THROW(s.solve(two), InputError);
  EXPECT_NO_THROW(s.solve(std::span<const Disc>(&ok, 1)));
}

namespace {
int run_cli(const std::string& args, std::string* out = nullptr) {
  const std::string cmd = std::string(NIPDEM_CLI_PATH) + " " + args + " 2>/dev/null";
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return -1;
  std::string s;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, f)) s += buf;
  const int rc = pclose(f);
  if (out) *out = s;
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
std::string write_tmp(const std::string& name, const std::string& content) {
  const auto path = std::filesystem::temp_directory_path() / ("nipdem_test_ldc_" + name);
  std::ofstream(path) << content;
  return path.string();
}
}  // namespace

TEST(LdcInput, CliExitsTwoOnBadSetup) {
  const std::string overlap = write_tmp("overlap.json", R"({"box": {"x_max_m": 1, "y_max_m": 1, "cells_x": 20, "cells_y": 20},
    "discs": [{"x_m": 0.5, "y_m": 0.5, "radius_m": 0.05, "charge_C_per_m": 1e-10},
              {"x_m": 0.55, "y_m": 0.5, "radius_m": 0.05, "charge_C_per_m": 1e-10}]})");
  EXPECT_EQ(run_cli("ldc solve " + overlap), 2);
  const std::string outside = write_tmp("outside.json", R"({"discs": [{"x_m": 1.5, "y_m": 0.5, "radius_m": 0.05}]})");
  EXPECT_EQ(run_cli("ldc solve " + outside), 2);
  const std::string grid = write_tmp("grid.json", R"({"box": {"cells_x": 0}, "discs": []})");
  EXPECT_EQ(run_cli("ldc solve " + grid), 2);
  const std::string notjson = write_tmp("bad.json", "{not json");
  EXPECT_EQ(run_cli("ldc solve " + notjson), 2);
  // A valid setup runs and prints one JSON object with the potential of the disc.
  const std::string good = write_tmp("good.json", R"({"permittivity_F_per_m": 1.0,
    "discs": [{"x_m": 0.5, "y_m": 0.5, "radius_m": 0.05, "charge_C_per_m": 1.0}]})");
  std::string out;
  EXPECT_EQ(run_cli("ldc solve " + good + " --json", &out), 0);
  EXPECT_NE(out.find("\"potential_V\""), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Building blocks

TEST(LdcCoarse, LinearPotentialIsExact) {
  // u = y solves the discrete problem exactly (five-point stencil and Neumann mirror are exact
  // for linear functions): any error is a solver bug, so the tolerance is round-off.
  Params p;
  p.cells_x = 17;
  p.cells_y = 23;
  p.top = {SideKind::dirichlet, 1.0};
  p.left.kind = p.right.kind = SideKind::neumann;
  const CoarseGrid g(p);
  CoarseSolver s(g);
  std::vector<double> u(g.size(), 0.0), src(g.size(), 0.0);
  s.solve(src, u);
  for (int n = 0; n < g.size(); ++n) EXPECT_NEAR(u[n], g.node(n).y, 1e-12);
  EXPECT_NEAR(g.field(u, {0.37, 0.61}).y, -1.0, 1e-12);
}

TEST(LdcAnnulus, ReproducesExactHarmonicFunction) {
  // Uncharged cylinder in a uniform field E0 x̂ plus a line charge q, free space:
  //   u = g0 - E0 (r - R²/r) cos θ - q/(2π ε) ln(r/R).
  // The boundary data on Γ is a trigonometric polynomial of degree 1, so the annulus solution
  // must be exact up to round-off; σ = ε E_r gives the force q E0 x̂ (round-off tolerance).
  const double R = 1e-5, R2 = 4e-5, E0 = 1e5, q = 3e-11, g0 = 7.0;
  const Vec2 c{1e-4, 2e-4};
  auto exact = [&](Vec2 x) {
    const Vec2 d = x - c;
    const double r = norm(d), ct = d.x / r;
    return g0 - E0 * (r - R * R / r) * ct - q / (2 * pi * eps0) * std::log(r / R);
  };
  const int M = AnnulusSolution::samples_for(R2, R / 2);
  std::vector<double> s(M);
  for (int j = 0; j < M; ++j) s[j] = exact(AnnulusSolution::sample_point(c, R2, j, M));
  AnnulusSolution a;
  a.fit(c, R, R2, q, eps0, s);
  EXPECT_NEAR(a.potential(), g0, 1e-12 * g0);
  for (double r : {1.2 * R, 2 * R, 3.5 * R})
    for (double t : {0.3, 2.0, 4.4}) {
      const Vec2 x = c + r * Vec2{std::cos(t), std::sin(t)};
      EXPECT_NEAR(a.value(x), exact(x), 1e-11 * g0);
    }
  // E_r on the surface: 2 E0 cos θ + q/(2π ε R)
  EXPECT_NEAR(a.surface_field(0.0), 2 * E0 + q / (2 * pi * eps0 * R), 1e-9 * E0);
  const Vec2 f = a.force(eps0);
  EXPECT_NEAR(f.x, q * E0, 1e-9 * q * E0);
  EXPECT_NEAR(f.y, 0.0, 1e-9 * q * E0);
}

// ---------------------------------------------------------------------------------------------
// Full solver against analytic electrostatics

TEST(LdcSolver, SingleDiscInGroundedBoxIsLineCharge) {
  // A disc of radius R at the centre of a grounded square of side L: since the regular part of
  // the Green's function is even about the centre, the disc potential is that of a line charge
  // averaged over the circle, g = q/ε · mean_circle G(x, c) (exact up to O((R/L)^4) ~ 1e-7).
  // LDC error: O(H²) coarse-grid error of the regular part (measured 3e-4 relative at H = R/2);
  // tolerance 2e-3.
  const double L = 1e-3, R = 2e-5, q = 1e-10;
  const Vec2 c{L / 2, L / 2};
  double mean = 0.0;
  for (int j = 0; j < 32; ++j) mean += square_green(L, c + R * Vec2{std::cos(0.1 + j * pi / 16), std::sin(0.1 + j * pi / 16)}, c);
  const double g_exact = q / eps0 * mean / 32;
  Params p = grounded_box(L, 100);  // H = R/2
  p.tolerance = 1e-10;
  LdcSolver s(p);
  const Disc d{c, R, q};
  const SolveStats& st = s.solve(std::span<const Disc>(&d, 1));
  EXPECT_TRUE(st.converged);
  EXPECT_EQ(s.method(0), LocalMethod::analytic);
  EXPECT_NEAR(s.potential(0), g_exact, 2e-3 * g_exact);
  // Field of the line charge at 2R (inside the local domain, analytic solution): q/(2π ε r);
  // the box adds an O((r/L)²) correction -> 1 % tolerance.
  const double e_line = q / (2 * pi * eps0 * 2 * R);
  EXPECT_NEAR(s.field(c + Vec2{2 * R, 0}).x, e_line, 1e-2 * e_line);
  // By symmetry no net force. The discrete force is not exactly zero: the 2N+1 samples on Γ are
  // not mirror symmetric in x, and the bilinear data carry an O(H²) error (measured
  // 3.7e-3, 2.2e-4, 3.3e-5 x q²/(2π ε R) at H = R, R/2, R/4). Tolerance at H = R/2: 1e-3.
  const double fs = q * q / (2 * pi * eps0 * R);
  EXPECT_LT(norm(s.force(0)), 1e-3 * fs);
}

TEST(LdcSolver, UnchargedDiscInUniformFieldFeelsNoForce) {
  // Capacitor: u = 0 at the bottom, V at the top, Neumann sides; uncharged disc in the middle.
  // Symmetry (left-right mirror, top-bottom antisymmetry about V/2) makes g = V/2 and F = 0. The
  // discrete sampling of Γ is not exactly mirror symmetric (see above): |F| below 1e-3 of the
  // natural scale ε E0² R (measured 1e-4). σ_max = 2 ε E0
  // for a cylinder in a uniform field; the finite box changes this by O((R/L)²) ~ 1e-3 and the
  // coarse grid by O(H²): 1 % tolerance.
  const double L = 1e-3, V = 100.0, R = 2e-5;
  Params p = grounded_box(L, 40);
  p.top = {SideKind::dirichlet, V};
  p.left.kind = p.right.kind = SideKind::neumann;
  p.tolerance = 1e-11;
  LdcSolver s(p);
  const Disc d{{L / 2, L / 2}, R, 0.0};
  s.solve(std::span<const Disc>(&d, 1));
  EXPECT_NEAR(s.potential(0), V / 2, 1e-9 * V);
  const double E0 = V / L;
  const double scale = eps0 * E0 * E0 * R;
  EXPECT_LT(norm(s.force(0)), 1e-3 * scale);
  // σ at the bottom of the disc (facing the grounded plate) = ε E_r with E_r = 2 E0 |cos|.
  const Vec2 eb = s.field(Vec2{L / 2, L / 2 - R * 1.0001});
  EXPECT_NEAR(-eb.y, 2 * E0, 0.01 * 2 * E0);
}

TEST(LdcSolver, ImageForceBetweenGroundedPlates) {
  // Charged cylinder (R, q) at height D between grounded plates y = 0 and y = W (Neumann sides
  // far away: the strip field decays like exp(-πx/W)). Equivalent line charge at
  // s = sqrt(D² - R²) (exact for one plate); force of a line charge in the strip:
  //   F_y = -q²/(4 ε W) cot(π s / W).
  // Neglected: the second plate's effect on the equivalent-charge shift, O(R²/(W-D)²) ~ 0.3 %,
  // plus O(H²) coarse error. Tolerance 1 %.
  const double W = 1e-3, R = 5e-5, D = 1.5e-4, q = 1e-10;
  Params p;
  p.x_max_m = 4 * W;
  p.y_max_m = W;
  p.cells_x = 160;
  p.cells_y = 40;
  p.left.kind = p.right.kind = SideKind::neumann;
  p.tolerance = 1e-10;
  LdcSolver s(p);
  const Disc d{{2 * W, D}, R, q};
  s.solve(std::span<const Disc>(&d, 1));
  const double sh = std::sqrt(D * D - R * R);
  const double f_exact = -q * q / (4 * eps0 * W) / std::tan(pi * sh / W);
  EXPECT_NEAR(s.force(0).y, f_exact, 0.01 * std::abs(f_exact));
  EXPECT_NEAR(s.force(0).x, 0.0, 1e-2 * std::abs(f_exact));  // symmetry, same tolerance
}

TEST(LdcSolver, NewtonThirdLawForTwoDiscs) {
  // Two discs with different charges, placed symmetrically about the centre of a large grounded
  // box (L = 20 x separation). The forces they exert on each other are equal and opposite for
  // the exact solution; the box adds image forces of relative size ~ (d/L)² ~ 3e-3, and the
  // discrete local solutions (each disc's force comes from its own local solution) differ by
  // O(H²): measured |F1 + F2|/|F1| = 1.7e-2 at H = R (Schwarz), 5.4e-3 at H = R/2 (Schwarz) and
  // 2.7e-3 at H = R/2 with separate annuli. Tolerance at H = R/2: 1 %. Both local methods.
  const double L = 2e-3, R = 2e-5, d = 1e-4;
  for (const bool separate : {false, true}) {
    Params p = grounded_box(L, 200);
    p.tolerance = 1e-10;
    p.prefer_separate_annuli = separate;
    LdcSolver s(p);
    const Disc discs[2] = {{{L / 2 - d / 2, L / 2}, R, 1e-10}, {{L / 2 + d / 2, L / 2}, R, -3e-10}};
    s.solve(discs);
    EXPECT_EQ(s.method(0), separate ? LocalMethod::analytic : LocalMethod::schwarz);
    const Vec2 f1 = s.force(0), f2 = s.force(1);
    EXPECT_GT(f1.x, 0.0);  // opposite charges attract
    EXPECT_LT(norm(f1 + f2), 0.01 * norm(f1)) << "separate annuli: " << separate;
  }
}

TEST(LdcSolver, WarmStartNeedsFewerIterations) {
  // Re-solving after a small displacement starting from the previous potentials and defect must
  // converge faster than a cold start and to the same answer (within the LDC tolerance 1e-9,
  // relative).
  Params p = grounded_box(1e-3, 50);
  p.tolerance = 1e-9;
  Disc discs[3] = {{{3e-4, 3e-4}, 2e-5, 1e-10}, {{6e-4, 5e-4}, 2e-5, -1e-10}, {{4e-4, 7e-4}, 3e-5, 2e-10}};
  LdcSolver warm(p);
  warm.solve(discs);
  const int cold_iterations = warm.stats().iterations;
  discs[0].center_m.x += 1e-6;
  discs[2].center_m.y -= 1e-6;
  warm.solve(discs);
  LdcSolver cold(p);
  cold.solve(discs);
  EXPECT_LT(warm.stats().iterations, cold_iterations);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(warm.potential(k), cold.potential(k), 1e-7 * std::abs(cold.potential(k)));
}

TEST(LdcSolver, ChoosesLocalMethodByConfiguration) {
  // Local radius R2 = 3R (prefer_separate_annuli off, so that annuli keep that size). Far apart:
  // analytic. Annuli overlap but Γ stays outside the other
  // disc (distance > R2 + R): Schwarz. Closer: finite differences. The three methods solve the
  // same problem, so the potentials of the Schwarz configuration computed with the
  // finite-difference local solution must agree: tolerance 1 % (the FD local solution is first
  // order, measured 0.5 % at h = R/8).
  const double R = 2e-5;
  Params p = grounded_box(1e-3, 50);
  p.tolerance = 1e-10;
  p.prefer_separate_annuli = false;
  LdcSolver s(p);
  const Vec2 c{5e-4, 5e-4};
  Disc far[2] = {{c, R, 1e-10}, {c + Vec2{2e-4, 0}, R, 1e-10}};
  s.solve(far);
  EXPECT_EQ(s.method(0), LocalMethod::analytic);
  Disc mid[2] = {{c, R, 1e-10}, {c + Vec2{4.5 * R, 0}, R, 5e-11}};
  s.solve(mid);
  EXPECT_EQ(s.method(0), LocalMethod::schwarz);
  EXPECT_TRUE(s.stats().converged);
  Params pf = p;
  pf.force_finite_difference = true;
  pf.fd_refinement = 8;
  LdcSolver f(pf);
  f.solve(mid);
  EXPECT_EQ(f.method(0), LocalMethod::finite_difference);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(f.potential(k), s.potential(k), 0.01 * std::abs(s.potential(k)));
  Disc near[2] = {{c, R, 1e-10}, {c + Vec2{2.5 * R, 0}, R, 5e-11}};
  s.solve(near);
  EXPECT_EQ(s.method(0), LocalMethod::finite_difference);
  EXPECT_TRUE(s.stats().converged);
}
