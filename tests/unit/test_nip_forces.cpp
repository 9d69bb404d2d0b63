// The magnet force provider of the nip (nip/nip_forces): per-body force equals the
// model (m . grad) B at the centre of mass (eqs. 2.4.34, 4.5.1) up to the tabulation error,
// held forces are the last evaluation, and dipole-dipole forces obey Newton's third law.
#include <gtest/gtest.h>

#include <cmath>

#include "nipdem/core/rng.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/nip/nip_forces.hpp"
#include "nipdem/io/field_map.hpp"

using namespace nipdem;
using namespace nipdem::nip;

namespace {
BodyStore bodies(int n, std::uint64_t seed) {
  BodyStore b;
  Rng r(seed);
  for (int i = 0; i < n; ++i) {
    b.x.push_back(r.uniform(-150e-6, 150e-6));
    b.y.push_back(r.uniform(5e-6, 140e-6));
    b.size.push_back(r.uniform(7e-6, 14e-6));
    b.id.push_back(i);
  }
  return b;
}
}  // namespace

TEST(NipMagnetForce, MatchesModelAtCentreOfMassAndHoldsBetweenEvaluations) {
  auto field = make_magnet_field(MagnetConfig{});
  MagnetConfig c;
  c.dipole_dipole = false;
  c.field_interval = 3;
  MagnetForce f(field, c);
  BodyStore b = bodies(50, 3);
  DiscStore d;
  std::vector<double> fx(50, 0.0), fy(50, 0.0), tq(50, 0.0);
  f.add(b, d, 0.0, fx, fy, tq);
  for (int i = 0; i < 50; ++i) {
    const auto s = field->at({b.x[i], b.y[i]});
    const Vec2 ref = magnet::induced_dipole_force(c.toner, 0.5 * b.size[i], s);
    // tabulated field (20 um bicubic tiles): relative force error < 5e-4 (docs/performance.md); 2e-3 margin
    EXPECT_NEAR(fx[i], ref.x, 2e-3 * norm(ref));
    EXPECT_NEAR(fy[i], ref.y, 2e-3 * norm(ref));
  }
  // moved bodies: the next two calls hold the first evaluation, the third recomputes
  const std::vector<double> f0 = fx;
  for (auto& x : b.x) x += 20e-6;
  for (int call = 1; call <= 3; ++call) {
    std::fill(fx.begin(), fx.end(), 0.0);
    std::fill(fy.begin(), fy.end(), 0.0);
    f.add(b, d, 0.0, fx, fy, tq);
    if (call < 3) EXPECT_EQ(fx, f0);
    else EXPECT_NE(fx, f0);
  }
}

TEST(NipMagnetForce, DipoleDipoleForcesSumToZero) {
  auto field = make_magnet_field(MagnetConfig{});
  MagnetConfig c;
  c.dipole_dipole = true;
  MagnetForce f(field, c);
  BodyStore b = bodies(80, 5);
  DiscStore d;
  std::vector<double> fx(80, 0.0), fy(80, 0.0), tq(80, 0.0);
  f.add(b, d, 0.0, fx, fy, tq);
  double sx = 0, sy = 0, mx = 0;
  for (int i = 0; i < 80; ++i) {
    sx += f.dipole_fx()[i];
    sy += f.dipole_fy()[i];
    mx = std::max(mx, std::hypot(f.dipole_fx()[i], f.dipole_fy()[i]));
  }
  ASSERT_GT(mx, 0.0);
  // pairwise antisymmetric forces: the sum vanishes to round-off (1e-12 of the largest)
  EXPECT_LT(std::fabs(sx), 1e-12 * mx * 80);
  EXPECT_LT(std::fabs(sy), 1e-12 * mx * 80);
}

TEST(NipMagnetForce, ThreadedDipolePassEqualsSerial) {
  // Two threads evaluate each pair from both ends (no shared writes); the forces agree with
  // the serial half-list pass to round-off (different summation order): 1e-12 relative.
  auto field = make_magnet_field(MagnetConfig{});
  BodyStore b = bodies(120, 9);
  DiscStore d;
  std::vector<double> fx1(120, 0.0), fy1(120, 0.0), fx2(120, 0.0), fy2(120, 0.0), tq(120, 0.0);
  MagnetConfig c1;
  MagnetConfig c2;
  c2.threads = 2;
  MagnetForce f1(field, c1), f2(field, c2);
  f1.add(b, d, 0.0, fx1, fy1, tq);
  f2.add(b, d, 0.0, fx2, fy2, tq);
  double scale = 0;
  for (int i = 0; i < 120; ++i) scale = std::max(scale, std::hypot(f1.dipole_fx()[i], f1.dipole_fy()[i]));
  for (int i = 0; i < 120; ++i) {
    EXPECT_NEAR(f1.dipole_fx()[i], f2.dipole_fx()[i], 1e-12 * scale);
    EXPECT_NEAR(f1.dipole_fy()[i], f2.dipole_fy()[i], 1e-12 * scale);
  }
}

TEST(NipMagnetForce, AMapAskedOutsideItsRangeFailsCleanlyOnAnyThreadCount) {
  // A failure inside the threaded field pass (here: a body outside the field map) must come out
  // of the OpenMP region as the same InputError as with one thread, never std::terminate.
  auto field = std::make_shared<io::FieldMap>(io::FieldMap::sample(magnet::make_knife(), -200e-6, 200e-6, 41, 0.0, 200e-6, 21));
  BodyStore b = bodies(64, 9);
  b.x[40] = 500e-6;  // outside the map
  b.x[50] = -600e-6;
  for (int threads : {1, 2}) {
    MagnetConfig c;
    c.dipole_dipole = false;
    c.threads = threads;
    MagnetForce f(field, c);
    DiscStore d;
    std::vector<double> fx(64, 0.0), fy(64, 0.0), tq(64, 0.0);
    std::string msg;
    try {
      f.add(b, d, 0.0, fx, fy, tq);
    } catch (const InputError& e) {
      msg = e.what();
    }
    SCOPED_TRACE(threads);
    EXPECT_NE(msg.find("outside the field map"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(0.0005, "), std::string::npos) << "the lowest index is reported: " << msg;
  }
}

// Offered by the engine (BodyForce::hand_held), the magnet leaves its held forces out of add()
// and returns them from held(): the field term and the dipole-dipole term, which the engine adds
// as 0 + field + dipole, the bits add() gives (engine test HeldForces.*).
TEST(NipMagnetForce, HandsItsHeldForcesToTheEngineWhenOffered) {
  auto field = make_magnet_field(MagnetConfig{});
  for (bool dd : {false, true}) {
    MagnetConfig c;
    c.dipole_dipole = dd;
    MagnetForce direct(field, c), handed(field, c);
    handed.set_hand_held(true);
    BodyStore b = bodies(60, 7);
    DiscStore d;
    std::vector<double> fx(60, 0.0), fy(60, 0.0), tq(60, 0.0), gx(60, 0.0), gy(60, 0.0), gt(60, 0.0);
    direct.add(b, d, 0.0, fx, fy, tq);
    handed.add(b, d, 0.0, gx, gy, gt);
    EXPECT_TRUE(direct.held().terms == 0);
    const auto h = handed.held();
    ASSERT_EQ(h.terms, dd ? 2 : 1);
    for (int i = 0; i < 60; ++i) {
      EXPECT_EQ(gx[i], 0.0);
      double px = gx[i], py = gy[i];
      for (int q = 0; q < h.terms; ++q) { px += h.fx[q][i]; py += h.fy[q][i]; }
      EXPECT_EQ(px, fx[i]);
      EXPECT_EQ(py, fy[i]);
    }
    EXPECT_NE(fx[0], 0.0);
  }
}

// The engine's body-set number (BodyForce::body_set_version) stands for "the held forces belong
// to these bodies" only after a pass succeeded: a pass that failed for a new body set is made
// again at the next call under the same number, not skipped as if its bodies were held.
TEST(NipMagnetForce, AFailedPassForNewBodiesIsMadeAgainUnderTheSameBodySetNumber) {
  auto field = std::make_shared<io::FieldMap>(io::FieldMap::sample(magnet::make_knife(), -200e-6, 200e-6, 41, 0.0, 200e-6, 21));
  MagnetConfig c;
  c.dipole_dipole = false;
  c.field_interval = 100;  // held between passes: only a new body set evaluates again
  MagnetForce f(field, c);
  DiscStore d;
  std::vector<double> fx(64, 0.0), fy(64, 0.0), tq(64, 0.0);
  BodyStore a = bodies(64, 9);
  f.set_body_set_version(101);
  f.add(a, d, 0.0, fx, fy, tq);
  BodyStore b = bodies(64, 11);  // other bodies, the same count
  for (auto& id : b.id) id += 1000;
  b.x[10] = 500e-6;  // outside the map: the pass fails
  f.set_body_set_version(102);
  EXPECT_THROW(f.add(b, d, 0.0, fx, fy, tq), InputError);
  b.x[10] = 0.0;
  std::fill(fx.begin(), fx.end(), 0.0);
  std::fill(fy.begin(), fy.end(), 0.0);
  f.add(b, d, 0.0, fx, fy, tq);  // same number 102
  MagnetForce fresh(field, c);
  std::vector<double> gx(64, 0.0), gy(64, 0.0);
  fresh.add(b, d, 0.0, gx, gy, tq);
  EXPECT_EQ(fx, gx);
  EXPECT_EQ(fy, gy);
}
