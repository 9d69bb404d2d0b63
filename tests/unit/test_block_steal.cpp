// BlockSteal (engine/block_steal.hpp): every block is handed out exactly once, whatever the
// number of threads that ask and however unevenly they work; one thread gets them in order.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <vector>

#include "nipdem/engine/block_steal.hpp"

using nipdem::engine::BlockSteal;

TEST(BlockSteal, OneThreadTakesEveryBlockInOrder) {
  BlockSteal s;
  for (int n : {0, 1, 7, 100}) {
    s.reset(n, 1);
    std::vector<int> got;
    for (int q = s.next(0); q >= 0; q = s.next(0)) got.push_back(q);
    ASSERT_EQ(static_cast<int>(got.size()), n);
    for (int q = 0; q < n; ++q) { EXPECT_EQ(got[q], q); }
  }
}

TEST(BlockSteal, AThreadThatNeverAsksLeavesItsRangeToTheOthers) {
  // Ranges of 3 threads; only thread 0 asks: its own range front to back, then thread 1's and
  // thread 2's ranges from their backs.
  BlockSteal s;
  s.reset(9, 3);
  std::vector<int> got;
  for (int q = s.next(0); q >= 0; q = s.next(0)) got.push_back(q);
  EXPECT_EQ(got, (std::vector<int>{0, 1, 2, 5, 4, 3, 8, 7, 6}));
}

TEST(BlockSteal, EveryBlockOnceUnderContention) {
  // Threads asking at once, one of them slowed down: each block must be taken exactly once,
  // and the slow thread's range must partly go to the others (it was stolen from).
  const int T = 4, n = 20000;
  BlockSteal s;
  for (int round = 0; round < 20; ++round) {
    s.reset(n, T);
    std::vector<std::atomic<int>> taken(n);
    std::vector<int> by(n, -1);
#pragma omp parallel num_threads(T)
    {
      const int t = omp_get_thread_num();
      volatile double sink = 0.0;
      for (int q = s.next(t); q >= 0; q = s.next(t)) {
        taken[q].fetch_add(1, std::memory_order_relaxed);
        by[q] = t;
        if (t == 0)
          for (int k = 0; k < 2000; ++k) sink = sink + k;  // thread 0 works slowly
      }
    }
    for (int q = 0; q < n; ++q) { ASSERT_EQ(taken[q].load(), 1) << "block " << q << " round " << round; }
    if (omp_get_max_threads() >= 2) {
      int stolen = 0;  // blocks of thread 0's range (the first quarter) run by another thread
      for (int q = 0; q < n / T; ++q) stolen += by[q] != 0 && by[q] != -1;
      EXPECT_GT(stolen, 0) << "round " << round;
    }
  }
}
