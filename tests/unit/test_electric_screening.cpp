// Electric screening (thesis §2.5.4): geometric tests with hand-placed discs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "nipdem/core/error.hpp"
#include "nipdem/models/electric_screening.hpp"

using namespace nipdem;
using namespace nipdem::electric;

namespace {
constexpr double r = 5e-6;       // toner radius
constexpr double Rd = 0.02;      // drum radius (CPS700 scale, 2 cm)
const Vec2 kDrumC{0.0, Rd};      // drum above the particles: its bottom surface is y = 0
ScreeningParams params() {
  ScreeningParams p;
  p.range_m = 10.5e-6;  // d50 black
  return p;
}
}  // namespace

// A particle at gap 12 um (range set to 3 d50 so that a disc fits in between) with a disc right
// between it and the drum is screened; the same particle without that disc is in direct view.
TEST(ElectricScreening, ParticleBetweenScreens) {
  const auto drum = DrumSurface::circle(kDrumC, Rd);
  ScreeningParams p = params();
  p.range_m = 3 * 10.5e-6;
  const Disc a{{0.0, -(12e-6 + r)}, r};  // surface 12 um below the drum
  const Disc blocker{{0.0, -(1e-6 + r)}, r};  // 1 um from the drum, directly between
  std::vector<Disc> others{blocker};
  const auto res = screening(a, drum, others, p);
  EXPECT_TRUE(res.within_range);
  EXPECT_TRUE(res.screened);
  EXPECT_EQ(res.screened_by, 0);
  EXPECT_FALSE(res.printable());
  EXPECT_NEAR(res.gap_m, 12e-6, 1e-12);
  // The blocker itself is in direct view of the drum (a is behind it).
  const Disc a_copy = a;
  std::vector<Disc> others2{a_copy};
  EXPECT_TRUE(screening(blocker, drum, others2, p).printable());
  // Without the blocker: not screened.
  EXPECT_TRUE(screening(a, drum, std::span<const Disc>{}, p).printable());
}

// Neighbours in the same layer at the drum (touching, even with a DEM overlap of 1 % of r)
// never screen each other; this is why corridor_fraction must stay below 1.
TEST(ElectricScreening, SideNeighboursDoNotScreen) {
  const auto drum = DrumSurface::plane({0, 0}, {0, -1});  // toner below y = 0
  const double overlap = 0.01 * r;
  const Disc a{{0.0, -r}, r};
  std::vector<Disc> row{{{-(2 * r - overlap), -r}, r}, {{2 * r - overlap, -r}, r}};
  for (double f : {0.0, 0.5, 0.9}) {
    ScreeningParams p = params();
    p.corridor_fraction = f;
    EXPECT_TRUE(screening(a, drum, row, p).printable()) << "corridor_fraction " << f;
  }
  ScreeningParams bad = params();
  bad.corridor_fraction = 1.0;
  EXPECT_THROW(bad.validate(), InputError);
}

// Partially between: a disc offset laterally by 1.2 r lies off the line of sight (not
// screening with fraction 0) but inside a corridor of half-width 0.5 r (1.2r - r < 0.5r).
TEST(ElectricScreening, CorridorWidth) {
  const auto drum = DrumSurface::plane({0, 0}, {0, -1});
  ScreeningParams p = params();
  p.range_m = 30e-6;
  const Disc a{{0.0, -(20e-6 + r)}, r};
  std::vector<Disc> o{{{1.2 * r, -(2e-6 + r)}, r}};
  EXPECT_FALSE(screening(a, drum, o, p).screened);
  p.corridor_fraction = 0.5;
  EXPECT_TRUE(screening(a, drum, o, p).screened);
  // A disc behind the particle (farther from the drum) never screens.
  std::vector<Disc> behind{{{0.0, -(40e-6 + r)}, r}};
  EXPECT_FALSE(screening(a, drum, behind, p).screened);
  // self_index is skipped.
  std::vector<Disc> self{a};
  EXPECT_FALSE(screening(a, drum, self, p, 0).screened);
}

// Range: the gap is measured surface to surface along the drum normal (circle geometry),
// and a particle beyond d50 is not within range regardless of screening.
TEST(ElectricScreening, RangeOnCircle) {
  const auto drum = DrumSurface::circle({0, 0}, Rd);
  const double ang = 0.7;
  const Vec2 dir{std::cos(ang), std::sin(ang)};
  const Disc near{(Rd + r + 10e-6) * dir, r};
  const Disc far{(Rd + r + 11e-6) * dir, r};
  const auto rn = screening(near, drum, {}, params());
  EXPECT_NEAR(rn.gap_m, 10e-6, 1e-12);
  EXPECT_TRUE(rn.within_range);
  EXPECT_NEAR(norm(rn.foot - Rd * dir), 0.0, 1e-12);
  EXPECT_NEAR(dot(rn.normal, dir), -1.0, 1e-12);
  EXPECT_FALSE(screening(far, drum, {}, params()).within_range);
  EXPECT_THROW(DrumSurface::circle({0, 0}, -1.0), InputError);
  EXPECT_THROW(DrumSurface::plane({0, 0}, {0, 0}), InputError);
}

// screening_reach bounds the centre distance of every disc that screens a particle in range
// (ElectricForce tests only the discs within it along x). Random particles within range of a
// circular drum (gap in [-r, range]), radii in [0.5, 1] r_max, corridor fractions up to 0.99,
// and discs thrown around each within 1.3x the reach: every blocking one is within the reach,
// and some reach beyond 0.6 of it (the bound is not loose by more than that: with range +
// 2 r_max instead, discs of this test screen from beyond it).
TEST(ElectricScreening, BlockingDiscsLieWithinTheReach) {
  const double r_max = 6e-6;
  const auto drum = DrumSurface::circle({0.0, 0.0}, Rd);
  std::uint64_t s = 12345;
  auto uni = [&s]() {  // xorshift64*, in [0, 1)
    s ^= s >> 12; s ^= s << 25; s ^= s >> 27;
    return static_cast<double>((s * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
  };
  double farthest = 0.0;
  int blocking = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    ScreeningParams p = params();
    p.range_m = 10.5e-6 * (0.5 + 2.5 * uni());
    p.corridor_fraction = 0.99 * uni();
    const double rp = r_max * (0.5 + 0.5 * uni());
    const double ang = 6.283185307179586 * uni();
    const Vec2 dir{std::cos(ang), std::sin(ang)};
    const Disc part{(Rd + rp + (-rp + (p.range_m + rp) * uni())) * dir, rp};
    const double reach = screening_reach(p, r_max);
    const auto res = screening(part, drum, {}, p);
    ASSERT_TRUE(res.within_range);
    for (int q = 0; q < 50; ++q) {
      const double a = 6.283185307179586 * uni(), dist = 1.3 * reach * uni();
      const Disc d{part.centre + Vec2{dist * std::cos(a), dist * std::sin(a)}, r_max * (0.5 + 0.5 * uni())};
      if (!blocks_corridor(part, res.foot, d, p.corridor_fraction * rp)) continue;
      ++blocking;
      EXPECT_LT(dist, reach);
      farthest = std::max(farthest, dist / reach);
    }
  }
  EXPECT_GT(blocking, 1000);
  EXPECT_GT(farthest, 0.6);
  // The corner case: a particle of r_max at gap = range, corridor fraction 0.99, and a disc of
  // r_max just over the corridor's far corner (0.7 r_max beyond its end and its side) screens
  // it from sqrt((range + 1.7 r)^2 + (1.69 r)^2), beyond range + 2 r_max.
  ScreeningParams p = params();
  p.corridor_fraction = 0.99;
  const Vec2 down{0.0, -1.0};  // from the particle to the drum (the drum above, kDrumC)
  const auto top = DrumSurface::circle(kDrumC, Rd);
  const Disc part{{0.0, -(p.range_m + r_max)}, r_max};
  const auto res = screening(part, top, {}, p);
  ASSERT_TRUE(res.within_range);
  const double L = norm(res.foot - part.centre), w = 0.99 * r_max;
  const Disc corner{part.centre - (L + 0.7 * r_max) * down + Vec2{w + 0.7 * r_max, 0.0}, r_max};
  ASSERT_TRUE(blocks_corridor(part, res.foot, corner, w));
  EXPECT_LT(norm(corner.centre - part.centre), screening_reach(p, r_max));
  EXPECT_GT(norm(corner.centre - part.centre), p.range_m + 2.0 * r_max);
}
