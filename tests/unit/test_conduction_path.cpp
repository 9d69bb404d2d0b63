// Shortest conducting paths (thesis §2.5.5, fig. 2.26).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <set>
#include <utility>
#include <cmath>
#include <cstdio>

#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/solvers/conduction_path.hpp"

using namespace nipdem;
using namespace nipdem::conduction;

namespace {
// Reference: Bellman–Ford relaxation until nothing changes (independent of Dijkstra's order).
std::vector<double> bellman_ford(int n, const std::vector<Contact>& c, const std::vector<RollerContact>& r) {
  std::vector<double> d(n, INFINITY);
  for (const auto& x : r) d[x.i] = std::min(d[x.i], x.resistance_ohm);
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& e : c) {
      if (d[e.i] + e.resistance_ohm < d[e.j]) { d[e.j] = d[e.i] + e.resistance_ohm; changed = true; }
      if (d[e.j] + e.resistance_ohm < d[e.i]) { d[e.i] = d[e.j] + e.resistance_ohm; changed = true; }
    }
  }
  return d;
}

// Random "packing-like" graph: particles on a jittered W x H lattice, contacts between
// lattice neighbours (incl. one diagonal) with probability p, roller contacts on row 0.
void random_graph(Rng& rng, int W, int H, double p, std::vector<Contact>& c, std::vector<RollerContact>& r) {
  c.clear();
  r.clear();
  auto id = [W](int x, int y) { return y * W + x; };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W && rng.uniform() < p) c.push_back({id(x, y), id(x + 1, y), rng.uniform(0.5, 1.5)});
      if (y + 1 < H && rng.uniform() < p) c.push_back({id(x, y), id(x, y + 1), rng.uniform(0.5, 1.5)});
      if (x + 1 < W && y + 1 < H && rng.uniform() < 0.3 * p) c.push_back({id(x, y), id(x + 1, y + 1), rng.uniform(0.5, 1.5)});
      if (y == 0 && rng.uniform() < p) r.push_back({id(x, y), rng.uniform(0.5, 1.5)});
    }
}
}  // namespace

// A chain roller - 0 - 1 - ... - k: R_path(k) = k R_tt + R_ti exactly (sums of equal terms).
TEST(ConductionPath, ChainResistanceAndParents) {
  const int k = 12;
  const double Rtt = 3.7e10, Rti = 2e10;
  std::vector<Contact> c;
  for (int i = 0; i < k; ++i) c.push_back({i, i + 1, Rtt});
  ConductionPaths cp(k + 2);  // particle k+1 is isolated
  EXPECT_TRUE(cp.update(c, {{0, Rti}}));
  for (int i = 0; i <= k; ++i) {
    EXPECT_NEAR(cp.path_resistance(i), i * Rtt + Rti, 1e-6 * Rtt) << i;
    EXPECT_EQ(cp.hops(i), i);
  }
  EXPECT_EQ(cp.parent(0), kRoller);
  EXPECT_EQ(cp.path(k).size(), static_cast<std::size_t>(k + 1));
  EXPECT_FALSE(cp.connected(k + 1));
  EXPECT_TRUE(std::isinf(cp.path_resistance(k + 1)));
  // The same contacts again: no recomputation.
  EXPECT_FALSE(cp.update(c, {{0, Rti}}));
  EXPECT_EQ(cp.stats().unchanged, 1u);
  // Break the chain in the middle: everything beyond loses its path.
  c.erase(c.begin() + 5);
  EXPECT_TRUE(cp.update(c, {{0, Rti}}));
  EXPECT_TRUE(cp.connected(5));
  EXPECT_FALSE(cp.connected(6));
  EXPECT_FALSE(cp.connected(k));
  // A shortcut (a second roller contact at the far end) is used when shorter.
  EXPECT_TRUE(cp.update(c, {{0, Rti}, {k, Rti}}));
  EXPECT_NEAR(cp.path_resistance(k - 1), Rtt + Rti, 1e-6 * Rtt);
}

// Dijkstra equals Bellman–Ford on random graphs (exact up to summation order: 1e-12 rel).
TEST(ConductionPath, MatchesBellmanFord) {
  Rng rng(7);
  for (int rep = 0; rep < 5; ++rep) {
    std::vector<Contact> c;
    std::vector<RollerContact> r;
    random_graph(rng, 30, 20, 0.6, c, r);
    std::vector<double> R;
    std::vector<int> par, hops;
    shortest_paths(600, c, r, R, par, hops);
    const auto ref = bellman_ford(600, c, r);
    for (int i = 0; i < 600; ++i) {
      if (std::isinf(ref[i])) EXPECT_TRUE(std::isinf(R[i]));
      else EXPECT_NEAR(R[i], ref[i], 1e-12 * ref[i]);
    }
  }
}

// The CSR entry point gives the same result as the edge-list one (it is what the latter calls,
// but the test also checks the size validation).
TEST(ConductionPath, CsrInput) {
  // roller - 0 - 1 - 2, and 0 - 2 directly with a large resistance
  const std::vector<int> off{0, 2, 4, 6};
  const std::vector<int> nb{1, 2, 0, 2, 1, 0};
  const std::vector<double> w{1.0, 5.0, 1.0, 1.0, 1.0, 5.0};
  std::vector<double> R;
  std::vector<int> par, hops;
  shortest_paths_csr(3, off, nb, w, {{0, 0.5}}, R, par, hops);
  EXPECT_DOUBLE_EQ(R[2], 2.5);
  EXPECT_EQ(par[2], 1);
  EXPECT_EQ(hops[2], 2);
  EXPECT_THROW(shortest_paths_csr(3, {0, 2, 4}, nb, w, {}, R, par, hops), InputError);
  EXPECT_THROW(shortest_paths_csr(3, off, nb, {1.0, 5.0, 1.0, 1.0, 1.0, -5.0}, {}, R, par, hops), InputError);
}

// Incremental updates (random insertions/removals of ~2 % of the contacts per step) must give
// the same path resistances as a full recompute after every step (1e-12 relative).
TEST(ConductionPath, IncrementalEqualsFull) {
  Rng rng(11);
  std::vector<Contact> c;
  std::vector<RollerContact> r;
  random_graph(rng, 40, 25, 0.7, c, r);
  const int n = 1000;
  ConductionPaths cp(n);
  cp.update(c, r);
  for (int step = 0; step < 200; ++step) {
    // remove a few
    for (int k = 0; k < 10 && !c.empty(); ++k) {
      const std::size_t idx = static_cast<std::size_t>(rng.uniform() * c.size());
      c[idx] = c.back();
      c.pop_back();
    }
    // add a few between nearby ids (no duplicate pairs: update() rejects them)
    std::set<std::pair<int, int>> have;
    for (const auto& e : c) have.insert({std::min(e.i, e.j), std::max(e.i, e.j)});
    for (int k = 0; k < 10; ++k) {
      const int a = static_cast<int>(rng.uniform() * n);
      const int b = std::clamp(a + (rng.uniform() < 0.5 ? 1 : 40), 0, n - 1);
      if (a != b && have.insert({a, b}).second) c.push_back({a, b, rng.uniform(0.5, 1.5)});
    }
    // change one resistance
    if (!c.empty()) c[static_cast<std::size_t>(rng.uniform() * c.size())].resistance_ohm *= 1.7;
    if (step % 17 == 0 && !r.empty()) r.pop_back();
    cp.update(c, r);
    std::vector<double> R;
    std::vector<int> par, hops;
    shortest_paths(n, c, r, R, par, hops);
    for (int i = 0; i < n; ++i) {
      if (std::isinf(R[i])) ASSERT_TRUE(std::isinf(cp.path_resistance(i))) << "step " << step << " i " << i;
      else ASSERT_NEAR(cp.path_resistance(i), R[i], 1e-12 * R[i]) << "step " << step << " i " << i;
      if (cp.connected(i)) {
        // The parent pointers give a path whose hop count is consistent.
        ASSERT_EQ(static_cast<int>(cp.path(i).size()), cp.hops(i) + 1);
      }
    }
  }
  std::printf("[ConductionPath] 200 edit steps: %llu incremental, %llu full recomputes, %llu particles re-seeded\n",
              static_cast<unsigned long long>(cp.stats().incremental), static_cast<unsigned long long>(cp.stats().full),
              static_cast<unsigned long long>(cp.stats().invalidated));
  EXPECT_THROW(cp.update({{0, 1, 1.0}, {1, 0, 2.0}}, r), InputError);  // duplicate pair
  // After the error the object is consistent again with the next valid update.
  cp.update(c, r);
  {
    std::vector<double> R;
    std::vector<int> par, hops;
    shortest_paths(n, c, r, R, par, hops);
    for (int i = 0; i < n; ++i) {
      if (!std::isinf(R[i])) {
        ASSERT_NEAR(cp.path_resistance(i), R[i], 1e-12 * R[i]);
      }
    }
  }
}

// Cost for 10^4 particles (~2.3e4 contacts): full Dijkstra, unchanged update, and an update
// with 1 % of the contacts changed. Printed for the report; the only assertion is a loose
// 50 ms bound on a full recompute so a pathological slowdown is caught.
TEST(ConductionPath, Cost10k) {
  Rng rng(3);
  std::vector<Contact> c;
  std::vector<RollerContact> r;
  random_graph(rng, 100, 100, 0.8, c, r);
  const int n = 10000;
  using clk = std::chrono::steady_clock;
  std::vector<double> R;
  std::vector<int> par, hops;
  auto t0 = clk::now();
  const int reps = 20;
  for (int k = 0; k < reps; ++k) shortest_paths(n, c, r, R, par, hops);
  const double t_full = std::chrono::duration<double>(clk::now() - t0).count() / reps;
  ConductionPaths cp(n);
  cp.update(c, r);
  t0 = clk::now();
  for (int k = 0; k < reps; ++k) cp.update(c, r);
  const double t_same = std::chrono::duration<double>(clk::now() - t0).count() / reps;
  double t_inc = 0;
  std::set<std::pair<int, int>> have;
  for (const auto& e : c) have.insert({std::min(e.i, e.j), std::max(e.i, e.j)});
  // One contact changes: a random one is removed, one between neighbours a, a + 1 added (if new).
  auto change_contact = [&] {
    const std::size_t idx = static_cast<std::size_t>(rng.uniform() * c.size());
    have.erase({std::min(c[idx].i, c[idx].j), std::max(c[idx].i, c[idx].j)});
    c[idx] = c.back();
    c.pop_back();
    const int a = static_cast<int>(rng.uniform() * (n - 1));
    if (have.insert({a, a + 1}).second) c.push_back({a, a + 1, rng.uniform(0.5, 1.5)});
  };
  for (int k = 0; k < reps; ++k) {
    for (int m = 0; m < static_cast<int>(c.size()) / 200; ++m) change_contact();  // 0.5 % removed, 0.5 % added
    t0 = clk::now();
    cp.update(c, r);
    t_inc += std::chrono::duration<double>(clk::now() - t0).count();
  }
  t_inc /= reps;
  // A typical DEM step changes only a few contacts: 5 removed + 5 added.
  double t_few = 0;
  const int reps_few = 200;
  for (int k = 0; k < reps_few; ++k) {
    for (int m = 0; m < 5; ++m) change_contact();
    t0 = clk::now();
    cp.update(c, r);
    t_few += std::chrono::duration<double>(clk::now() - t0).count();
  }
  std::printf("[ConductionPath] n=1e4: update with 10 contact changes %.3f ms\n", 1e3 * t_few / reps_few);
  std::vector<double> Rref;
  shortest_paths(n, c, r, Rref, par, hops);
  for (int i = 0; i < n; ++i)
    if (!std::isinf(Rref[i])) {
      ASSERT_NEAR(cp.path_resistance(i), Rref[i], 1e-12 * Rref[i]);
    }
  std::printf("[ConductionPath] n=1e4, %zu contacts: full Dijkstra %.3f ms, unchanged update %.3f ms, "
              "1%% changed update %.3f ms (%llu full, %llu incremental, %.0f re-seeded per update)\n",
              c.size(), 1e3 * t_full, 1e3 * t_same, 1e3 * t_inc, static_cast<unsigned long long>(cp.stats().full),
              static_cast<unsigned long long>(cp.stats().incremental), static_cast<double>(cp.stats().invalidated) / reps);
  EXPECT_LT(t_full, 0.05);
}

// Hop statistics for the per-contact calibration: a chain of 12 plus one isolated particle.
TEST(ConductionPath, HopStatistics) {
  std::vector<Contact> c;
  for (int i = 0; i < 12; ++i) c.push_back({i, i + 1, 1.0});
  ConductionPaths cp(14);
  cp.update(c, {{0, 1.0}});
  const auto h = hop_statistics(cp, {4, 12, 13});
  EXPECT_EQ(h.count, 3);
  EXPECT_DOUBLE_EQ(h.mean_hops, 8.0);  // (4 + 12) / 2
  EXPECT_DOUBLE_EQ(h.connected_fraction, 2.0 / 3.0);
  EXPECT_THROW(hop_statistics(cp, {14}), InputError);
}

TEST(ConductionPath, BadInput) {
  ConductionPaths cp(3);
  EXPECT_THROW(cp.update({{0, 3, 1.0}}, {}), InputError);
  EXPECT_THROW(cp.update({{1, 1, 1.0}}, {}), InputError);
  EXPECT_THROW(cp.update({{0, 1, -1.0}}, {}), InputError);
  EXPECT_THROW(cp.update({{0, 1, 1.0}}, {{5, 1.0}}), InputError);
  EXPECT_THROW(cp.update({{0, 1, 1.0}}, {{0, 0.0}}), InputError);
}
