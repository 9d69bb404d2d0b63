// No exception may cross an OpenMP region (the runtime would call std::terminate: SIGABRT with
// two threads). These tests replace the global operator new of this executable (hence a test
// program of its own) with one that fails, when armed, for every allocation made inside an active
// parallel region, and check that
//   - an allocation failing inside the neighbour list's parallel row search or the engine's wall
//     queries comes out of the call as std::bad_alloc (the engine carries it across the region);
//   - once warmed up, the engine's force evaluation and the dipole pair sum allocate nothing
//     inside their regions (their buffers are sized before);
//   - a non-finite or flung-away disc position is a clear error, not UB or a hang.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <omp.h>

#include "nipdem/core/rng.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/geometry/neighbor_list.hpp"
#include "nipdem/models/dipole.hpp"
#include "support/engine_fixtures.hpp"

namespace {
std::atomic<bool> g_fail_in_parallel{false};
std::atomic<long> g_failed{0};

bool must_fail() {
  if (!g_fail_in_parallel.load(std::memory_order_relaxed) || !omp_in_parallel()) return false;
  g_failed.fetch_add(1, std::memory_order_relaxed);
  return true;
}
void* allocate(std::size_t n, std::size_t align) {
  if (must_fail()) return nullptr;
  if (n == 0) n = 1;
  if (align <= alignof(std::max_align_t)) return std::malloc(n);
  void* p = nullptr;
  return posix_memalign(&p, align, n) == 0 ? p : nullptr;
}
void* allocate_or_throw(std::size_t n, std::size_t align) {
  void* p = allocate(n, align);
  if (!p) throw std::bad_alloc();
  return p;
}

// Arms the fault for one scope.
struct FailInParallel {
  FailInParallel() { g_failed = 0; g_fail_in_parallel = true; }
  ~FailInParallel() { g_fail_in_parallel = false; }
};
}  // namespace

void* operator new(std::size_t n) { return allocate_or_throw(n, 0); }
void* operator new[](std::size_t n) { return allocate_or_throw(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate_or_throw(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate_or_throw(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate(n, 0); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate(n, 0); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace {
using namespace nipdem;

using test::random_discs;

// The fault itself works: an allocation inside a region fails, one outside does not.
TEST(FaultAlloc, FailsOnlyInsideParallelRegions) {
  FailInParallel armed;
  std::vector<int> outside(1000, 1);
  EXPECT_EQ(outside.size(), 1000u);
  std::atomic<int> threw{0}, team{0};
#pragma omp parallel num_threads(2)
  {
    team = omp_get_num_threads();
    try {
      std::vector<int> inside(1000, 1);
    } catch (const std::bad_alloc&) {
      ++threw;
    }
  }
  ASSERT_EQ(team.load(), 2);  // the tests below need a real team of two
  EXPECT_EQ(threw.load(), 2);
}

TEST(FaultAlloc, NeighbourListRowsFailingInsideTheRegionComeOutAsBadAlloc) {
  const test::DiscCloud c = random_discs(5000, 500e-6, 3);  // >= 1024 discs per thread: the row search runs on 2 threads
  geometry::NeighborListParams p;
  p.threads = 2;
  geometry::NeighborList reference;
  reference.rebuild(c.x, c.y, c.r, c.body, {}, p);
  geometry::NeighborList list;  // fresh: its row buffers must grow inside the region
  {
    FailInParallel armed;
    EXPECT_THROW(list.rebuild(c.x, c.y, c.r, c.body, {}, p), std::bad_alloc);
    EXPECT_GT(g_failed.load(), 0);
  }
  EXPECT_EQ(list.size(), 0u);  // a failed build leaves the list as it was (empty)
  list.rebuild(c.x, c.y, c.r, c.body, {}, p);
  EXPECT_EQ(list.row_start_, reference.row_start_);
  EXPECT_EQ(list.nbr_, reference.nbr_);
}

engine::Simulation settled_pile(int threads, bool with_wall) {
  engine::EngineParams p;
  p.interactions = {engine::Interaction{}};
  p.dt = 1e-9;
  p.threads = threads;
  p.gravity = {0, -9.81};
  std::vector<geometry::Wall> walls;
  if (with_wall) walls.emplace_back();  // plane y = 0, normal +y
  engine::Simulation sim(p, walls);
  Rng rng(11);
  for (int i = 0; i < 600; ++i) {  // < 1024 discs: the list search is serial, the force passes parallel
    engine::BodySpec s;
    s.offsets = {{0, 0}};
    s.radii = {4e-6};
    s.density = 1500;
    s.position = {(i % 40) * 8.5e-6 + 5e-6, (i / 40) * 8.5e-6 + 3.99e-6 + rng.uniform(0, 1e-8)};
    sim.add_body(s);
  }
  return sim;
}

TEST(FaultAlloc, WallQueriesFailingInsideTheForceRegionComeOutAsBadAlloc) {
  auto sim = settled_pile(2, true);
  {
    FailInParallel armed;  // the per-thread wall hit lists are still empty: they grow in the region
    EXPECT_THROW(sim.compute_forces(), std::bad_alloc);
    EXPECT_GT(g_failed.load(), 0);
  }
  sim.compute_forces();  // works once memory is there again
  EXPECT_GT(sim.contacts(), 0);
}

TEST(FaultAlloc, WarmForceEvaluationAllocatesNothingInsideItsRegions) {
  for (bool wall : {false, true}) {
    auto sim = settled_pile(2, wall);
    for (int k = 0; k < 20; ++k) sim.step();  // buffers grown, list built
    const auto n_before = sim.neighbor_list().builds();
    FailInParallel armed;
    sim.compute_forces();
    sim.step();
    EXPECT_EQ(g_failed.load(), 0) << "wall " << wall;
    EXPECT_EQ(sim.neighbor_list().builds(), n_before);  // (a rebuild would be allowed to allocate)
  }
}

// Which thread queries a disc's walls is decided at run time (BlockSteal): a thread that never
// ran a wall block before must not grow its hit list inside the region (CI saw the test above fail
// once when, on a loaded machine, the second thread took the first thread's wall block). Here the
// warm-up runs on one thread, so only thread 0's list has grown; then both threads run a row of
// discs that all touch the wall, so both query walls in the armed step.
TEST(FaultAlloc, AThreadNewToWallQueriesAllocatesNothingInsideTheRegion) {
  engine::EngineParams p;
  p.interactions = {engine::Interaction{}};
  p.dt = 1e-9;
  p.threads = 2;
  p.run_threads = 1;
  p.gravity = {0, -9.81};
  engine::Simulation sim(p, {geometry::Wall{}});
  for (int i = 0; i < 600; ++i) {  // one row on the plane y = 0: every body block has wall contacts
    engine::BodySpec s;
    s.offsets = {{0, 0}};
    s.radii = {4e-6};
    s.density = 1500;
    s.position = {i * 8.5e-6 + 5e-6, 3.99e-6};
    sim.add_body(s);
  }
  for (int k = 0; k < 20; ++k) sim.step();
  ASSERT_EQ(sim.team_tuner().team(), 1);
  sim.mutable_params().run_threads = 2;
  const auto n_before = sim.neighbor_list().builds();
  FailInParallel armed;
  sim.step();
  sim.step();
  EXPECT_EQ(g_failed.load(), 0);
  EXPECT_EQ(sim.team_tuner().team(), 2);
  EXPECT_EQ(sim.neighbor_list().builds(), n_before);
}

// The dipole pair list is built on the running threads, its rows growing inside the region: a
// failed allocation there is carried out as std::bad_alloc (not std::terminate), and the next
// pass builds the list and gives the reference sums. The sum itself allocates nothing inside
// its region: a pass with the list built runs under the fault without a failure.
TEST(FaultAlloc, DipolePairSumCarriesAFailedBuildOutAndSumsWithoutAllocating) {
  const test::DiscCloud c = random_discs(3000, 400e-6, 5);
  std::vector<Vec2> m(c.x.size(), Vec2{1e-13, 2e-13});
  dipole::PairSum ps({42e-6, 2e-6, 2});
  std::vector<double> fx, fy, gx, gy;
  ps.compute(c.x, c.y, m, false, gx, gy);  // reference, and the list
  dipole::PairSum fresh({42e-6, 2e-6, 2});
  {
    FailInParallel armed;  // first call on a fresh object: the list build allocates in its region
    EXPECT_THROW(fresh.compute(c.x, c.y, m, false, fx, fy), std::bad_alloc);
    EXPECT_GT(g_failed.load(), 0);
  }
  fresh.compute(c.x, c.y, m, true, fx, fy);  // (same_set: the failed build is built again anyway)
  EXPECT_EQ(fx, gx);
  EXPECT_EQ(fy, gy);
  {
    FailInParallel armed;  // the list is built: nothing allocates inside the sum's region
    fresh.compute(c.x, c.y, m, true, fx, fy);
    EXPECT_EQ(g_failed.load(), 0);
  }
  EXPECT_EQ(fx, gx);
  EXPECT_EQ(fy, gy);
}

// A NaN, an infinite or a flung-away position is refused by the list (which disc, where), and
// by the engine at the next step as a runtime error naming the body and the time; a far but
// binnable disc is fine.
TEST(NeighbourListGuard, NonFiniteOrFlungAwayPositionsAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int threads : {1, 2}) {
    for (double bad : {nan, inf, -inf, 1e300, 1e30}) {
      for (int which : {0, 1700}) {  // the first disc (the bounding box starts from it) or another
        test::DiscCloud c = random_discs(3000, 500e-6, 9);
        geometry::NeighborListParams p;
        p.threads = threads;
        geometry::NeighborList list;
        list.rebuild(c.x, c.y, c.r, c.body, {}, p);
        const auto pairs = list.nbr_;
        (which == 0 ? c.y : c.x)[which] = bad;
        try {
          list.rebuild(c.x, c.y, c.r, c.body, {}, p);
          ADD_FAILURE() << "accepted " << bad << " at disc " << which;
        } catch (const geometry::BadPositionError& e) {
          EXPECT_EQ(e.disc(), static_cast<std::size_t>(which)) << e.what();
          EXPECT_NE(std::string(e.what()).find("disc " + std::to_string(which)), std::string::npos) << e.what();
        }
        EXPECT_EQ(list.nbr_, pairs);  // unchanged
        EXPECT_EQ(list.builds(), 1);
      }
    }
    test::DiscCloud c = random_discs(3000, 500e-6, 9);
    c.x[5] = 1e3;  // 1 km away: 1e8 cells, binnable (the cell count is capped)
    geometry::NeighborListParams p;
    p.threads = threads;
    geometry::NeighborList list;
    EXPECT_NO_THROW(list.rebuild(c.x, c.y, c.r, c.body, {}, p));
    EXPECT_EQ(list.row_start_[6], list.row_start_[5]);  // it has no neighbours
  }
}

TEST(NeighbourListGuard, EngineStopsWithTheBodyAndTimeNamed) {
  for (int threads : {1, 2}) {
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), 1e300}) {
      auto sim = settled_pile(threads, true);
      for (int k = 0; k < 5; ++k) sim.step();
      sim.bodies().vx[7] = bad;  // as a blown-up force would leave it
      const auto id = sim.bodies().id[7];
      try {
        for (int k = 0; k < 5; ++k) sim.step();
        ADD_FAILURE() << "ran on with vx = " << bad;
      } catch (const std::runtime_error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("body id " + std::to_string(id)), std::string::npos) << m;
        EXPECT_NE(m.find("step 6"), std::string::npos) << m;
        EXPECT_NE(m.find(bad != bad ? "not finite" : "cannot be binned"), std::string::npos) << m;
      }
    }
  }
}
}  // namespace
