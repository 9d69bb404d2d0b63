// How many threads run the engine's loops, chosen by measurement: on a machine shared with other
// jobs a core may be taken, and then a step split over all threads waits for the slowest one
// (2 threads on a core shared with another job ran at 0.6-0.9x of 1 thread, docs/performance.md).
// The engine always splits its work into EngineParams::threads parts and sums them in the same
// order, so the number of threads that run them changes the speed, never a result.
//
// Schedule: after a warm-up, alternate short blocks of steps with all threads and with one
// (kProbeBlocks blocks of kBlockSteps each), keep the one whose median block time is lower, run
// with it for kHoldSteps, and probe again (the load on a shared machine changes). A probe stops
// after its first pair of blocks if the other team was more than 1.5x slower (a probe of two
// threads on a taken core costs 2-3x the steps it runs), and each probe that confirms the choice
// doubles the hold, up to kMaxHoldSteps: the probes cost ~1 % of the steps.
// While it holds more than one thread, the tuner watches the step time: kSlowBlocks blocks in a
// row each slower than kSlowFactor x the probe's median block of that team (another job took a
// core, or the probe was misled by a moment of quiet) start the next probe at once instead of up
// to kMaxHoldSteps later. (Two threads on a taken core ran at 0.56x of one thread for a whole
// 3,000-step benchmark after such a probe, docs/performance.md, twenty-first pass.) One thread is
// not watched: it is the safe choice on a loaded machine, and the periodic probe finds a core
// that came free.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>

namespace nipdem::engine {

class TeamTuner {
 public:
  static constexpr int kWarmupSteps = 32;    // before the first probe (the first list build and page faults pass)
  static constexpr int kBlockSteps = 16;     // steps per probe block
  static constexpr int kProbeBlocks = 8;     // blocks per probe, alternating (4 per candidate)
  static constexpr int kHoldSteps = 4000;    // steps between probes (after a switch)
  static constexpr int kMaxHoldSteps = 64000;
  static constexpr double kSlowFactor = 1.5;  // a held block this much slower than probed is slow
  static constexpr int kSlowBlocks = 4;       // slow blocks in a row that start a probe
  static constexpr int kWatchAfterSteps = 256;  // held steps before the watch starts (the state settles)

  // max: the threads available (EngineParams::threads); fixed > 0: always use that many.
  explicit TeamTuner(int max = 1, int fixed = 0) { reset(max, fixed); }
  void reset(int max, int fixed) {
    max_ = std::max(1, max);
    fixed_ = fixed;
    team_ = fixed > 0 ? std::min(fixed, max_) : max_;
    chosen_ = max_;
    until_probe_ = kWarmupSteps;
    hold_ = kHoldSteps;
    block_ = -1;
    ref_ = 0.0;
    held_ = slow_ = 0;
  }
  // Threads for the next step.
  int team() const { return team_; }
  // Whether the tuner is choosing (max > 1 and not fixed).
  bool adaptive() const { return fixed_ <= 0 && max_ > 1; }
  int switches() const { return switches_; }
  int probes() const { return probes_; }
  int early_probes() const { return early_probes_; }  // probes started by the watch

  // Wall time [s] of the step just run with team().
  void step_done(double seconds) {
    if (!adaptive()) return;
    if (block_ < 0) {  // holding
      watch(seconds);
      if (--until_probe_ > 0) return;
      block_ = 0;
      block_time_ = 0.0;
      in_block_ = 0;
      team_ = candidate(0);
      return;
    }
    block_time_ += seconds;
    if (++in_block_ < kBlockSteps) return;
    times_[block_] = block_time_;
    block_time_ = 0.0;
    in_block_ = 0;
    if (block_ == 1 && times_[1] > 1.5 * times_[0]) {  // the other team is clearly slower
      end_probe(chosen_);
      return;
    }
    if (++block_ < kProbeBlocks) {
      team_ = candidate(block_);
      return;
    }
    // even blocks ran candidate(0), odd ones candidate(1)
    std::array<double, kProbeBlocks / 2> a{}, b{};
    for (int k = 0; k < kProbeBlocks / 2; ++k) { a[k] = times_[2 * k]; b[k] = times_[2 * k + 1]; }
    end_probe(median(a) <= median(b) ? candidate(0) : candidate(1));
  }

 private:
  void end_probe(int best) {
    if (best != chosen_) {
      ++switches_;
      hold_ = kHoldSteps;
    } else {
      hold_ = std::min(2 * hold_, kMaxHoldSteps);
    }
    // the chosen team's median block time in this probe (even blocks ran candidate(0))
    std::array<double, kProbeBlocks / 2> mine{};
    int nm = 0;
    for (int k = 0; k <= block_ && k < kProbeBlocks; ++k)
      if (candidate(k) == best) mine[nm++] = times_[k];
    ref_ = nm == kProbeBlocks / 2 ? median(mine) : nm > 0 ? mine[0] : 0.0;  // (a probe ended early: its one block)
    chosen_ = best;
    team_ = chosen_;
    ++probes_;
    block_ = -1;
    until_probe_ = hold_;
    held_ = 0;
    slow_ = 0;
    block_time_ = 0.0;
    in_block_ = 0;
  }
  // A held step: blocks of kBlockSteps against the probe's median block (more than one thread).
  void watch(double seconds) {
    if (chosen_ <= 1 || ref_ <= 0.0 || ++held_ <= kWatchAfterSteps) return;
    block_time_ += seconds;
    if (++in_block_ < kBlockSteps) return;
    slow_ = block_time_ > kSlowFactor * ref_ ? slow_ + 1 : 0;
    block_time_ = 0.0;
    in_block_ = 0;
    if (slow_ >= kSlowBlocks && until_probe_ > 1) {
      until_probe_ = 1;  // the probe starts with this step's countdown
      ++early_probes_;
    }
  }
  // Probe blocks start with the team in use, then alternate with the other one (all or 1).
  int candidate(int block) const {
    const int other = chosen_ == 1 ? max_ : 1;
    return block % 2 == 0 ? chosen_ : other;
  }
  template <std::size_t N> static double median(std::array<double, N> v) {
    std::sort(v.begin(), v.end());
    return N % 2 ? v[N / 2] : 0.5 * (v[N / 2 - 1] + v[N / 2]);
  }
  int max_ = 1, fixed_ = 0, team_ = 1, chosen_ = 1;
  int until_probe_ = 0, hold_ = kHoldSteps, block_ = -1, in_block_ = 0;
  double block_time_ = 0.0;
  std::array<double, kProbeBlocks> times_{};
  double ref_ = 0.0;      // the chosen team's median probe block [s] (0: none yet)
  int held_ = 0, slow_ = 0;  // steps held since the probe, slow blocks in a row
  int switches_ = 0, probes_ = 0, early_probes_ = 0;
};

}  // namespace nipdem::engine
