// Rough-cylinder queries: the prepared fast path (one sin/cos per query, rotations for the
// rest) must find the same features as direct trigonometry per vertex.
#include <gtest/gtest.h>

#include <vector>

#include "nipdem/core/rng.hpp"
#include "nipdem/geometry/walls.hpp"

using namespace nipdem;

TEST(WallQuery, PreparedRotationsEqualDirectTrigonometry) {
  geometry::Wall w;
  w.kind = geometry::Wall::Kind::cylinder;
  w.name = "roller";
  w.centre = {1e-4, -0.02};
  w.radius = 0.02;
  geometry::set_pyramid_roughness(w, 15e-6, 50e-6, 20e-6);  // prepares
  geometry::Wall direct = w;
  direct.unit_offsets_.clear();  // forces the per-vertex trigonometry
  Rng rng(7);
  int hits_total = 0;
  for (double angle : {0.0, 0.3, -2.1, 1e3}) {  // large angles: the roller has turned many times
    w.angle = direct.angle = angle;
    for (int i = 0; i < 2000; ++i) {
      // points from 20 um inside to 20 um outside the base circle, all around the roller
      const double phi = rng.uniform(0.0, 6.283185307179586), rr = w.radius + rng.uniform(-20e-6, 20e-6);
      const Vec2 c = w.centre + Vec2{rr * std::cos(phi), rr * std::sin(phi)};
      const double r = rng.uniform(2e-6, 8e-6);
      std::vector<geometry::WallHit> a, b;
      w.query(c, r, 1e-6, a);
      direct.query(c, r, 1e-6, b);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].key, b[k].key);
        // Rotation recurrences lose a few ulps of the 2 cm radius: 1e-12 R = 2e-14 m, far below
        // any contact overlap (~1e-9 m).
        EXPECT_NEAR(a[k].gap, b[k].gap, 2e-14);
        EXPECT_NEAR(a[k].point.x, b[k].point.x, 2e-14);
        EXPECT_NEAR(a[k].point.y, b[k].point.y, 2e-14);
        EXPECT_NEAR(a[k].normal.x, b[k].normal.x, 1e-8);
        EXPECT_NEAR(a[k].normal.y, b[k].normal.y, 1e-8);
      }
      hits_total += static_cast<int>(a.size());
    }
  }
  EXPECT_GT(hits_total, 1000);  // the sample does exercise contacts
}
