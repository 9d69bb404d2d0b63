// bench_magnet: cost of one magnet-field evaluation (B + gradient + induced-dipole force) as the
// engine will call it, once per particle per step. Prints ns per evaluation for the analytic black
// knife, the colour pole and a field map (bicubic Hermite), plus parameters and the git hash.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "nipdem/core/rng.hpp"
#include "nipdem/io/field_map.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/version.hpp"

using namespace nipdem;

namespace {
double ns_per_eval(const magnet::MagnetField& f, const std::vector<Vec2>& pts, int reps) {
  const auto toner = magnet::black_toner();
  double sink = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r)
    for (const Vec2& p : pts) {
      const auto s = f.at(p);
      const Vec2 F = magnet::induced_dipole_force(toner, 5.25e-6, s);
      sink += F.x + F.y;
    }
  const auto t1 = std::chrono::steady_clock::now();
  if (sink == 12345.0) std::printf("%g\n", sink);  // keep the work
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / (static_cast<double>(reps) * pts.size());
}
}  // namespace

int main() {
  const int n = 10000, reps = 50;  // 1e4 particles, like one engine step
  Rng rng(1);
  std::vector<Vec2> pts(n);
  for (auto& p : pts) p = {rng.uniform(-450e-6, 450e-6), rng.uniform(5e-6, 350e-6)};
  const auto knife = magnet::make_knife();
  const auto pole = magnet::make_color_pole();
  const auto map = io::FieldMap::sample(knife, -500e-6, 500e-6, 201, 0.0, 400e-6, 81);
  // Best of 7 trials: the machine is shared, the minimum is the least disturbed figure.
  double a = 1e300, c = 1e300, m = 1e300;
  for (int t = 0; t < 7; ++t) {
    a = std::min(a, ns_per_eval(knife, pts, reps));
    c = std::min(c, ns_per_eval(pole, pts, reps));
    m = std::min(m, ns_per_eval(map, pts, reps));
  }
  std::printf("bench_magnet git=%s particles=%d reps=%d (best of 7)\n", kGitHash, n, reps);
  std::printf("  analytic black knife (2 blocks, 5 current edges): %.1f ns/eval\n", a);
  std::printf("  analytic colour pole (1 block, 2 current edges):  %.1f ns/eval\n", c);
  std::printf("  field map 201x81 (bicubic Hermite):               %.1f ns/eval\n", m);
  return 0;
}
