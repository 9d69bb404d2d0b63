// Progress on stderr for long runs: a redrawn bar when stderr is a terminal, otherwise a
// plain line every few seconds (CLI.md). Shows simulated time, steps/s and ETA.
// The one progress reporter: `nipdem run` draws the bar; the runs inside an experiment's
// ensemble (several at once, on threads) print plain lines only, every minute.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace nipdem::io {

class Progress {
 public:
  struct Style {
    bool enabled = true;   // false: print nothing (--quiet)
    bool bar = true;       // redraw one line when stderr is a terminal
    double every_s = 5.0;  // wall time between plain lines
  };
  Progress(std::string label, double t_start, double t_end, std::int64_t step_start);
  Progress(std::string label, double t_start, double t_end, std::int64_t step_start, Style style);
  void update(double t, std::int64_t steps, const std::string& extra = {});
  void finish(double t, std::int64_t steps, const std::string& extra = {});
  double elapsed_s() const;
  double steps_per_s(std::int64_t steps) const;

 private:
  void print(double t, std::int64_t steps, const std::string& extra, bool final);
  std::string label_;
  double t0_, t1_;
  std::int64_t s0_;
  Style style_;
  bool tty_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace nipdem::io
