#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/core/vec2.hpp"
#include "nipdem/io/atomic_file.hpp"

using namespace nipdem;

TEST(Vec2, AlgebraAndCross) {
  Vec2 a{1, 2}, b{3, -1};
  EXPECT_EQ(a + b, (Vec2{4, 1}));
  EXPECT_DOUBLE_EQ(dot(a, b), 1.0);
  EXPECT_DOUBLE_EQ(cross(a, b), -7.0);
  // w x r for w = 2 about z and r = (1, 0) is (0, 2).
  EXPECT_EQ(cross(2.0, Vec2{1, 0}), (Vec2{0, 2}));
  Vec2 r = rotate(Vec2{1, 0}, std::acos(-1.0) / 2);
  EXPECT_NEAR(r.x, 0.0, 1e-15);
  EXPECT_NEAR(r.y, 1.0, 1e-15);
}

TEST(Rng, SameSeedSameStreamAndSaneMoments) {
  Rng a(42), b(42), c(43);
  EXPECT_EQ(a.next_u64(), b.next_u64());
  EXPECT_NE(Rng(42).next_u64(), c.next_u64());
  // Mean and variance of 2e5 normals: standard error of the mean 2.2e-3, so 0.01 is > 4 sigma.
  Rng r(7);
  double s = 0, s2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) { double x = r.normal(); s += x; s2 += x * x; }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.02);
}

TEST(Error, RangeMessageNamesKeyValueAndRange) {
  try {
    require_range("cfg.toml", "gap_m", -1.0, 0.0, 1.0);
    FAIL();
  } catch (const InputError& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("cfg.toml"), std::string::npos);
    EXPECT_NE(m.find("gap_m"), std::string::npos);
    EXPECT_NE(m.find("-1"), std::string::npos);
    EXPECT_NE(m.find("[0, 1]"), std::string::npos);
  }
}

TEST(AtomicFile, WriteReplacesWholeFileAndLeavesNoTemp) {
  auto dir = std::filesystem::temp_directory_path() / "nipdem_atomic_test";
  std::filesystem::remove_all(dir);
  auto p = dir / "out.json";
  io::write_file_atomic(p, "first");
  io::write_file_atomic(p, "second, longer");
  EXPECT_EQ(io::read_file(p), "second, longer");
  int n = 0;
  for (auto& e : std::filesystem::directory_iterator(dir)) { (void)e; ++n; }
  EXPECT_EQ(n, 1);
  EXPECT_THROW(io::read_file(dir / "missing"), InputError);
  std::filesystem::remove_all(dir);
}
