// Blocks of work shared out by stealing: blocks [0, n) are split into T equal ranges, thread t
// takes its own range from the front and, once that is empty, the other ranges' blocks from
// their backs. A thread slowed by its share (more wall contacts, a busier core) then hands the
// end of it to the other, and each thread still starts where its data are.
// Which thread runs a block is decided at run time: use it only for work whose result does not
// depend on that (per-disc and per-body sums whose order is fixed by the data, not the thread).
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>

namespace nipdem::engine {

class BlockSteal {
 public:
  // Serial, before the parallel region: n blocks over T threads.
  void reset(int n, int T) {
    if (T > cap_) {
      r_ = std::make_unique<Range[]>(static_cast<std::size_t>(T));
      cap_ = T;
    }
    T_ = T;
    for (int t = 0; t < T; ++t) {
      const auto lo = static_cast<std::uint64_t>(static_cast<std::int64_t>(n) * t / T);
      const auto hi = static_cast<std::uint64_t>(static_cast<std::int64_t>(n) * (t + 1) / T);
      r_[t].fb.store(lo << 32 | hi, std::memory_order_relaxed);
    }
  }
  // The next block for thread t, or -1 when every block has been taken.
  int next(int t) {
    {  // own range, from the front
      auto& a = r_[t].fb;
      std::uint64_t v = a.load(std::memory_order_relaxed);
      while (static_cast<std::uint32_t>(v >> 32) < static_cast<std::uint32_t>(v)) {
        if (a.compare_exchange_weak(v, v + (std::uint64_t{1} << 32), std::memory_order_relaxed))
          return static_cast<int>(v >> 32);
      }
    }
    for (int k = 1; k < T_; ++k) {  // the others', from the back
      auto& a = r_[(t + k) % T_].fb;
      std::uint64_t v = a.load(std::memory_order_relaxed);
      while (static_cast<std::uint32_t>(v >> 32) < static_cast<std::uint32_t>(v)) {
        if (a.compare_exchange_weak(v, v - 1, std::memory_order_relaxed))
          return static_cast<int>(static_cast<std::uint32_t>(v) - 1);
      }
    }
    return -1;
  }

 private:
  struct alignas(64) Range {
    std::atomic<std::uint64_t> fb{0};  // front (high 32 bits) and back (low 32 bits), front <= back
  };
  std::unique_ptr<Range[]> r_;
  int T_ = 0, cap_ = 0;
};

}  // namespace nipdem::engine
