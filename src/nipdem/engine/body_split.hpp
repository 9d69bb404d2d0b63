// Which bodies each running thread takes in the engine's per-body loops (drift, placing and
// packing the discs, their sums and kicks), chosen by measurement: the threads' time per body
// differs with the data (2 threads on the shared packing: the second half of the bodies took
// ~30 % more time than the first, on either core), and a region waits for its slowest thread.
// Per-body work is independent of which thread does it, so the split changes speed, never a
// result (the pair rows, whose split decides the order of the sums, keep theirs).
//
// Every kUpdateSteps steps each thread's share is set in proportion to the bodies it got
// through per second of its own busy time, halfway from the old share, and kept within
// [1/2, 3/2] of an even share. fix() holds a given split instead (tests, benchmarks).
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

namespace nipdem::engine {

class BodySplit {
 public:
  static constexpr int kUpdateSteps = 50;

  // First body of thread t of a team of team_size over nb bodies (t = team_size: nb). Even if
  // the team is not the one the split is kept for.
  std::size_t first(std::size_t nb, int t, int team_size) const {
    if (t <= 0) return 0;
    if (t >= team_size) return nb;
    if (team_size != team_ || cuts_.size() != static_cast<std::size_t>(team_size) + 1)
      return nb * static_cast<std::size_t>(t) / static_cast<std::size_t>(team_size);
    return std::min(nb, static_cast<std::size_t>(cuts_[static_cast<std::size_t>(t)] * static_cast<double>(nb)));
  }
  // The team the next step runs with: a new team size starts from an even split.
  void prepare(int team_size) {
    if (team_size == team_ && busy_.size() == kStride * static_cast<std::size_t>(team_size)) return;
    team_ = team_size;
    busy_.assign(kStride * static_cast<std::size_t>(team_size), 0.0);
    steps_ = 0;
    if (fixed_.size() == static_cast<std::size_t>(team_size)) {
      set_shares(fixed_);
    } else {
      cuts_.assign(static_cast<std::size_t>(team_size) + 1, 0.0);
      for (int t = 0; t <= team_size; ++t) cuts_[static_cast<std::size_t>(t)] = static_cast<double>(t) / team_size;
    }
  }
  // Thread t's busy time [s] in a per-body loop of this step (each thread its own slot).
  void add_busy(int t, double seconds) {
    if (static_cast<std::size_t>(t) * kStride < busy_.size()) busy_[static_cast<std::size_t>(t) * kStride] += seconds;
  }
  // After each step (serial).
  void step_done() {
    if (team_ < 2 || ++steps_ < kUpdateSteps) return;
    steps_ = 0;
    if (fixed_.size() != static_cast<std::size_t>(team_)) {
      std::vector<double> rate(static_cast<std::size_t>(team_));
      double total = 0.0;
      bool ok = true;
      for (int t = 0; t < team_; ++t) {
        const double share = cuts_[static_cast<std::size_t>(t) + 1] - cuts_[static_cast<std::size_t>(t)];
        const double busy = busy_[static_cast<std::size_t>(t) * kStride];
        ok = ok && busy > 0.0 && share > 0.0;
        rate[static_cast<std::size_t>(t)] = ok ? share / busy : 0.0;
        total += rate[static_cast<std::size_t>(t)];
      }
      if (ok && total > 0.0) {
        std::vector<double> shares(static_cast<std::size_t>(team_));
        for (int t = 0; t < team_; ++t) {
          const double old = cuts_[static_cast<std::size_t>(t) + 1] - cuts_[static_cast<std::size_t>(t)];
          const double even = 1.0 / team_;
          shares[static_cast<std::size_t>(t)] = std::clamp(0.5 * old + 0.5 * rate[static_cast<std::size_t>(t)] / total, 0.5 * even, 1.5 * even);
        }
        set_shares(shares);
      }
    }
    std::fill(busy_.begin(), busy_.end(), 0.0);
  }
  // Holds the shares (one per thread of a team of that size, positive); empty: measured again.
  void fix(std::vector<double> shares) {
    fixed_ = std::move(shares);
    team_ = 0;  // prepare() starts over
  }
  // The present share of thread t (for reports).
  double share(int t) const {
    return t >= 0 && static_cast<std::size_t>(t) + 1 < cuts_.size() ? cuts_[static_cast<std::size_t>(t) + 1] - cuts_[static_cast<std::size_t>(t)] : 0.0;
  }

 private:
  static constexpr std::size_t kStride = 8;  // one cache line per thread's busy time
  void set_shares(const std::vector<double>& shares) {
    double sum = 0.0;
    for (const double s : shares) sum += s;
    cuts_.assign(shares.size() + 1, 0.0);
    for (std::size_t t = 0; t < shares.size(); ++t) cuts_[t + 1] = cuts_[t] + shares[t] / sum;
    cuts_.back() = 1.0;
  }
  int team_ = 0, steps_ = 0;
  std::vector<double> cuts_, busy_, fixed_;
};

}  // namespace nipdem::engine
