// The engine's speed-ups must not change the physics: body orientation advanced by rotations
// instead of per-step sin/cos (rigid rotation against the analytic angle), the neighbour list
// searched by several threads (the same list as one thread), and the rebuild criterion on the
// two largest displacements (no interacting pair is ever missing from the list).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <array>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <nlohmann/json.hpp>

#include "../cli_run.hpp"
#include "support/engine_fixtures.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/geometry/neighbor_list.hpp"
#include "nipdem/models/collision_params.hpp"

using namespace nipdem;
using namespace nipdem::engine;

namespace {
BodySpec rod(Vec2 pos, double angle, double omega) {
  BodySpec s;
  s.offsets = {{-3e-6, 0}, {0, 0}, {3e-6, 0}};
  s.radii = {2e-6, 2e-6, 2e-6};
  s.density = 1700;
  s.position = pos;
  s.angle = angle;
  s.omega = omega;
  return s;
}
}  // namespace

// A free cluster spinning at constant omega: after N steps its discs must sit where the
// analytic rotation by omega N dt puts them. Per step the rotation is exact to rounding
// (Taylor series through d^7 for |d| <= 1e-2, libm above) and renormalised, so the position
// error stays at the rounding level of the accumulated angle: 1e-12 of the offset after 2e5
// steps (random walk of ~1e-16 per step gives ~5e-14; the bound leaves a margin of 20).
TEST(EngineRotation, FreeSpinMatchesAnalyticAngleWithoutPerStepTrigonometry) {
  for (double omega : {3.7e4, -2.9e6, 9e6}) {  // |omega dt| = 3.7e-5, 2.9e-3 and 9e-3 (Taylor branch)
    EngineParams p;
    p.interactions = {Interaction{}};
    p.dt = 1e-9;
    Simulation sim(p, {});
    const double a0 = 0.4;
    sim.add_body(rod({1e-5, 2e-5}, a0, omega));
    const int n = 200000;
    for (int i = 0; i < n; ++i) sim.step();
    const double a = a0 + omega * n * p.dt;
    const auto& d = sim.discs();
    const Vec2 c{sim.bodies().x[0], sim.bodies().y[0]};
    const Vec2 want{c.x + 3e-6 * std::cos(a), c.y + 3e-6 * std::sin(a)};
    EXPECT_NEAR(d.x[2], want.x, 1e-12 * 3e-6) << "omega " << omega;
    EXPECT_NEAR(d.y[2], want.y, 1e-12 * 3e-6) << "omega " << omega;
    // theta itself is a running sum: each of the n additions rounds by <= ulp/2 of |theta|
    EXPECT_NEAR(sim.bodies().theta[0], a, n * 1.1e-16 * std::fabs(a));
    const double len = std::hypot(sim.bodies().cth[0], sim.bodies().sth[0]);
    EXPECT_NEAR(len, 1.0, 4e-16);
  }
  // A large step angle (|d| > 1e-2) takes the libm branch.
  EngineParams p;
  p.interactions = {Interaction{}};
  p.dt = 1e-6;
  Simulation sim(p, {});
  sim.add_body(rod({0, 0}, 0.0, 5e4));  // 0.05 rad per step
  for (int i = 0; i < 1000; ++i) sim.step();
  EXPECT_NEAR(sim.discs().x[2], 3e-6 * std::cos(50.0), 1e-13 * 3e-6);
  EXPECT_NEAR(sim.discs().y[2], 3e-6 * std::sin(50.0), 1e-13 * 3e-6);
}

namespace {
std::set<std::pair<int, int>> listed(const geometry::NeighborList& nl) {
  std::set<std::pair<int, int>> s;
  for (std::size_t i = 0; i < nl.size(); ++i)
    for (int k = nl.row_start_[i]; k < nl.row_start_[i + 1]; ++k) s.insert({static_cast<int>(i), nl.nbr_[k]});
  return s;
}
// Brute force over all pairs: the pairs (i < j) of discs of different bodies within
// r_i + r_j + extra + h_i + h_j of each other (skins per disc h), or r_i + r_j + extra + skin if h
// is empty; with the minimum image along x if the box is periodic with width L > 0.
std::set<std::pair<int, int>> pairs_within(const test::DiscCloud& d, double extra, double skin,
                                           const std::vector<double>& h, double L) {
  std::set<std::pair<int, int>> want;
  for (std::size_t i = 0; i < d.x.size(); ++i)
    for (std::size_t j = i + 1; j < d.x.size(); ++j) {
      if (d.body[i] == d.body[j]) continue;
      double dx = d.x[i] - d.x[j];
      if (L > 0.0) dx -= L * std::nearbyint(dx / L);
      const double dy = d.y[i] - d.y[j];
      const double rc = h.empty() ? d.r[i] + d.r[j] + extra + skin : d.r[i] + d.r[j] + extra + h[i] + h[j];
      if (dx * dx + dy * dy < rc * rc) want.insert({static_cast<int>(i), static_cast<int>(j)});
    }
  return want;
}
// The pairs of discs of different bodies within r_i + r_j + extra of each other that `have`
// lacks (brute force over all pairs): how many, and the first as "i,j".
struct Unlisted { int count = 0; std::string first; };
Unlisted unlisted_pairs(const test::DiscCloud& d, double extra, const std::set<std::pair<int, int>>& have) {
  Unlisted u;
  for (std::size_t i = 0; i < d.x.size(); ++i)
    for (std::size_t j = i + 1; j < d.x.size(); ++j) {
      if (d.body[i] == d.body[j]) continue;
      const double rc = d.r[i] + d.r[j] + extra;
      const double dx = d.x[i] - d.x[j], dy = d.y[i] - d.y[j];
      if (dx * dx + dy * dy < rc * rc && !have.count({static_cast<int>(i), static_cast<int>(j)})) {
        if (u.count++ == 0) u.first = std::to_string(i) + "," + std::to_string(j);
      }
    }
  return u;
}
}  // namespace

// The row search runs in parallel over contiguous row ranges and is concatenated in order:
// the list (rows, order, carried-over history) must be identical for 1, 2 and 3 threads,
// periodic or not.
TEST(NeighborList, ParallelBuildEqualsSerialBuild) {
  for (bool periodic : {false, true}) {
    const test::DiscCloud d = test::random_discs(6000, 600e-6, 5, 3);  // triples share a body: never listed
    geometry::NeighborListParams p;
    p.skin = 1e-6;
    p.extra_range = 0.3e-6;
    p.periodic_x = periodic;
    p.x_lo = 0;
    p.x_hi = 600e-6;
    std::vector<geometry::NeighborList> lists(3);
    for (int t = 0; t < 3; ++t) {
      p.threads = t + 1;
      lists[t].rebuild(d.x, d.y, d.r, d.body, {}, p);
      // history carried over through a second build: mark every pair, rebuild, compare
      for (std::size_t k = 0; k < lists[t].eta_.size(); ++k) lists[t].eta_[k] = static_cast<double>(k);
      lists[t].rebuild(d.x, d.y, d.r, d.body, {}, p);
    }
    ASSERT_GT(lists[0].pair_count(), 5000u);
    for (int t = 1; t < 3; ++t) {
      EXPECT_EQ(lists[t].row_start_, lists[0].row_start_);
      EXPECT_EQ(lists[t].nbr_, lists[0].nbr_);
      EXPECT_EQ(lists[t].eta_, lists[0].eta_);
    }
  }
}

// Random walks with a few fast discs: the list is rebuilt only when the two largest
// displacements since the build exceed the skin; at every step every pair within the
// interaction range (r_i + r_j + extra) must be in the list (brute force over all pairs).
TEST(NeighborList, TwoLargestDisplacementCriterionNeverMissesAPair) {
  test::DiscCloud d = test::random_discs(400, 150e-6, 9, 3);
  geometry::NeighborListParams p;
  p.skin = 1e-6;
  p.extra_range = 0.2e-6;
  geometry::NeighborList nl;
  nl.rebuild(d.x, d.y, d.r, d.body, {}, p);
  Rng rng(3);
  int rebuilds = 0;
  for (int step = 0; step < 600; ++step) {
    for (std::size_t i = 0; i < d.x.size(); ++i) {
      const double s = i < 4 ? 0.2e-6 : 0.01e-6;  // four fast discs
      d.x[i] += rng.uniform(-s, s);
      d.y[i] += rng.uniform(-s, s);
    }
    double d1 = 0, d2 = 0;
    for (std::size_t i = 0; i < d.x.size(); ++i) geometry::NeighborList::top2(nl.displacement2(i, d.x[i], d.y[i]), d1, d2);
    EXPECT_EQ(nl.exceeds(d1, d2), nl.needs_rebuild(d.x, d.y));
    if (nl.exceeds(d1, d2)) { nl.rebuild(d.x, d.y, d.r, d.body, {}, p); ++rebuilds; }
    const Unlisted u = unlisted_pairs(d, p.extra_range, listed(nl));
    ASSERT_EQ(u.count, 0) << "pair " << u.first << " step " << step;
  }
  EXPECT_GT(rebuilds, 3);  // the walk does trigger rebuilds
}

// Skins per disc (NeighborList::rebuild's half_skin): the list holds exactly the pairs within
// r_i + r_j + extra + h_i + h_j of each other (brute force over all pairs), also where a disc's
// skin reaches beyond the 3 x 3 cells around it (one in ten discs, up to 8 times the others'),
// periodic or not, and the same list for 1 and 3 threads. Random positions: no pair sits on
// the boundary to rounding.
TEST(NeighborList, SkinsPerDiscListExactlyThePairsWithinTheirReach) {
  for (bool periodic : {false, true}) {
    const test::DiscCloud d = test::random_discs(3000, 400e-6, 11, 3);
    geometry::NeighborListParams p;
    p.skin = 1e-6;
    p.extra_range = 0.3e-6;
    p.periodic_x = periodic;
    p.x_lo = 0;
    p.x_hi = 400e-6;
    Rng rng(4);
    std::vector<double> h(d.x.size(), 0.5e-6);
    for (auto& v : h)
      if (rng.uniform(0, 1) < 0.1) v = rng.uniform(0.5e-6, 4e-6);
    std::vector<geometry::NeighborList> lists(2);
    for (int t = 0; t < 2; ++t) {
      p.threads = 1 + 2 * t;
      lists[t].rebuild(d.x, d.y, d.r, d.body, {}, p, h);
    }
    EXPECT_EQ(lists[1].row_start_, lists[0].row_start_);
    EXPECT_EQ(lists[1].nbr_, lists[0].nbr_);
    EXPECT_GT(lists[0].wide_discs(), 100u);  // the wide search ran
    const std::set<std::pair<int, int>> want = pairs_within(d, p.extra_range, 0.0, h, periodic ? 400e-6 : 0.0);
    EXPECT_EQ(listed(lists[0]), want) << (periodic ? "periodic" : "open");
    // rows sorted, no repeats (the wide pairs merged into them)
    for (std::size_t i = 0; i < lists[0].size(); ++i)
      for (int k = lists[0].row_start_[i] + 1; k < lists[0].row_start_[i + 1]; ++k)
        ASSERT_LT(lists[0].nbr_[k - 1], lists[0].nbr_[k]);
  }
}

// The row search skips, cell by cell, the discs with an index below the row's (a cell holds its
// discs in index order). In the spatial order the engine keeps bodies in (strips along x, then y)
// most cells are skipped whole or cut inside; in random order few are. Either way the list is
// exactly the pairs within reach (brute force), with one skin for all or skins per disc,
// periodic or not. Random positions: no pair sits on the boundary to rounding.
TEST(NeighborList, RowsThatSkipLowerIndicesListExactlyThePairsWithinReach) {
  for (bool sorted : {false, true})
    for (bool periodic : {false, true})
      for (bool per_disc : {false, true}) {
        test::DiscCloud d = test::random_discs(2500, 300e-6, 17, 2);
        if (sorted) {  // bodies in strips of 24 um along x, then by y (as sort_bodies_spatially)
          std::vector<int> order(d.x.size() / 2);
          for (std::size_t b = 0; b < order.size(); ++b) order[b] = static_cast<int>(b);
          std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
            const double sa = std::floor(d.x[2 * a] / 24e-6), sb = std::floor(d.x[2 * b] / 24e-6);
            return sa != sb ? sa < sb : d.y[2 * a] < d.y[2 * b];
          });
          test::DiscCloud s;
          for (std::size_t b = 0; b < order.size(); ++b)
            for (int q = 0; q < 2; ++q) {
              const std::size_t k = 2 * static_cast<std::size_t>(order[b]) + q;
              s.x.push_back(d.x[k]); s.y.push_back(d.y[k]); s.r.push_back(d.r[k]);
              s.body.push_back(static_cast<int>(b));
            }
          d = s;
        }
        geometry::NeighborListParams p;
        p.skin = 1e-6;
        p.extra_range = 0.3e-6;
        p.periodic_x = periodic;
        p.x_lo = 0;
        p.x_hi = 300e-6;
        p.threads = 2;
        std::vector<double> h;
        if (per_disc) {
          Rng rng(6);
          h.assign(d.x.size(), 0.5e-6);
          for (auto& v : h) v = rng.uniform(0.2e-6, 1.5e-6);
        }
        geometry::NeighborList nl;
        nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h);
        const std::set<std::pair<int, int>> want = pairs_within(d, p.extra_range, p.skin, h, periodic ? 300e-6 : 0.0);
        ASSERT_GT(want.size(), 2000u);
        EXPECT_EQ(listed(nl), want) << (sorted ? "sorted " : "random ") << (periodic ? "periodic " : "open ")
                                    << (per_disc ? "skins per disc" : "one skin");
      }
}

// The criterion with skins per disc: rebuilt when a disc has moved farther than its own skin
// (track(), needs_rebuild()). Random walks where four discs move 20 times faster than the rest
// and have skins 4 times wider: at every step every pair within the interaction range is
// listed (brute force), and the list is rebuilt far less often than with one skin for all
// (where the four fast discs set the pace).
TEST(NeighborList, SkinsPerDiscCriterionNeverMissesAPair) {
  auto walk = [](bool per_disc) {
    test::DiscCloud d = test::random_discs(400, 150e-6, 9, 3);
    geometry::NeighborListParams p;
    p.skin = 1e-6;
    p.extra_range = 0.2e-6;
    std::vector<double> h;
    if (per_disc) {
      h.assign(d.x.size(), 0.5e-6);
      for (int i = 0; i < 4; ++i) h[i] = 2e-6;
    }
    geometry::NeighborList nl;
    nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h);
    Rng rng(3);
    int rebuilds = 0;
    for (int step = 0; step < 600; ++step) {
      for (std::size_t i = 0; i < d.x.size(); ++i) {
        const double s = i < 4 ? 0.2e-6 : 0.01e-6;
        d.x[i] += rng.uniform(-s, s);
        d.y[i] += rng.uniform(-s, s);
      }
      double d1 = 0, d2 = 0;
      for (std::size_t i = 0; i < d.x.size(); ++i) nl.track(i, d.x[i], d.y[i], d1, d2);
      EXPECT_EQ(nl.exceeds(d1, d2), nl.needs_rebuild(d.x, d.y));
      if (nl.exceeds(d1, d2)) { nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h); ++rebuilds; }
      EXPECT_EQ(nl.per_disc(), per_disc);
      const Unlisted u = unlisted_pairs(d, p.extra_range, listed(nl));
      EXPECT_EQ(u.count, 0) << "first pair " << u.first << " step " << step;
    }
    return rebuilds;
  };
  const int one = walk(false), own = walk(true);
  EXPECT_GT(own, 3);        // the walk does trigger rebuilds...
  EXPECT_LT(2 * own, one);  // ...less than half as many as with one skin
}

// A skin per disc that is negative, not finite or missing is a caller's error, refused before
// anything changes.
TEST(NeighborList, BadSkinsPerDiscAreRefused) {
  const test::DiscCloud d = test::random_discs(50, 100e-6, 2);
  geometry::NeighborListParams p;
  geometry::NeighborList nl;
  std::vector<double> h(d.x.size(), 0.5e-6);
  nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h);
  const auto before = nl.nbr_;
  for (double bad : {-1e-9, std::nan(""), 1.0 / 0.0}) {
    h[7] = bad;
    EXPECT_THROW(nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h), std::invalid_argument);
  }
  h.pop_back();
  EXPECT_THROW(nl.rebuild(d.x, d.y, d.r, d.body, {}, p, h), std::invalid_argument);
  EXPECT_EQ(nl.nbr_, before);
  EXPECT_EQ(nl.builds(), 1);
}

// Walls each disc may touch are listed at each neighbour-list build. A wall that changes shape
// between builds (an experiment moving a plane) must still be felt at once: the lists are
// rebuilt when any wall's shape differs from the one they were made for.
TEST(WallCandidates, AWallMovedBetweenListBuildsIsFeltAtOnce) {
  EngineParams p;
  Interaction ia;
  ia.contact.k = 56;
  p.interactions = {ia, ia};
  p.dt = 1e-9;
  p.skin = 1e-6;
  Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
  sim.add_body(test::disc_body(2e-6, 1700, {0, 10e-6}));  // 8 um above the floor: no candidate
  sim.step();
  EXPECT_EQ(sim.contacts(), 0);
  sim.walls()[0].point = {0, 9e-6};  // the floor moves up into the disc (1 um overlap)
  sim.compute_forces();
  EXPECT_EQ(sim.contacts(), 1);
  EXPECT_NEAR(sim.bodies().fy[0], 56 * 1e-6, 1e-3 * 56e-6);  // k * overlap, disc at rest
}

// The program chooses its OpenMP wait policy (core/wait_policy.hpp): with no policy in the
// environment a run records its short spin (GOMP_SPINCOUNT=10000); a user's own setting wins.
TEST(WaitPolicy, TheCliSetsAShortSpinUnlessTheUserChose) {
  const std::string out = "/tmp/nipdem_waits_" + std::to_string(::getpid());
  const std::string args = std::string(" run ") + NIPDEM_SOURCE_DIR + "/examples/nip_black_small.toml --set run.end_time_s=2e-6 --force --out ";
  auto waits = [&](const std::string& env, const std::string& dir) {
    const auto r = nipdem::test::run_cli_command("env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT " + env + " " + NIPDEM_CLI_PATH + args + dir, "waits");
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream f(dir + "/summary.json");
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string s = ss.str();
    const auto k = s.find("\"omp_waits\"");
    return k == std::string::npos ? std::string("(missing)") : s.substr(k, s.find('\n', k) - k);
  };
  const std::string own = waits("", out + "_a");
  EXPECT_NE(own.find("GOMP_SPINCOUNT=10000"), std::string::npos) << own;
  EXPECT_EQ(own.find("OMP_WAIT_POLICY"), std::string::npos) << own;
  EXPECT_NE(waits("OMP_WAIT_POLICY=active", out + "_b").find("OMP_WAIT_POLICY=active"), std::string::npos);
  EXPECT_NE(waits("GOMP_SPINCOUNT=0", out + "_c").find("GOMP_SPINCOUNT=0"), std::string::npos);
  std::filesystem::remove_all(out + "_a");
  std::filesystem::remove_all(out + "_b");
  std::filesystem::remove_all(out + "_c");
}

// summary.json counts the builds of the contact and dipole pair lists (what the skins trade
// against); the black example has dipole-dipole forces on, so both lists are built at least
// once, and at most once per step.
TEST(RunSummary, CountsThePairListBuilds) {
  const std::string out = "/tmp/nipdem_listbuilds_" + std::to_string(::getpid());
  const auto r = nipdem::test::run_cli_command(std::string(NIPDEM_CLI_PATH) + " run " + NIPDEM_SOURCE_DIR +
                                                   "/examples/nip_black_small.toml --set run.end_time_s=2e-6 --force --out " + out,
                                               "listbuilds");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream f(out + "/summary.json");
  const auto j = nlohmann::json::parse(f);
  const long steps = j.at("steps").get<long>();
  for (const char* k : {"neighbor_list_builds_this_session", "dipole_list_builds_this_session",
                        "pair_sublist_builds_this_session"}) {
    EXPECT_GE(j.at(k).get<long>(), 1) << k;
    EXPECT_LE(j.at(k).get<long>(), steps) << k;
  }
  std::filesystem::remove_all(out);
}

namespace {
// The engine of the thread and sublist tests: adhesive tri-disc contacts (k 40 N/m), dt 2 ns, skin 0.5 um
// and the given sublist margin (a fraction of the skin; 0 = every listed pair each step).
EngineParams sublist_params(double fraction) {
  EngineParams p;
  Interaction ia;
  ia.contact = models::contact_params(40.0, 0.5, 1e-12, 0.5, 0.3);
  ia.adhesion.hamaker_J = 1e-19;
  ia.adhesion.min_separation_m = 4e-10;
  ia.adhesion.cutoff_m = 5e-8;
  p.interactions = {ia, ia};
  p.dt = 2e-9;
  p.skin = 5e-7;
  p.inner_skin_fraction = fraction;
  return p;
}
// Periodic box with a floor: tri-disc clusters with adhesion and the default sublist, under a
// strong gravity (shared by the thread-count and kick tests).
EngineParams floor_box_params(double width, int threads, int run_threads) {
  EngineParams p = sublist_params(EngineParams{}.inner_skin_fraction);
  p.gravity = {0, -1e4};
  p.periodic_x = true;
  p.x_lo = 0;
  p.x_hi = width;
  p.threads = threads;
  p.run_threads = run_threads;
  return p;
}

// An n x n grid of such clusters, 14 um apart, random orientation, spin and downward velocity
// (they collide and pile onto the floor).
void add_cluster_grid(Simulation& sim, int n, std::uint64_t seed) {
  Rng rng(seed);
  for (int row = 0; row < n; ++row)
    for (int col = 0; col < n; ++col) {
      BodySpec s;
      s.offsets = {{-3e-6, 0}, {3e-6, 0}, {0, 4e-6}};
      s.radii = {3e-6, 3e-6, 2.5e-6};
      s.density = 1700;
      s.position = {14e-6 * col + 7e-6, 8e-6 + 14e-6 * row};
      s.angle = rng.uniform(0, 6.28);
      s.velocity = {rng.uniform(-1, 1), rng.uniform(-4, -1)};
      s.omega = rng.uniform(-1e5, 1e5);
      sim.add_body(s);
    }
}
// A rough roller (15 um pyramids, radius 0.5 mm) turning at 600 rad/s, and a plane floor at its side.
std::vector<geometry::Wall> roller_and_floor() {
  geometry::Wall roller;
  roller.kind = geometry::Wall::Kind::cylinder;
  roller.name = "roller";
  roller.radius = 0.5e-3;
  roller.centre = {0, -0.5e-3};
  roller.omega = 600.0;
  roller.interaction = 1;
  geometry::set_pyramid_roughness(roller, 15e-6, 50e-6, 20e-6);
  return {roller, test::plane_wall({0, -60e-6}, {0, 1}, 1, "floor")};
}

// 6 rows of 10 tri-disc clusters above the roller, random orientation and spin; vy(rng, row)
// gives each its downward velocity (drawn after its vx, as the tests' streams expect).
template <class Vy> void rain_clusters(Simulation& sim, Vy vy) {
  Rng rng(9);
  for (int row = 0; row < 6; ++row)
    for (int col = 0; col < 10; ++col) {
      BodySpec s;
      s.offsets = {{-3e-6, 0}, {3e-6, 0}, {0, 4e-6}};
      s.radii = {3e-6, 3e-6, 2.5e-6};
      s.density = 1700;
      s.position = {14e-6 * col - 70e-6, 6e-6 + 14e-6 * row};
      s.angle = rng.uniform(0, 6.28);
      const double vx = rng.uniform(-0.5, 0.5);
      s.velocity = {vx, vy(rng, row)};
      s.omega = rng.uniform(-1e5, 1e5);
      sim.add_body(s);
    }
}
}  // namespace

// How many threads run the engine's loops (EngineParams::run_threads; engine/team_tuner.hpp)
// changes speed, never a result: the work is split into `threads` parts summed in one order.
// Tri-disc clusters with adhesion collide in a periodic box and pile onto a floor; with
// threads = 3 the run on 1, 2 and 3 running threads and the measured choice (which probes 1 and
// 3 after the warm-up and may switch) end bitwise alike.
TEST(TeamTuner, ResultsDoNotDependOnHowManyThreadsRun) {
  auto run = [](int run_threads) {
    Simulation sim(floor_box_params(200e-6, 3, run_threads), {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    add_cluster_grid(sim, 14, 11);
    for (int k = 0; k < 2000; ++k) sim.step();
    EXPECT_GT(sim.contacts(), 10);  // the run exercises contacts (21 open at the end; walls, adhesion)
    return std::pair{sim.bodies().x, sim.bodies().y};
  };
  const auto one = run(1), two = run(2), all = run(3), measured = run(0);
  ASSERT_EQ(one.first.size(), 196u);
  EXPECT_TRUE(one == two);
  EXPECT_TRUE(one == all);
  EXPECT_TRUE(one == measured);
}

// Each part of the pair rows writes its own discs, and its listed partners beyond its rows
// (across a periodic seam at the far end of the disc order) through cross slots read in the
// per-body phase by the block of the disc they act on. Disc 0 (x = 2.8 um) and the last disc (x =
// 197.1 um) touch across the seam of a 200 um box; 72 pairs of touching discs in between (rows
// above) give the second part rows of its own, so the last disc lies in it, two blocks of 64
// discs past the first part's own rows, while its only force comes from the first part's row
// of disc 0. With one contact per disc every force is 0 + one value, so
// 1 and 2 parts give the same bits; a part's write left out of the reduction would leave the
// last disc at rest (or give it a stale force later).
TEST(PartBuffers, APartnerAcrossThePeriodicSeamIsSummed) {
  auto run = [](int threads) {
    EngineParams p = sublist_params(EngineParams{}.inner_skin_fraction);
    p.periodic_x = true;
    p.x_lo = 0;
    p.x_hi = 200e-6;
    p.threads = threads;
    p.run_threads = threads;
    Simulation sim(p, {});
    auto disc = [&](double x, double y) {
      BodySpec s;
      s.offsets = {{0, 0}};
      s.radii = {3e-6};
      s.density = 1700;
      s.position = {x, y};
      sim.add_body(s);
    };
    disc(2.8e-6, 50e-6);
    for (int row = 0; row < 6; ++row)
      for (int k = 0; k < 12; ++k) {
        disc(15e-6 + 14e-6 * k, 70e-6 + 14e-6 * row);
        disc(15e-6 + 14e-6 * k + 5.9e-6, 70e-6 + 14e-6 * row);
      }
    disc(200e-6 - 2.9e-6, 50e-6);
    for (int k = 0; k < 10; ++k) sim.step();
    return std::pair{sim.bodies().vx, sim.bodies().x};
  };
  const auto one = run(1), two = run(2);
  ASSERT_EQ(one.first.size(), 146u);
  const double va = one.first.front(), vb = one.first.back();
  EXPECT_GT(va, 0.0);  // pushed apart across the seam: disc 0 to +x, the last disc to -x
  EXPECT_LT(vb, 0.0);
  EXPECT_NEAR(va, -vb, 1e-12 * va);  // equal masses: momentum is conserved pair by pair
  EXPECT_TRUE(one == two);
}

// A part's listed partners in later parts (cross entries) reach the per-body phase through slots
// of their own, numbered from the part's first entry and summed per part in part order. 196
// tri-disc clusters with adhesion in a periodic box pile up for 2,000 steps on one part, then
// run 40 steps more on 1, 2, 3 and 4 parts (as many running threads): the sums differ only in
// rounding, so the velocities agree to 1e-9 of the largest (a part's slots read at the wrong
// place, as a first version did for parts after the first, left 2x the kinetic energy after 100
// steps of the packing benchmark). Every split has cross entries, and the run has contacts.
// Run twice: with the bodies in the grid's order (a part's cross entries reach the next part
// only) and in an order shuffled the same way for every part count (discs reached by several
// earlier parts in one block, the per-body phase's general case).
TEST(PartBuffers, EveryPartCountSumsTheSameForces) {
  for (const bool shuffled : {false, true}) {
    std::vector<std::vector<double>> v;
    for (int parts = 1; parts <= 4; ++parts) {
      Simulation sim(floor_box_params(200e-6, 1, 1), {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
      add_cluster_grid(sim, 14, 11);
      for (int k = 0; k < 2000; ++k) sim.step();
      if (shuffled) {
        std::vector<int> order(sim.bodies().x.size());
        for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
        Rng rng(5);
        for (std::size_t k = order.size() - 1; k > 0; --k)
          std::swap(order[k], order[static_cast<std::size_t>(rng.uniform(0.0, static_cast<double>(k + 1))) % (k + 1)]);
        sim.permute_bodies(order);
      }
      sim.mutable_params().threads = parts;
      sim.mutable_params().run_threads = parts;
      for (int k = 0; k < 40; ++k) sim.step();
      EXPECT_GT(sim.contacts(), 10);
      if (parts > 1) {
        EXPECT_GT(sim.pair_cross_entries(), 0) << parts << " parts";
      }
      std::vector<double> w = sim.bodies().vx;
      w.insert(w.end(), sim.bodies().vy.begin(), sim.bodies().vy.end());
      v.push_back(std::move(w));
    }
    double vmax = 0.0;
    for (double x : v[0]) vmax = std::max(vmax, std::fabs(x));
    ASSERT_GT(vmax, 0.1);
    for (int parts = 2; parts <= 4; ++parts) {
      double worst = 0.0;
      for (std::size_t k = 0; k < v[0].size(); ++k) worst = std::max(worst, std::fabs(v[parts - 1][k] - v[0][k]));
      EXPECT_LT(worst, 1e-9 * vmax) << parts << " parts" << (shuffled ? ", shuffled" : "");
    }
  }
}

// The choice itself, on step times made up: the team whose median probe block is faster is
// kept, and the next probe can switch back when the load changes.
TEST(TeamTuner, KeepsTheFasterTeamAndProbesAgain) {
  TeamTuner t(2);
  ASSERT_TRUE(t.adaptive());
  EXPECT_EQ(t.team(), 2);
  auto run = [&](int steps, double t1, double t2) {  // step time with 1 and with 2 threads
    for (int k = 0; k < steps; ++k) t.step_done(t.team() == 1 ? t1 : t2);
  };
  run(TeamTuner::kWarmupSteps, 1.0, 0.9);
  // probe: 2 threads faster (a free core): kept
  run(TeamTuner::kBlockSteps * TeamTuner::kProbeBlocks, 1.0, 0.9);
  EXPECT_EQ(t.team(), 2);
  EXPECT_EQ(t.probes(), 1);
  // another job takes a core: 2 threads now slower than 1 (by less than the 1.5x that ends a
  // probe early, and than the 1.5x of the probe's time that the watch reacts to); the next
  // probe, after a doubled hold, switches to 1
  run(2 * TeamTuner::kHoldSteps + TeamTuner::kBlockSteps * TeamTuner::kProbeBlocks, 1.0, 1.3);
  EXPECT_EQ(t.early_probes(), 0);
  EXPECT_EQ(t.team(), 1);
  EXPECT_EQ(t.switches(), 1);
  EXPECT_EQ(t.probes(), 2);
  // a probe of 2 threads on the taken core that is far slower ends after its first pair of blocks
  run(TeamTuner::kHoldSteps + 2 * TeamTuner::kBlockSteps, 1.0, 3.0);
  EXPECT_EQ(t.team(), 1);
  EXPECT_EQ(t.probes(), 3);
  // the core is free again: back to 2 at the next probe (the hold doubled again)
  run(2 * TeamTuner::kHoldSteps + TeamTuner::kBlockSteps * TeamTuner::kProbeBlocks, 1.0, 0.6);
  EXPECT_EQ(t.team(), 2);
  EXPECT_EQ(t.switches(), 2);
  // one slow block (a list rebuild) does not move the median
  TeamTuner u(2);
  int step = 0;
  for (int k = 0; k < TeamTuner::kWarmupSteps + TeamTuner::kBlockSteps * TeamTuner::kProbeBlocks; ++k, ++step)
    u.step_done(u.team() == 1 ? 1.0 : (step == TeamTuner::kWarmupSteps + 5 ? 500.0 : 0.6));
  EXPECT_EQ(u.team(), 2);
  // fixed: no probing
  TeamTuner f(2, 1);
  EXPECT_FALSE(f.adaptive());
  EXPECT_EQ(f.team(), 1);
}

// While it holds two threads the tuner watches their step time: kSlowBlocks blocks in a row
// slower than kSlowFactor x the probe's median block start a probe at once (a wrong choice, or a
// core taken after the probe, ran 0.56x of one thread for a whole benchmark before). Blocks that
// are slow now and then do not, and one thread is not watched. Step times made up.
TEST(TeamTuner, TwoThreadsThatSlowDownWhileHeldAreProbedAtOnce) {
  constexpr int kProbe = TeamTuner::kBlockSteps * TeamTuner::kProbeBlocks;
  auto start = [&](TeamTuner& t, double t1, double t2) {  // warm-up and the first probe
    for (int k = 0; k < TeamTuner::kWarmupSteps + kProbe; ++k) t.step_done(t.team() == 1 ? t1 : t2);
  };
  TeamTuner t(2);
  start(t, 1.0, 0.8);  // a free core: 2 threads kept (a full probe: 0.8 is not 1.5x faster)
  ASSERT_EQ(t.team(), 2);
  ASSERT_EQ(t.probes(), 1);
  // a core is taken: 2 threads 2.5x slower than probed; after the watch's first kWatchAfterSteps
  // and kSlowBlocks slow blocks a probe starts, and it chooses 1 thread, thousands of steps
  // before the (doubled) hold would have ended
  const int react = TeamTuner::kWatchAfterSteps + TeamTuner::kSlowBlocks * TeamTuner::kBlockSteps;
  for (int k = 0; k < react + kProbe; ++k) t.step_done(t.team() == 1 ? 1.0 : 2.0);
  EXPECT_EQ(t.early_probes(), 1);
  EXPECT_EQ(t.probes(), 2);
  EXPECT_EQ(t.team(), 1);
  EXPECT_EQ(t.switches(), 1);
  EXPECT_LT(react + kProbe, 2 * TeamTuner::kHoldSteps);
  // one step short of kSlowBlocks slow blocks: no probe yet
  TeamTuner s(2);
  start(s, 1.0, 0.8);
  for (int k = 0; k < react - 1; ++k) s.step_done(s.team() == 1 ? 1.0 : 2.0);
  EXPECT_EQ(s.probes(), 1);
  EXPECT_EQ(s.team(), 2);
  // three slow blocks of every four (list rebuilds, a busy moment): never kSlowBlocks in a row
  TeamTuner u(2);
  start(u, 1.0, 0.8);
  for (int k = 0; k < 3000; ++k) u.step_done(u.team() == 1 ? 1.0 : ((k / TeamTuner::kBlockSteps) % 4 == 3 ? 0.8 : 2.0));
  EXPECT_EQ(u.early_probes(), 0);
  EXPECT_EQ(u.probes(), 1);
  EXPECT_EQ(u.team(), 2);
  // one thread held while it slows down (a taken core): not watched, no probe before the hold ends
  TeamTuner w(2);
  start(w, 1.0, 3.0);  // 2 threads on a taken core: 1 chosen
  ASSERT_EQ(w.team(), 1);
  for (int k = 0; k < 3000; ++k) w.step_done(w.team() == 1 ? 3.0 : 9.0);
  EXPECT_EQ(w.early_probes(), 0);
  EXPECT_EQ(w.probes(), 1);
}

// run_threads outside 0..threads is refused when the engine is made, naming the key.
TEST(TeamTuner, RunThreadsOutsideItsRangeIsRefused) {
  for (const int bad : {-1, 3}) {
    EngineParams p;
    p.interactions = {Interaction{}};
    p.threads = 2;
    p.run_threads = bad;
    try {
      Simulation sim(p, {});
      ADD_FAILURE() << "run_threads = " << bad << " was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("run_threads"), std::string::npos) << e.what();
    }
  }
}

// The pair kernel's per-step sublist (EngineParams::inner_skin_fraction) must not change a
// result: it holds every listed pair within range + margin when taken, and is taken again
// before two discs can have closed the margin, so the same pairs interact, in the same order.
// Fast tri-disc clusters with adhesion collide in a periodic box and pile onto a floor (the
// fastest discs move ~15 % of the margin 0.1 skin per step); bodies are removed and added on the
// way, one body is moved by hand, and forces are evaluated once outside step(). The
// state after 2000 steps is bitwise the same as when the kernel tests every listed pair, at 1
// and 3 threads, and the sublist was taken far fewer times than there were steps (it was used).
TEST(PairSublist, SameResultsAsTestingEveryListedPair) {
  auto run = [](double fraction, int threads, int* takes) {
    EngineParams p = sublist_params(fraction);
    p.gravity = {0, -1e4};
    p.periodic_x = true;
    p.x_lo = 0;
    p.x_hi = 200e-6;
    p.threads = threads;
    p.run_threads = threads;
    Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    Rng rng(5);
    auto add = [&](Vec2 pos) {
      BodySpec s;
      s.offsets = {{-3e-6, 0}, {3e-6, 0}, {0, 4e-6}};
      s.radii = {3e-6, 3e-6, 2.5e-6};
      s.density = 1700;
      s.position = pos;
      s.angle = rng.uniform(0, 6.28);
      s.velocity = {rng.uniform(-1, 1), rng.uniform(-4, -1)};
      s.omega = rng.uniform(-1e5, 1e5);
      sim.add_body(s);
    };
    for (int row = 0; row < 14; ++row)
      for (int col = 0; col < 14; ++col) add({14e-6 * col + 7e-6, 8e-6 + 14e-6 * row});
    for (int k = 0; k < 2000; ++k) {
      sim.step();
      if (k == 700) sim.remove_bodies_if([](int b) { return b % 17 == 3; });
      if (k == 900) add({100e-6, 230e-6});
      if (k == 1200) sim.bodies().x[5] += 2e-8;  // moved by hand: seen as a displacement
      if (k == 1500) sim.compute_forces();        // evaluated outside step(): every disc is checked
    }
    EXPECT_GT(sim.contacts(), 10);
    *takes = sim.pair_sublist_builds();
    const auto& b = sim.bodies();
    return std::vector<std::vector<double>>{b.x, b.y, b.vx, b.vy, b.omega};
  };
  int t_off = 0, t1 = 0, t3 = 0, t_wide = 0;
  const auto every = run(0.0, 1, &t_off);
  EXPECT_EQ(t_off, 0);
  EXPECT_TRUE(every == run(0.1, 1, &t1));
  EXPECT_TRUE(every == run(0.1, 3, &t3));
  EXPECT_TRUE(every == run(0.5, 3, &t_wide));
  EXPECT_GT(t1, 10);      // taken again and again as the discs move...
  EXPECT_LT(t1, 1000);    // ...but used on most steps
  EXPECT_EQ(t1, t3);
  EXPECT_LT(t_wide, t1);  // a wider margin is taken less often
}

// The sublist also narrows the wall candidates: while it is in use, a disc queries only the
// walls that were within reach + margin of it when it was taken. A rough roller turns under
// the discs, so the candidates are taken again before its surface has moved half the margin.
// Tri-disc clusters with adhesion rain onto a rough roller (15 um pyramids, radius 0.5 mm)
// turning at 600 rad/s (0.3 m/s at its surface, 1.2 % of the margin per step) and a plane
// floor at its side. After 6,000 steps the state is bitwise that of testing every candidate
// wall and listed pair at every step, at 1 and 2 threads, and the sublist was used.
TEST(PairSublist, SameResultsOnARotatingRoughRoller) {
  auto run = [](double fraction, int threads, int* takes) {
    EngineParams p = sublist_params(fraction);
    p.gravity = {0, -2e4};
    p.threads = threads;
    p.run_threads = threads;
    Simulation sim(p, roller_and_floor());
    rain_clusters(sim, [](Rng& rng, int) { return rng.uniform(-6, -3); });
    for (int k = 0; k < 6000; ++k) sim.step();
    EXPECT_GT(sim.contacts(), 10);
    *takes = sim.pair_sublist_builds();
    const auto& b = sim.bodies();
    return std::vector<std::vector<double>>{b.x, b.y, b.vx, b.vy, b.omega};
  };
  int t0 = 0, t1 = 0, t2 = 0;
  const auto every = run(0.0, 1, &t0);
  EXPECT_TRUE(every == run(0.1, 1, &t1));
  EXPECT_TRUE(every == run(0.1, 2, &t2));
  EXPECT_GT(t1, 10);
  EXPECT_LT(t1, 3000);
}

// Skins per disc (EngineParams::skin_speed_quantile) change when the list is rebuilt, never a
// result. Tri-disc clusters with adhesion rain at up to 6 m/s onto a turning rough roller and
// a floor (the roller test above): after 6,000 steps the state is bitwise that of one skin for
// all, at 1 and 2 threads and for two quantiles, and the list was rebuilt and the pair
// kernel's sublist (its margins per disc follow the skins) taken again less often.
TEST(SkinsPerDisc, SameResultsAsOneSkinForAll) {
  std::map<double, int> takes;
  auto run = [&takes](double quantile, int threads, int* builds) {
    EngineParams p = sublist_params(EngineParams{}.inner_skin_fraction);
    p.gravity = {0, -2e4};
    p.threads = threads;
    p.run_threads = threads;
    p.skin_speed_quantile = quantile;
    Simulation sim(p, roller_and_floor());
    rain_clusters(sim, [](Rng& rng, int row) { return row % 3 == 0 ? -6.0 : rng.uniform(-1, -0.5); });
    for (int k = 0; k < 6000; ++k) sim.step();
    EXPECT_GT(sim.contacts(), 10);
    *builds = sim.neighbor_list().builds();
    takes[quantile] = sim.pair_sublist_builds();
    const auto& b = sim.bodies();
    return std::vector<std::vector<double>>{b.x, b.y, b.vx, b.vy, b.omega};
  };
  int one = 0, own1 = 0, own2 = 0, own_half = 0;
  const auto same = run(0.0, 1, &one);
  EXPECT_TRUE(same == run(0.9, 1, &own1));
  EXPECT_TRUE(same == run(0.9, 2, &own2));
  EXPECT_TRUE(same == run(0.5, 2, &own_half));
  EXPECT_LT(own1, one);
  EXPECT_EQ(own1, own2);
  EXPECT_LT(takes[0.9], takes[0.0]);
  std::printf("list builds: one skin %d, own skins %d; sublist taken %d / %d times\n", one, own1, takes[0.0], takes[0.9]);
  EXPECT_THROW(run(1.0, 1, &one), InputError);  // the quantile is checked
}

// What the skins per disc and the sublist's margins promise together: at every step the
// contact list holds every pair of discs within interaction range (r_i + r_j + adhesion reach;
// brute force over all pairs), though step() checks the list only when the sublist is taken
// again (list_room_). Also the invariant behind it: no disc has moved farther than its own skin
// since the list was built (one skin: no two discs farther than the skin together). Fast
// tri-disc clusters (up to 4 m/s, 1.6 % of the skin per step) collide in a periodic box and
// pile onto a floor for 3000 steps, with skins per disc and one for all.
TEST(SkinsPerDisc, TheListAlwaysHoldsEveryPairInRange) {
  for (double quantile : {0.9, 0.0}) {
    EngineParams p = floor_box_params(200e-6, 1, 1);
    p.skin_speed_quantile = quantile;
    Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    add_cluster_grid(sim, 12, 5);
    const double reach = p.interactions[0].adhesion.cutoff_m;
    int missing = 0;
    for (int k = 0; k < 3000 && missing == 0; ++k) {
      sim.step();
      const auto& d = sim.discs();
      const auto& nl = sim.neighbor_list();
      const auto have = listed(nl);
      double d1 = 0, d2 = 0, worst = 0;
      for (std::size_t i = 0; i < d.x.size(); ++i) {
        const double m2 = nl.displacement2(i, d.x[i], d.y[i]);
        geometry::NeighborList::top2(m2, d1, d2);
        worst = std::max(worst, std::sqrt(m2) / nl.max_move(i));
      }
      EXPECT_EQ(nl.per_disc(), quantile > 0);
      if (nl.per_disc()) {
        EXPECT_LE(worst, 1.0) << "step " << k;
      } else {
        EXPECT_FALSE(nl.exceeds(d1, d2)) << "step " << k;
      }
      for (std::size_t i = 0; i < d.x.size(); ++i)
        for (std::size_t j = i + 1; j < d.x.size(); ++j) {
          if (d.body[i] == d.body[j]) continue;
          double dx = d.x[i] - d.x[j];
          dx -= 200e-6 * std::nearbyint(dx / 200e-6);
          const double dy = d.y[i] - d.y[j], rc = d.r[i] + d.r[j] + reach;
          if (dx * dx + dy * dy < rc * rc && !have.count({static_cast<int>(i), static_cast<int>(j)})) {
            ADD_FAILURE() << "quantile " << quantile << " step " << k << ": pair " << i << "," << j << " in range, not listed";
            ++missing;
          }
        }
    }
    EXPECT_GT(sim.neighbor_list().builds(), 5) << quantile;  // the discs do move through the skins
  }
}

// Blocks of bodies that are one disc at their centre are placed, packed and summed in loops of
// their own (step(), contact_forces(): "simple" blocks); the results must be those of the
// general per-body path. 600 adhesive discs of random size fall onto a floor and collide for
// 2000 steps, beside a tri-disc body far away that never touches them: first in the body
// order, it makes the first block of 256 bodies take the general path; last, every block of
// the discs is simple. The discs end bitwise alike (shifting every index by one keeps the
// order of every sum), at 1 and 2 threads.
TEST(SimpleBodies, SameBitsAsTheGeneralPath) {
  auto run = [](bool far_first, int threads) {
    EngineParams p = sublist_params(EngineParams{}.inner_skin_fraction);
    p.gravity = {0, -2e4};
    p.threads = threads;
    p.run_threads = threads;
    Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    BodySpec far;
    far.offsets = {{-3e-6, 0}, {3e-6, 0}, {0, 4e-6}};
    far.radii = {3e-6, 3e-6, 2.5e-6};
    far.density = 1700;
    far.position = {5e-3, 5e-3};
    far.omega = 1e4;
    if (far_first) sim.add_body(far);
    Rng rng(21);
    for (int k = 0; k < 600; ++k) {
      BodySpec s;
      s.offsets = {{0, 0}};
      s.radii = {rng.uniform(2e-6, 3.5e-6)};
      s.density = 1700;
      s.position = {8e-6 * (k % 30), 5e-6 + 8e-6 * (k / 30)};
      s.velocity = {rng.uniform(-1, 1), rng.uniform(-2, 0)};
      s.omega = rng.uniform(-1e5, 1e5);
      sim.add_body(s);
    }
    if (!far_first) sim.add_body(far);
    for (int k = 0; k < 2000; ++k) sim.step();
    EXPECT_GT(sim.contacts(), 100);
    const auto& b = sim.bodies();
    const std::size_t lo = far_first ? 1 : 0;
    std::vector<std::vector<double>> out;
    for (const auto* v : {&b.x, &b.y, &b.vx, &b.vy, &b.omega, &b.theta, &b.cth, &b.sth, &b.fx, &b.torque})
      out.emplace_back(v->begin() + lo, v->begin() + lo + 600);
    return out;
  };
  for (int threads : {1, 2}) EXPECT_TRUE(run(true, threads) == run(false, threads)) << threads << " threads";
}

// The same where only the roller moves: discs at rest hover 30 nm above the roller's lands
// (inside the adhesion reach there, 15 um out of it above a pit) while it turns at 10 m/s, so
// lands and pits pass under them and the adhesion pulls them only over a land. The discs
// alone (they move by nm) would never call for a new sublist; the roller's turning must (its
// surface moves 40 % of the margin per step). Bitwise the same as testing every candidate wall
// at every step; the test fails if the roller's turning is left out of the criterion.
TEST(PairSublist, ATurningRoughRollerRenewsTheWallCandidates) {
  auto run = [](double fraction, int* takes) {
    EngineParams p = sublist_params(fraction);
    geometry::Wall roller;
    roller.kind = geometry::Wall::Kind::cylinder;
    roller.name = "roller";
    roller.radius = 0.5e-3;
    roller.centre = {0, 0};
    roller.omega = 2e4;
    roller.interaction = 1;
    geometry::set_pyramid_roughness(roller, 15e-6, 50e-6, 20e-6);
    Simulation sim(p, {roller});
    const double r = 3e-6;
    for (int k = 0; k < 40; ++k) {  // 40 discs 7 um apart along the top of the roller
      const double phi = 1.2 + 7e-6 * k / roller.radius;
      const double rho = roller.radius + r + 3e-8;
      sim.add_body(test::disc_body(r, 1700, {rho * std::cos(phi), rho * std::sin(phi)}));
    }
    for (int k = 0; k < 1500; ++k) sim.step();
    *takes = sim.pair_sublist_builds();
    const auto& b = sim.bodies();
    return std::vector<std::vector<double>>{b.x, b.y, b.vx, b.vy, b.omega};
  };
  int t0 = 0, t1 = 0;
  const auto every = run(0.0, &t0);
  EXPECT_TRUE(every == run(0.1, &t1));
  double vmax = 0.0;
  for (double v : every[3]) vmax = std::max(vmax, std::fabs(v));
  EXPECT_GT(vmax, 1e-5);  // the lands' adhesion pulls the discs (3.1e-5 m/s by the end)
  EXPECT_GT(t1, 100);     // the roller's turning renews the candidates (751 times in 1,500 steps)
}

// Without force providers step() does the closing half kick inside the contact region, body by
// body as its force is summed; with one it runs a loop of its own after the provider. A provider
// that adds nothing takes the second path with the same forces, so both must give the same bits
// (positions and velocities after 1,500 steps of clusters piling onto a floor, 1 and 3 threads).
TEST(KickInContactRegion, SameBitsAsTheSeparateKickLoop) {
  struct NoForce : BodyForce {
    std::string name() const override { return "none"; }
    void add(const BodyStore&, const DiscStore&, double, std::span<double>, std::span<double>, std::span<double>) override {}
  };
  auto run = [](int threads, bool with_provider) {
    Simulation sim(floor_box_params(120e-6, threads, threads), {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
    if (with_provider) sim.add_force(std::make_shared<NoForce>());
    add_cluster_grid(sim, 8, 5);
    std::int64_t most = 0;
    for (int k = 0; k < 1500; ++k) {
      sim.step();
      most = std::max<std::int64_t>(most, sim.contacts());
    }
    EXPECT_GT(most, 10);  // the run exercises contacts (walls, adhesion), so the forces are not gravity alone
    const auto& b = sim.bodies();
    return std::vector<std::vector<double>>{b.x, b.y, b.vx, b.vy, b.omega};
  };
  for (int threads : {1, 3}) {
    SCOPED_TRACE(threads);
    const auto fused = run(threads, false), separate = run(threads, true);
    ASSERT_EQ(fused[0].size(), 64u);
    EXPECT_TRUE(fused == separate);
  }
}

namespace {
// The pile of add_cluster_grid after `steps` steps on a floor: contacts with stretched tangential
// springs, adhesion and wall history.
Simulation settled_pile(int steps, int threads = 1) {
  Simulation sim(floor_box_params(120e-6, threads, threads), {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
  add_cluster_grid(sim, 8, 5);
  for (int k = 0; k < steps; ++k) sim.step();
  return sim;
}
// Positions and velocities keyed by body id.
std::map<std::int64_t, std::array<double, 5>> by_id(const Simulation& sim) {
  std::map<std::int64_t, std::array<double, 5>> m;
  const auto& b = sim.bodies();
  for (std::size_t i = 0; i < b.x.size(); ++i) m[b.id[i]] = {b.x[i], b.y[i], b.vx[i], b.vy[i], b.omega[i]};
  return m;
}
}  // namespace

// Reordering the bodies (Simulation::permute_bodies) moves everything kept by index along:
// reversing the order of a settled pile (6,000 steps: 45 contacts, 35 stretched tangential
// springs; every listed pair then has its discs the other way round) keeps the elastic energy of
// the open contacts, which holds the springs' stretch (eq. 2.2.10), to rounding, and the last
// forces bitwise; 300 steps later every body is where the unpermuted run has it to 1e-13 m. The
// two runs may differ only in the order of the force sums (~1e-16 relative, grown by the pile's
// dynamics; measured: 0, no disc here has more than two terms to add). With the histories lost
// (mapping all -1, tried) the stretch count drops to 0 and the bodies differ by 2.3e-8 m.
TEST(BodyOrder, PermutingCarriesHistoriesAndForces) {
  Simulation a = settled_pile(6000), b = settled_pile(6000);
  const auto& nl = b.neighbor_list();
  const auto stretched = std::count_if(nl.eta_.begin(), nl.eta_.end(), [](double e) { return e != 0.0; });
  ASSERT_GT(stretched, 10);  // the pile holds tangential springs
  const Energy e0 = b.energy();
  const auto fx0 = b.bodies().fx;
  const auto ids0 = b.bodies().id;
  std::vector<int> reversed(b.bodies().x.size());
  for (std::size_t i = 0; i < reversed.size(); ++i) reversed[i] = static_cast<int>(reversed.size() - 1 - i);
  b.permute_bodies(reversed);
  EXPECT_EQ(b.bodies().id.front(), ids0.back());
  for (std::size_t i = 0; i < reversed.size(); ++i) EXPECT_EQ(b.bodies().fx[i], fx0[reversed[i]]);
  EXPECT_EQ(std::count_if(nl.eta_.begin(), nl.eta_.end(), [](double e) { return e != 0.0; }), stretched);
  const Energy e1 = b.energy();
  EXPECT_NEAR(e1.elastic, e0.elastic, 1e-12 * e0.elastic);
  ASSERT_GT(e0.elastic, 0.0);
  for (int k = 0; k < 300; ++k) { a.step(); b.step(); }
  const auto pa = by_id(a), pb = by_id(b);
  ASSERT_EQ(pa.size(), pb.size());
  double worst = 0.0;
  for (const auto& [id, s] : pa) worst = std::max({worst, std::fabs(s[0] - pb.at(id)[0]), std::fabs(s[1] - pb.at(id)[1])});
  EXPECT_LT(worst, 1e-13);
  EXPECT_GT(a.contacts(), 10);
}

// The spatial order: strips in x, by y within a strip. Sorting a sorted state changes nothing
// (the same bits after more steps as a run not sorted again), and a resumed run of a reordered
// state (ids no longer increasing) goes on bitwise.
TEST(BodyOrder, SortIsSpatialStableAndResumes) {
  const double strip = 20e-6;
  Simulation a = settled_pile(800);
  a.sort_bodies_spatially(strip);
  const auto& b = a.bodies();
  const double x0 = *std::min_element(b.x.begin(), b.x.end());
  bool increasing_ids = true;
  for (std::size_t i = 1; i < b.x.size(); ++i) {
    const double s0 = std::floor((b.x[i - 1] - x0) / strip), s1 = std::floor((b.x[i] - x0) / strip);
    ASSERT_TRUE(s0 < s1 || (s0 == s1 && b.y[i - 1] <= b.y[i])) << i;
    increasing_ids = increasing_ids && b.id[i] > b.id[i - 1];
  }
  EXPECT_FALSE(increasing_ids);  // the pile was reordered
  std::stringstream saved;
  a.save(saved);
  Simulation c(a.params(), a.walls());
  c.load(saved);
  Simulation d = settled_pile(0);
  std::stringstream again(saved.str());
  d.load(again);
  d.sort_bodies_spatially(strip);  // already in order: no change
  for (int k = 0; k < 400; ++k) { a.step(); c.step(); d.step(); }
  EXPECT_TRUE(by_id(a) == by_id(c));
  EXPECT_TRUE(by_id(a) == by_id(d));
}

TEST(BodyOrder, ABadPermutationIsRefusedAndChangesNothing) {
  Simulation a = settled_pile(10);
  const auto x = a.bodies().x;
  const std::size_t n = x.size();
  std::vector<int> short_order(n - 1, 0), repeated(n, 0), out_of_range(n);
  for (std::size_t i = 0; i < n; ++i) out_of_range[i] = static_cast<int>(i + 1);
  EXPECT_THROW(a.permute_bodies(short_order), std::invalid_argument);
  EXPECT_THROW(a.permute_bodies(repeated), std::invalid_argument);
  EXPECT_THROW(a.permute_bodies(out_of_range), std::invalid_argument);
  EXPECT_TRUE(a.bodies().x == x);
  EXPECT_THROW(a.sort_bodies_spatially(0.0), InputError);
  EXPECT_THROW(a.sort_bodies_spatially(std::nan("")), InputError);
}

// The sublist's margins per disc are made once per list build (not at each take of the
// sublist): at every take they are those of the list in use, g_i = inner_skin_fraction x h_i,
// across list builds whose skins per disc differ (clusters raining onto a floor at 1-4 m/s,
// skins from the speed quantile).
TEST(SublistMargins, AtEveryTakeTheyAreThoseOfTheListInUse) {
  EngineParams p = floor_box_params(140e-6, 1, 1);
  Simulation sim(p, {test::plane_wall({0, 0}, {0, 1}, 1, "floor")});
  add_cluster_grid(sim, 10, 17);
  int takes = sim.pair_sublist_builds(), checked = 0, builds_seen = 0, last_build = -1;
  std::vector<double> first_margins;
  bool margins_changed = false;
  for (int s = 0; s < 3000; ++s) {
    sim.step();
    if (sim.pair_sublist_builds() == takes) continue;
    takes = sim.pair_sublist_builds();
    const auto& nl = sim.neighbor_list();
    const auto& g = sim.pair_sublist_margins();
    if (!nl.per_disc()) continue;
    ASSERT_EQ(g.size(), nl.size());
    for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(g[i], p.inner_skin_fraction * nl.max_move(i)) << "disc " << i << " step " << s;
    ++checked;
    if (nl.builds() != last_build) { ++builds_seen; last_build = nl.builds(); }
    if (first_margins.empty()) first_margins = g;
    else margins_changed = margins_changed || g != first_margins;
  }
  // the test saw takes across several list builds with different skins
  EXPECT_GT(checked, 20);
  EXPECT_GT(builds_seen, 3);
  EXPECT_TRUE(margins_changed);
}
