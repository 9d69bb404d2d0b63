// Electric screening (thesis §2.5.4): geometric tests with hand-placed discs.
#include <gtest/gtest.h>

#include <cmath>
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
