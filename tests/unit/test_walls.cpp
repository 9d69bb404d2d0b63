// Rough-cylinder queries: the prepared fast path (one sin/cos per query; the disc centre turned
// into the period's own frame, where the profile's vertices and segments are prepared constants)
// must find the same features as direct trigonometry per vertex.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "nipdem/core/rng.hpp"
#include "nipdem/geometry/walls.hpp"

using namespace nipdem;

// A 2 cm roller with the pyramid roughness of the presets' scale (prepared tables included).
static geometry::Wall rough_roller(double omega = 0.0) {
  geometry::Wall w;
  w.kind = geometry::Wall::Kind::cylinder;
  w.name = "roller";
  w.centre = {1e-4, -0.02};
  w.radius = 0.02;
  w.omega = omega;
  geometry::set_pyramid_roughness(w, 15e-6, 50e-6, 20e-6);  // prepares
  return w;
}

TEST(WallQuery, PreparedRotationsEqualDirectTrigonometry) {
  geometry::Wall w = rough_roller();
  geometry::Wall direct = w;
  direct.unit_offsets_.clear();  // forces the per-vertex trigonometry
  Rng rng(7);
  int hits_total = 0;
  for (double angle : {0.0, 0.3, -2.1, 1e3}) {  // large angles: the roller has turned many times
    w.angle = direct.angle = angle;
    w.prepare_angle();  // the engine's per-evaluation cache: the roller-frame table path
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

// Every feature of every period, by direct trigonometry (independent of query()'s choice of
// which periods to look at): segment interiors and convex vertices within reach.
static std::vector<geometry::WallHit> all_features(const geometry::Wall& w, Vec2 c, double r, double reach) {
  std::vector<geometry::WallHit> out;
  const int m = static_cast<int>(w.profile.size()) - 1;
  const double P = w.period();
  for (int k = 0; k < w.n_periods; ++k) {
    for (int j = 0; j < m; ++j) {
      const Vec2 a = w.profile_point(k, w.profile[j]), b = w.profile_point(k, w.profile[j + 1]);
      const Vec2 ab = b - a;
      const double t = dot(c - a, ab) / norm2(ab);
      if (t <= 0.0 || t >= 1.0) continue;
      const Vec2 q = a + t * ab;
      const double gap = norm(c - q) - r;
      if (gap <= reach) out.push_back({static_cast<std::int64_t>(k) * 2 * m + j, q, {}, gap, {}});
    }
    for (int j = 0; j < m; ++j) {
      const Vec2 prev = j == 0 ? Vec2{w.profile[m - 1].x - P, w.profile[m - 1].y} : w.profile[j - 1];
      if (cross(w.profile[j] - prev, w.profile[j + 1] - w.profile[j]) <= 0.0) continue;
      const Vec2 v = w.profile_point(k, w.profile[j]);
      const double gap = norm(c - v) - r;
      if (gap <= reach) out.push_back({static_cast<std::int64_t>(k) * 2 * m + m + j, v, {}, gap, {}});
    }
  }
  return out;
}

// query() looks only at the periods that can reach the disc (bound in walls.cpp); it must
// still find every feature within reach, for discs on the lands, in the pits (centres down to
// the pit bottom) and at the period boundaries, and nothing else.
TEST(WallQuery, FindsEveryFeatureWithinReachOfAllPeriods) {
  geometry::Wall w;
  w.kind = geometry::Wall::Kind::cylinder;
  w.name = "roller";
  w.centre = {0.0, -0.02};
  w.radius = 0.02;
  geometry::set_pyramid_roughness(w, 15e-6, 50e-6, 20e-6);
  Rng rng(11);
  int hits_total = 0, two_period = 0;
  for (double angle : {0.0, 0.77, -31.4}) {
    w.angle = angle;
    w.prepare_angle();
    for (int i = 0; i < 400; ++i) {
      const double phi = 1.5707963267948966 + rng.uniform(-3e-3, 3e-3);  // near the top: +-60 um of arc
      const double rr = w.radius + rng.uniform(-16e-6, 10e-6);
      const Vec2 c = w.centre + Vec2{rr * std::cos(phi), rr * std::sin(phi)};
      const double r = rng.uniform(2e-6, 8e-6), reach = rng.uniform(0.0, 2e-6);
      std::vector<geometry::WallHit> got;
      w.query(c, r, reach, got);
      auto want = all_features(w, c, r, reach);
      auto by_key = [](const geometry::WallHit& a, const geometry::WallHit& b) { return a.key < b.key; };
      std::sort(got.begin(), got.end(), by_key);
      std::sort(want.begin(), want.end(), by_key);
      ASSERT_EQ(got.size(), want.size()) << "disc at (" << c.x << ", " << c.y << "), r = " << r;
      std::int64_t periods_seen = 0, last = -1;
      for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].key, want[k].key);
        EXPECT_NEAR(got[k].gap, want[k].gap, 2e-14);  // a few ulps of the 2 cm radius (see above)
        const std::int64_t period = got[k].key / (2 * (static_cast<std::int64_t>(w.profile.size()) - 1));
        if (period != last) { ++periods_seen; last = period; }
      }
      hits_total += static_cast<int>(got.size());
      two_period += periods_seen > 1;
    }
  }
  EXPECT_GT(hits_total, 300);
  EXPECT_GT(two_period, 5);  // discs straddling a period boundary are in the sample
}

// The period hint (engine-kept per disc) only saves the atan2: for any hint (right, a neighbour,
// stale, out of range), the hits are the same, bit for bit and in the same order, as without it,
// and the hint is left naming a period the centre lies in, so that the next query takes the fast path.
TEST(WallQuery, PeriodHintNeverChangesTheHits) {
  geometry::Wall w = rough_roller(25.0);
  Rng rng(11);
  int hits_total = 0, fast_hits = 0;
  for (double angle : {0.0, 0.3, -2.1, 1e3}) {
    w.angle = angle;
    w.prepare_angle();
    for (int i = 0; i < 3000; ++i) {
      // near period boundaries half of the time (where the hint and atan2 may disagree by one period)
      const double P = w.period();
      const int k = static_cast<int>(rng.uniform(0.0, w.n_periods));
      const double s = (i % 2 == 0) ? k * P + rng.uniform(-1e-12, 1e-12) : rng.uniform(0.0, P * w.n_periods);
      const double phi = (s + w.phase) / w.radius + angle;
      const double rr = w.radius + rng.uniform(-20e-6, 20e-6);
      const Vec2 c = w.centre + Vec2{rr * std::cos(phi), rr * std::sin(phi)};
      const double r = rng.uniform(2e-6, 8e-6), reach = rng.uniform(0.0, 1e-6);
      std::vector<geometry::WallHit> plain;
      w.query(c, r, reach, plain);
      int learned = -1;  // as the engine's first query: learns the period
      std::vector<geometry::WallHit> first;
      w.query(c, r, reach, first, &learned);
      if (learned < 0) {  // out of reach of the base circle: refused before any period is looked for
        ASSERT_TRUE(plain.empty());
        continue;
      }
      ASSERT_LT(learned, w.n_periods);
      for (int hint : {learned, learned, learned - 1, learned + 1, (learned + w.n_periods / 2) % w.n_periods, -5,
                       w.n_periods, 1 << 30}) {
        std::vector<geometry::WallHit> got;
        int h = hint;
        w.query(c, r, reach, got, &h);
        ASSERT_EQ(got.size(), plain.size());
        for (std::size_t q = 0; q < got.size(); ++q) {
          EXPECT_EQ(got[q].key, plain[q].key);
          // bit for bit: the same operations on the same numbers
          EXPECT_EQ(std::memcmp(&got[q], &plain[q], sizeof(geometry::WallHit)), 0);
        }
        if (hint == learned) fast_hits += static_cast<int>(got.size());
        EXPECT_GE(h, 0);
        EXPECT_LT(h, w.n_periods);
      }
      ASSERT_EQ(first.size(), plain.size());
      hits_total += static_cast<int>(plain.size());
    }
  }
  EXPECT_GT(hits_total, 1000);  // the sample does exercise contacts
  EXPECT_GT(fast_hits, 1000);   // and the hint's fast path
}

// The pyramid profile (§2.1, figs 2.6-2.7) against its own geometry, with a flat between the
// pyramids and without one (spacing 0, side by side: one vertex fewer). Each period holds one
// triangle of base B and height h (area B h / 2 by the trapezoid rule over the vertices, exact
// for a polygon), the periods fill the circumference, and the deepest point is h. Tolerance:
// rounding of sums of a few lengths of ~1e-5 m (1e-12 relative).
TEST(WallProfile, PyramidsWithAndWithoutAFlatHaveTheirGeometry) {
  for (const double spacing : {20e-6, 0.0}) {
    SCOPED_TRACE(spacing);
    geometry::Wall w;
    w.kind = geometry::Wall::Kind::cylinder;
    w.name = "roller";
    w.centre = {0.0, -0.02};
    w.radius = 0.02;
    const double h = 7.1e-6, base = 50e-6;
    geometry::set_pyramid_roughness(w, h, base, spacing);
    ASSERT_EQ(w.profile.size(), spacing > 0 ? 4u : 3u);
    const double circumference = 2.0 * 3.14159265358979323846 * w.radius;
    EXPECT_NEAR(w.period() * w.n_periods, circumference, 1e-12 * circumference);
    const double scale = w.period() / (base + spacing);  // the stretch that fits whole periods
    double area = 0.0, deepest = 0.0;
    for (std::size_t k = 0; k + 1 < w.profile.size(); ++k) {
      const Vec2 a = w.profile[k], b = w.profile[k + 1];
      EXPECT_GT(b.x, a.x);  // arc length increases
      area += 0.5 * (a.y + b.y) * (b.x - a.x);
      deepest = std::max(deepest, b.y);
    }
    EXPECT_NEAR(area, 0.5 * base * scale * h, 1e-12 * base * h);
    EXPECT_DOUBLE_EQ(deepest, h);
  }
}
