// Toner sizes and clusters (thesis Table 2.1, §4.1, §2.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "nipdem/core/error.hpp"
#include "nipdem/nip/toner.hpp"

using namespace nipdem;
using namespace nipdem::nip;

TEST(TonerSizes, NumberDrawnSamplesReproduceTheVolumeDistribution) {
  // Particles are drawn by number; weighting each by its volume must give back the fitted
  // normal volume distribution: median d50 and 5/95 % quantiles d50 -+ 1.645 sigma.
  // 2e5 samples: the quantiles' statistical error is ~0.3 %, so 1 % is a safe tolerance.
  SizeDistribution s;  // black toner, Table 2.1
  Rng rng(12);
  std::vector<std::pair<double, double>> dv;
  double total = 0;
  for (int i = 0; i < 200000; ++i) {
    const double d = s.sample(rng);
    ASSERT_GE(d, s.d_min());
    ASSERT_LE(d, s.d_max());
    dv.emplace_back(d, d * d * d);
    total += d * d * d;
  }
  std::sort(dv.begin(), dv.end());
  auto quantile = [&](double q) {
    double acc = 0;
    for (auto& [d, v] : dv) { acc += v; if (acc >= q * total) return d; }
    return dv.back().first;
  };
  EXPECT_NEAR(quantile(0.5), s.d50, 0.01 * s.d50);
  EXPECT_NEAR(quantile(0.05), s.d50 - 1.6449 * s.sigma(), 0.01 * s.d50);
  EXPECT_NEAR(quantile(0.95), s.d50 + 1.6449 * s.sigma(), 0.01 * s.d50);
  // By number the small particles are more frequent: number median below d50.
  EXPECT_LT(dv[dv.size() / 2].first, s.d50);
}

TEST(TonerClusters, TemplateScaledToTheTonerVolume) {
  for (const auto& t : builtin_templates()) {
    const double d = 10.5e-6;
    const auto b = make_toner(t, d, 1700);
    double v = 0;
    for (double r : b.radii) v += r * r * r;
    // member sphere volumes add up to pi d^3 / 6 (to round-off)
    EXPECT_NEAR(v, std::pow(d / 2, 3), 1e-12 * std::pow(d / 2, 3)) << t.name;
  }
  EXPECT_EQ(find_template(builtin_templates(), "tri3", "", "").radii.size(), 3u);
  EXPECT_THROW(find_template(builtin_templates(), "nonesuch", "cfg.toml", "toner.cluster"), InputError);
  EXPECT_THROW(parse_templates("[[template]]\nname = \"bad\"\ndiscs = [[0.0, 0.0, -1.0]]\n", "x.toml"), InputError);
}
