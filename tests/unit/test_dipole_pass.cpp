// The dipole-dipole pass of the nip (dipole::PairSum, used by nip::MagnetForce): a
// persistent Verlet pair list with a skin, half list with Newton's third law, threaded. It must
// give the plain cut-off sum F_i = sum_{|r_ij| < r_c} dipole_force(m_i, m_j, r_ij) (eq. 2.4.39)
// and must not depend on when the list was built (checkpoint/resume stays bitwise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "nipdem/core/rng.hpp"
#include "nipdem/nip/nip_forces.hpp"
#include "nipdem/models/dipole.hpp"

using namespace nipdem;

namespace {

struct Cloud {
  std::vector<double> x, y;
  std::vector<Vec2> m;
};

// Dense random packing of toner-sized discs (R = 5.25 um, area fraction 0.7) with moments of
// the saturated black toner (3.7e-11 A m^2) whose magnitude and direction vary a little, as
// the knife's field does over the assembly.
Cloud dense_cloud(double box, std::uint64_t seed) {
  Cloud c;
  const auto p = dipole::random_dense_packing(5.25e-6, 0.7, box, seed);
  Rng r(seed + 17);
  for (const Vec2& q : p) {
    c.x.push_back(q.x);
    c.y.push_back(q.y);
    const double a = -1.2 + r.uniform(-0.4, 0.4), s = 3.7e-11 * r.uniform(0.6, 1.0);
    c.m.push_back({s * std::cos(a), s * std::sin(a)});
  }
  return c;
}

// Largest |F_list - F_ref| / |F_ref| over particles (particles with a vanishing reference
// force are compared with the sum of the magnitudes of their pair forces instead).
double max_rel_diff(const std::vector<double>& ax, const std::vector<double>& ay, const std::vector<double>& bx,
                    const std::vector<double>& by) {
  double worst = 0;
  for (std::size_t i = 0; i < ax.size(); ++i) {
    const double d = std::hypot(ax[i] - bx[i], ay[i] - by[i]), f = std::hypot(bx[i], by[i]);
    if (d == 0.0) continue;
    worst = std::max(worst, d / std::max(f, 1e-300));
  }
  return worst;
}

}  // namespace

TEST(DipolePass, ListSumEqualsBruteForceCutoffSum) {
  // ~880 particles in a 330 um box (cut-off 42 um: ~60 partners each, many pairs near r_c).
  // The list pass and the O(N^2) reference sum the same pair forces in different orders with a
  // differently arranged (algebraically identical) formula: they agree to round-off. Measured
  // largest relative difference ~1e-14 (the sums cancel partly); bound 1e-12 relative per particle.
  const Cloud c = dense_cloud(330e-6, 3);
  ASSERT_GT(c.x.size(), 850u);
  std::vector<double> rx, ry;
  dipole::brute_force_pair_sum(c.x, c.y, c.m, 42e-6, rx, ry);
  for (int threads : {1, 2, 3}) {
    dipole::PairSum ps({42e-6, 2e-6, threads});
    std::vector<double> fx, fy;
    ps.compute(c.x, c.y, c.m, false, fx, fy);
    const double e = max_rel_diff(fx, fy, rx, ry);
    std::printf("threads=%d: %zu listed pairs, max relative difference to brute force %.3g\n", threads, ps.listed_pairs(), e);
    EXPECT_LT(e, 1e-12) << "threads " << threads;
    // the half list holds every pair within r_c + skin exactly once
    std::size_t within = 0;
    for (std::size_t i = 0; i < c.x.size(); ++i)
      for (std::size_t j = i + 1; j < c.x.size(); ++j)
        within += std::hypot(c.x[i] - c.x[j], c.y[i] - c.y[j]) < 44e-6;
    EXPECT_EQ(ps.listed_pairs(), within);
  }
}

TEST(DipolePass, ReusedListGivesBitwiseTheForcesOfAFreshList) {
  // Particles drift and jiggle over 60 passes (0.15 um per pass: two of them close the 2 um skin
  // over a few passes, so the list is rebuilt several times and reused in between). Each pass
  // must equal bitwise a pass with a list built just now (summation order independent of the
  // build time: checkpoint/resume exactness) and the brute-force sum to 1e-12 (round-off).
  Cloud c = dense_cloud(250e-6, 5);
  const std::size_t n = c.x.size();
  Rng r(11);
  std::vector<double> vx(n), vy(n);
  for (std::size_t i = 0; i < n; ++i) { vx[i] = r.uniform(-0.15e-6, 0.15e-6); vy[i] = r.uniform(-0.15e-6, 0.15e-6); }
  for (int threads : {1, 2}) {
    Cloud cc = c;
    dipole::PairSum kept({42e-6, 2e-6, threads});
    for (int pass = 0; pass < 60; ++pass) {
      std::vector<double> fx, fy, gx, gy, rx, ry;
      kept.compute(cc.x, cc.y, cc.m, true, fx, fy);
      dipole::PairSum fresh({42e-6, 2e-6, threads});
      fresh.compute(cc.x, cc.y, cc.m, true, gx, gy);
      ASSERT_EQ(fx, gx) << "pass " << pass << " threads " << threads;
      ASSERT_EQ(fy, gy) << "pass " << pass << " threads " << threads;
      if (pass % 10 == 9) {
        dipole::brute_force_pair_sum(cc.x, cc.y, cc.m, 42e-6, rx, ry);
        EXPECT_LT(max_rel_diff(fx, fy, rx, ry), 1e-12) << "pass " << pass;
      }
      for (std::size_t i = 0; i < n; ++i) {
        cc.x[i] += vx[i] + r.uniform(-2e-8, 2e-8);
        cc.y[i] += vy[i] + r.uniform(-2e-8, 2e-8);
      }
    }
    // A particle moves at most 0.24 um per pass: two of them need at least 4 passes to add up
    // to 0.98 of the 2 um skin, so at most 15 builds; the list is reused most of the time but
    // not always.
    std::printf("threads=%d: %d list builds in 60 passes\n", threads, kept.builds());
    EXPECT_GE(kept.builds(), 5);
    EXPECT_LE(kept.builds(), 15);
  }
}

TEST(DipolePass, ChangedParticleSetRebuildsAndThreadCountsAgree) {
  // Removing particles (same_set = false) must not reuse the old list; the forces of 1 and 2
  // threads differ only by summation order (1e-12 relative, round-off).
  Cloud c = dense_cloud(250e-6, 7);
  dipole::PairSum one({42e-6, 2e-6, 1}), two({42e-6, 2e-6, 2});
  std::vector<double> fx, fy, gx, gy, rx, ry;
  one.compute(c.x, c.y, c.m, true, fx, fy);
  two.compute(c.x, c.y, c.m, true, gx, gy);
  EXPECT_LT(max_rel_diff(gx, gy, fx, fy), 1e-12);
  for (int k = 0; k < 40; ++k) {  // drop every 17th particle
    const std::size_t i = static_cast<std::size_t>(k) * 17 % c.x.size();
    c.x.erase(c.x.begin() + static_cast<long>(i));
    c.y.erase(c.y.begin() + static_cast<long>(i));
    c.m.erase(c.m.begin() + static_cast<long>(i));
  }
  one.compute(c.x, c.y, c.m, false, fx, fy);
  EXPECT_EQ(one.builds(), 2);
  dipole::brute_force_pair_sum(c.x, c.y, c.m, 42e-6, rx, ry);
  EXPECT_LT(max_rel_diff(fx, fy, rx, ry), 1e-12);
}

TEST(DipolePass, MagnetForceEqualsBruteForceAndResumesBitwise) {
  // Through the nip's provider: toner in the knife field above the roller, held forces
  // re-evaluated every 2 calls, bodies moving. (a) the dipole part equals the O(N^2) cut-off
  // sum of the provider's own moments to 1e-12 (round-off); (b) a provider restored from a
  // checkpoint taken mid-run (its pair list is not saved) continues bitwise identically.
  using namespace nipdem::nip;
  const Cloud c = dense_cloud(300e-6, 9);
  BodyStore b;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    b.x.push_back(c.x[i] - 150e-6);
    b.y.push_back(c.y[i] + 10e-6);
    b.size.push_back(10.5e-6);
    b.id.push_back(static_cast<std::int64_t>(i));
  }
  const std::size_t n = b.x.size();
  MagnetConfig cfg;
  cfg.field_interval = 2;
  cfg.dipole_interval = 2;
  cfg.threads = 2;
  auto field = make_magnet_field(cfg);
  MagnetForce a(field, cfg), resumed(field, cfg);
  DiscStore d;
  std::vector<double> fx(n), fy(n), tq(n), gx(n), gy(n);
  Rng r(3);
  for (int call = 0; call < 24; ++call) {
    std::fill(fx.begin(), fx.end(), 0.0);
    std::fill(fy.begin(), fy.end(), 0.0);
    a.add(b, d, 0.0, fx, fy, tq);
    if (call == 9) {
      std::stringstream s;
      a.save(s);
      resumed.load(s);
    }
    if (call > 9) {
      std::fill(gx.begin(), gx.end(), 0.0);
      std::fill(gy.begin(), gy.end(), 0.0);
      resumed.add(b, d, 0.0, gx, gy, tq);
      ASSERT_EQ(fx, gx) << "call " << call;
      ASSERT_EQ(fy, gy) << "call " << call;
    }
    if (call == 20) {
      std::vector<double> rx, ry;
      dipole::brute_force_pair_sum(b.x, b.y, a.moments(), cfg.dipole_cutoff, rx, ry);
      EXPECT_LT(max_rel_diff(a.dipole_fx(), a.dipole_fy(), rx, ry), 1e-12);
    }
    for (std::size_t i = 0; i < n; ++i) { b.x[i] += r.uniform(-0.3e-6, 0.3e-6); b.y[i] += r.uniform(-0.3e-6, 0.3e-6); }
  }
}

// The engine may run a provider's parts on fewer threads than it splits them into (its
// measured choice on a contended machine, engine/team_tuner.hpp): PairSum with 3 parts gives
// bitwise the same forces on 1, 2 or 3 running threads.
TEST(DipolePass, FewerRunningThreadsGiveTheSameSums) {
  const Cloud c = dense_cloud(330e-6, 3);
  dipole::PairSum ps({42e-6, 2e-6, 3});
  std::vector<double> fx3, fy3;
  ps.compute(c.x, c.y, c.m, false, fx3, fy3, 3);
  for (int run : {1, 2, 0}) {
    std::vector<double> fx, fy;
    ps.compute(c.x, c.y, c.m, true, fx, fy, run);
    EXPECT_EQ(fx, fx3) << "running threads " << run;
    EXPECT_EQ(fy, fy3) << "running threads " << run;
  }
}

// The list itself is built on the running threads (rows in parts, joined in row order): three
// PairSums of 3 parts whose first pass (the build) ran on 1, 2 and 3 threads hold the same list,
// so their sums are bitwise alike.
TEST(DipolePass, TheListIsTheSameBuiltOnAnyNumberOfThreads) {
  const Cloud c = dense_cloud(330e-6, 3);
  std::vector<double> fx1, fy1;
  dipole::PairSum one({42e-6, 2e-6, 3});
  one.compute(c.x, c.y, c.m, false, fx1, fy1, 1);
  for (int run : {2, 3}) {
    dipole::PairSum ps({42e-6, 2e-6, 3});
    std::vector<double> fx, fy;
    ps.compute(c.x, c.y, c.m, false, fx, fy, run);
    EXPECT_EQ(ps.listed_pairs(), one.listed_pairs());
    EXPECT_EQ(fx, fx1) << "built on " << run << " threads";
    EXPECT_EQ(fy, fy1) << "built on " << run << " threads";
  }
}

// The list build's row order (dipole::sort_row): ascending, as std::sort gives it, for rows
// whose partners all lie within +-2048 of the row (the bit set, including both edges of that
// span) and rows with one beyond (sorted), empty and one-partner rows; the bit set is left clear.
TEST(DipolePass, RowsAreSortedWhereverTheirPartnersLie) {
  Rng r(99);
  dipole::RowSortBits bits{};
  for (int trial = 0; trial < 3000; ++trial) {
    const int row = static_cast<int>(r.uniform(3000.0, 20000.0));  // (room for partners 2100 below)
    const int m = trial % 7 == 0 ? trial % 2 : static_cast<int>(r.uniform(2.0, 90.0));
    const double spread = trial % 3 == 0 ? 2100.0 : (trial % 3 == 1 ? 2048.0 : 300.0);
    std::vector<int> c;
    while (static_cast<int>(c.size()) < m) {
      int j = row + static_cast<int>(std::floor(r.uniform(-spread, spread)));
      if (trial % 5 == 0) j = c.size() % 2 ? row - 2048 + static_cast<int>(c.size()) : row + 2047 - static_cast<int>(c.size());
      if (j < 0 || j == row || std::find(c.begin(), c.end(), j) != c.end()) continue;
      c.push_back(j);
    }
    std::vector<int> want = c;
    std::sort(want.begin(), want.end());
    dipole::sort_row(c.data(), m, row, bits);
    ASSERT_EQ(c, want) << "trial " << trial;
    for (auto w : bits) ASSERT_EQ(w, 0u) << "trial " << trial;
  }
}
