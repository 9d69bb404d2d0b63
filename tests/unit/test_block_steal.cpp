// BlockSteal (engine/block_steal.hpp): every block is handed out exactly once, whatever the
// number of threads that ask and however unevenly they work; one thread gets them in order.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <thread>
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
  // Threads asking at once: each block must be taken exactly once. Thread 0 takes one block of
  // its own and then waits until the others have run out of blocks, so the rest of its range
  // must have been stolen by them (a property of the hand-out, not of the timing).
  const int T = 4, n = 20000;
  BlockSteal s;
  for (int round = 0; round < 20; ++round) {
    s.reset(n, T);
    std::vector<std::atomic<int>> taken(n);
    std::vector<int> by(n, -1);
    std::atomic<int> done{0};
    int team = 0;
#pragma omp parallel num_threads(T)
    {
      const int t = omp_get_thread_num();
#pragma omp single
      team = omp_get_num_threads();
      int q = s.next(t);
      if (t == 0 && q >= 0) {
        taken[q].fetch_add(1, std::memory_order_relaxed);
        by[q] = t;
        while (done.load() < team - 1) std::this_thread::yield();  // the others take the rest
        q = s.next(t);
      }
      for (; q >= 0; q = s.next(t)) {
        taken[q].fetch_add(1, std::memory_order_relaxed);
        by[q] = t;
      }
      if (t != 0) done.fetch_add(1);
    }
    for (int q = 0; q < n; ++q) { ASSERT_EQ(taken[q].load(), 1) << "block " << q << " round " << round; }
    if (team == T) {  // thread 0 ran at most the front block of its range (the others may have
                      // stolen even that one before it first asked)
      for (int q = 1; q < n / T; ++q) { ASSERT_NE(by[q], 0) << "block " << q << " of thread 0's range, round " << round; }
    }
  }
}
