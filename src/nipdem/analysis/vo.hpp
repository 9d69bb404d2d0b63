// Vo-level search (thesis §5.2): the lowest voltage difference between imaging roller and
// DI-drum at which particles are printed, found by stepping the voltage (the thesis uses
// steps of 0.5 V) until the printed count becomes positive.
//
// The simulation is passed in as a function, so this helper knows nothing of the engine:
//   auto r = analysis::find_vo_level([&](double V) { return run_print(V, seed).printed; },
//                                    {.v0_V = 30, .step_V = 0.5, .v_max_V = 80});
#pragma once
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace nipdem::analysis {

struct VoSearchOptions {
  double v0_V = 0.0;      // first voltage tried [V]
  double step_V = 0.5;    // step [V]; negative to search downwards in (negative) voltage
  double v_max_V = 100.0; // give up beyond this voltage (inclusive bound in the step direction)
  // 0: plain stepping. Otherwise a multiple m >= 2 of step_V (same sign): step by it until a
  // voltage Vc prints, then try Vc - coarse + step, ..., Vc - step. Every voltage tried lies on
  // the fine grid v0 + k step, and the result equals plain stepping whenever no voltage below
  // the last non-printing coarse level would print (printing that switches off again as V
  // rises is missed). Costs ~ (Vo - v0)/coarse + m - 1 runs instead of (Vo - v0)/step + 1.
  double coarse_step_V = 0.0;
};

struct VoResult {
  bool found = false;
  double vo_V = 0;                                  // first V with count > 0
  long count_at_vo = 0;
  std::vector<std::pair<double, long>> trace;       // every (V, count) evaluated
};

// Steps V = v0, v0 + step, ... while |V - v0| <= |v_max - v0|; stops at the first count > 0.
// Throws InputError for step 0 or a v_max on the wrong side of v0.
VoResult find_vo_level(const std::function<long(double V)>& printed_count, const VoSearchOptions& opt = {});

struct VoStatistics {
  std::vector<double> vo_V;           // per seed (only seeds where Vo was found)
  std::vector<std::uint64_t> seeds_not_found;
  double mean_V = 0, std_V = 0;       // sample std (n - 1); 0 with one value
  double stderr_V = 0;
};
VoStatistics vo_level_over_seeds(const std::function<long(double V, std::uint64_t seed)>& printed_count,
                                 const std::vector<std::uint64_t>& seeds, const VoSearchOptions& opt = {});

}  // namespace nipdem::analysis
