// Tests of the dipole-dipole law (models/dipole.hpp) and the pigment study (dipole_pigments.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/constants.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/models/dipole.hpp"
#include "nipdem/models/dipole_pigments.hpp"

using namespace nipdem;
using namespace nipdem::dipole;

namespace {
constexpr double k = constants::mu0 / (4 * constants::pi);
}

TEST(Dipole, HandValuesHeadToTailAndSideBySide) {
  // Head-to-tail (m along r): F_i = -6 k m^2 / r^4 e (attraction); side by side (m perpendicular
  // to r): F_i = +3 k m^2 / r^4 e (repulsion). Energies -2 k m^2/r^3 and +k m^2/r^3. Exact: 1e-12.
  const double m = 3.7e-11, r = 13e-6;
  const Vec2 F1 = dipole_force({m, 0}, {m, 0}, {r, 0});
  EXPECT_NEAR(F1.x, -6 * k * m * m / std::pow(r, 4), 1e-12 * std::abs(F1.x));
  EXPECT_NEAR(F1.y, 0.0, 1e-20);
  const Vec2 F2 = dipole_force({0, m}, {0, m}, {r, 0});
  EXPECT_NEAR(F2.x, 3 * k * m * m / std::pow(r, 4), 1e-12 * std::abs(F2.x));
  EXPECT_NEAR(dipole_energy({m, 0}, {m, 0}, {r, 0}), -2 * k * m * m / std::pow(r, 3), 1e-12 * 2 * k * m * m / std::pow(r, 3));
  EXPECT_NEAR(dipole_energy({0, m}, {0, m}, {r, 0}), k * m * m / std::pow(r, 3), 1e-12 * k * m * m / std::pow(r, 3));
  // Magnitude used in §2.4.2 (theta = 0, d = 13 um, m = 3.7e-11): 28.76 nN.
  EXPECT_NEAR(norm(F1), 2.876e-8, 0.001e-8);
}

TEST(Dipole, NewtonsThirdLawAndForceIsMinusEnergyGradient) {
  // Third law: exact algebraic symmetry, 1e-14 relative. -grad U by central differences with
  // h = 1e-5 r: truncation (h/r)^2 ~ 1e-10, rounding eps*U/h ~ 1e-11 |F|; tolerance 1e-7 |F|.
  Rng rng(5);
  for (int t = 0; t < 100; ++t) {
    const Vec2 mi{rng.uniform(-1, 1) * 1e-11, rng.uniform(-1, 1) * 1e-11};
    const Vec2 mj{rng.uniform(-1, 1) * 1e-11, rng.uniform(-1, 1) * 1e-11};
    const double r = rng.uniform(10e-6, 100e-6), a = rng.uniform(0, 2 * constants::pi);
    const Vec2 d = r * Vec2{std::cos(a), std::sin(a)};
    const Vec2 Fi = dipole_force(mi, mj, d), Fj = dipole_force(mj, mi, -d);
    EXPECT_LT(norm(Fi + Fj), 1e-14 * norm(Fi));
    const double h = 1e-5 * r;
    const Vec2 g{(dipole_energy(mi, mj, d + Vec2{h, 0}) - dipole_energy(mi, mj, d - Vec2{h, 0})) / (2 * h),
                 (dipole_energy(mi, mj, d + Vec2{0, h}) - dipole_energy(mi, mj, d - Vec2{0, h})) / (2 * h)};
    EXPECT_LT(norm(Fi + g), 1e-7 * norm(Fi)) << t;
  }
}

TEST(Dipole, FieldRouteAndThreeDLawAgreeWithPairForce) {
  // (m_i . grad) B_j(r_i) from dipole_field (eq. 2.4.39) must equal the closed-form pair force, and
  // the 3D law restricted to z = 0 must equal the 2D one; the field must be curl/div-free.
  // Same formula rearranged: 1e-12 relative. FD of the field: h = 1e-6 r, tolerance 1e-6 |grad B|.
  Rng rng(9);
  for (int t = 0; t < 50; ++t) {
    const Vec2 mi{rng.uniform(-1, 1), rng.uniform(-1, 1)}, mj{rng.uniform(-1, 1), rng.uniform(-1, 1)};
    const Vec2 d{rng.uniform(-5e-5, 5e-5), rng.uniform(-5e-5, 5e-5)};
    if (norm(d) < 5e-6) continue;
    const Vec2 F = dipole_force(mi, mj, d);
    const auto s = dipole_field(mj, d);
    const Vec2 Ff = magnet::dipole_force(mi, s);
    EXPECT_LT(norm(F - Ff), 1e-12 * norm(F));
    const Vec3 F3 = dipole_force3({mi.x, mi.y, 0}, {mj.x, mj.y, 0}, {d.x, d.y, 0});
    EXPECT_LT(std::hypot(F3.x - F.x, F3.y - F.y), 1e-12 * norm(F));
    EXPECT_EQ(F3.z, 0.0);
    const double h = 1e-6 * norm(d);
    const Vec2 bxp = dipole_field(mj, d + Vec2{h, 0}).B, bxm = dipole_field(mj, d - Vec2{h, 0}).B;
    const Vec2 byp = dipole_field(mj, d + Vec2{0, h}).B, bym = dipole_field(mj, d - Vec2{0, h}).B;
    const double gxx = (bxp.x - bxm.x) / (2 * h), gxy = (byp.x - bym.x) / (2 * h);
    const double gyx = (bxp.y - bxm.y) / (2 * h), gyy = (byp.y - bym.y) / (2 * h);
    const double sc = std::sqrt(gxx * gxx + gxy * gxy + gyx * gyx + gyy * gyy);
    EXPECT_LT(std::abs(gxx - s.dB.xx) + std::abs(gxy - s.dB.xy) + std::abs(gyx - s.dB.yx) + std::abs(gyy - s.dB.yy), 1e-6 * sc);
    // In-plane restriction of a 3D field: dBx/dx + dBy/dy = -dBz/dz != 0 in general, so only the
    // in-plane curl vanishes.
    EXPECT_LT(std::abs(gxy - gyx), 1e-6 * sc);
  }
}

TEST(DipolePigments, ThirteenPigmentMeanEqualsCherryPitAndSpreadIsOfOrderForce) {
  // Fig. 2.14: the mean over 10,000 random placements of 13 pigments equals the cherry-pit force
  // (exact in expectation for uniform pigment density, see dipole_pigments.hpp): each component of
  // the mean within 4 standard errors. Fig. 2.15: the spread is of the order of the force itself:
  // std(|F|) / F_cherry in [0.3, 3].
  for (double deg : {0.0, 45.0, 90.0}) {
    PigmentStudyParams p;
    p.angle_rad = deg * constants::pi / 180;
    const auto cherry = pigment_study(p);
    p.pigments = 13;
    p.samples = 10000;
    p.seed = 42;
    const auto r = pigment_study(p);
    const double sem = 1.0 / std::sqrt(10000.0);
    EXPECT_NEAR(r.force_mean_N.x, cherry.force_mean_N.x, 4 * r.force_vec_std_N.x * sem) << deg;
    EXPECT_NEAR(r.force_mean_N.y, cherry.force_mean_N.y, 4 * r.force_vec_std_N.y * sem) << deg;
    EXPECT_NEAR(r.force_mean_N.z, 0.0, 4 * r.force_vec_std_N.z * sem) << deg;
    const double ratio = r.force_std_N / cherry.force_mean_abs_N;
    EXPECT_GT(ratio, 0.3) << deg;
    EXPECT_LT(ratio, 3.0) << deg;
  }
}

TEST(DipolePigments, TwentyThousandPigmentsReproduceCherryPit) {
  // Black toner (fig. 2.14): one placement of 20,000 pigments. The spread scales as n^-1/2; we
  // measure it at n = 2000 (16 placements) and require the single 20,000-pigment force within
  // 4 sigma_2000 * sqrt(2000/20000) of the cherry-pit force. The variance is A/n + B/n^2 (single-
  // pigment and pigment-pair terms; B/A ~ 65 here, so at n = 13 the pair term dominates and the
  // spread is ~2.5x the n^-1/2 extrapolation -- measured, see docs/magnetic.md). Between n = 500 and
  // n = 2000 the pair term is < 15 %, so we check the n^-1/2 scaling there within a factor 1.6
  // (16-sample std estimates: ~18 % error each); extrapolating from 2000 to 20000 with n^-1/2 is then
  // slightly conservative.
  // Takes ~6 s in Release (4e8 pair forces).
  PigmentStudyParams p;
  p.angle_rad = 30.0 * constants::pi / 180;
  const double cherry = pigment_study(p).force_mean_abs_N;
  p.pigments = 2000;
  p.samples = 16;
  p.seed = 7;
  const double sd2000 = pigment_study(p).force_std_N;
  p.pigments = 500;
  const double sd500 = pigment_study(p).force_std_N;
  const double scale = sd500 / sd2000 / std::sqrt(2000.0 / 500.0);
  EXPECT_GT(scale, 1 / 1.6);
  EXPECT_LT(scale, 1.6);
  p.pigments = 20000;
  p.samples = 1;
  const auto r = pigment_study(p);
  EXPECT_NEAR(r.force_mean_abs_N, cherry, 4 * sd2000 * std::sqrt(0.1));
  EXPECT_LT(4 * sd2000 * std::sqrt(0.1), 0.1 * cherry);  // the check is tight enough to mean something
}

TEST(DipolePigments, BadInputThrows) {
  PigmentStudyParams p;
  p.distance_m = 11e-6;  // < 2R = 12 um
  EXPECT_THROW(pigment_study(p), InputError);
  p = {};
  p.pigments = 0;
  EXPECT_THROW(pigment_study(p), InputError);
  p = {};
  p.moment_Am2 = -1;
  EXPECT_THROW(pigment_study(p), InputError);
  p = {};
  p.pigments = 100000;
  p.samples = 100000;
  EXPECT_THROW(pigment_study(p), InputError);
}

TEST(DipoleCutoff, BoundHoldsAndErrorFallsWithCutoff) {
  // Truncation error of a cut-off on a relaxed random packing (phi = 0.75, R = 5.25 um): the
  // measured mean error (relative to the contact force scale) must lie below the worst-case bound
  // 16 phi R^2/r_c^2 of cutoff_radius(), and fall monotonically with r_c.
  TruncationSetup s;
  s.box_m = 500e-6;
  s.reference_cutoff_m = 200e-6;
  s.probe_radius_m = 40e-6;
  const std::vector<double> rcs{4 * s.radius_m, 8 * s.radius_m, 16 * s.radius_m, 32 * s.radius_m};
  const auto st = measure_cutoff_truncation(s, rcs);
  ASSERT_EQ(st.size(), rcs.size());
  for (std::size_t i = 0; i < st.size(); ++i) {
    EXPECT_GT(st[i].probes, 20);
    const double bound = 16 * s.packing_fraction * s.radius_m * s.radius_m / (rcs[i] * rcs[i]);
    EXPECT_LT(st[i].mean_rel_to_contact, bound) << rcs[i];
    if (i > 0) {
      EXPECT_LT(st[i].mean_rel_error, st[i - 1].mean_rel_error) << rcs[i];
    }
  }
  EXPECT_NEAR(cutoff_radius(5e-6, 0.8, 0.01), 4 * 5e-6 * std::sqrt(80.0), 1e-18);
  EXPECT_THROW(cutoff_radius(5e-6, 0.8, 0.0), InputError);
  // The packing is dense and nearly overlap-free.
  const auto pk = random_dense_packing(5e-6, 0.75, 300e-6, 3);
  EXPECT_NEAR(pk.size() * constants::pi * 25e-12 / (300e-6 * 300e-6), 0.75, 0.01);
}
