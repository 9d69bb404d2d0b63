// Reduction experiment analysis (thesis §4.6, fig. 4.23, table 4.3): particles removed from
// the toner assembly in a time window, front/back position and size of the assembly over
// time, and the reduction speed (slope of size vs time).
//
// Sign convention: the front is the assembly edge nearest the magnet (§4.6). The caller says
// whether that is the minimum or the maximum x (`FrontAt`); the back is the other extreme.
// Robustness: `trim` extreme particles on each side are ignored (stray particles that left the
// assembly but are still tracked), so a few outliers do not move front or back.
#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "nipdem/core/vec2.hpp"

namespace nipdem::analysis {

// ---- Removal events --------------------------------------------------------------------
struct RemovalEvent {
  double t = 0;      // time of removal [s]
  Vec2 where;        // position where the particle left the assembly [m]
  long id = -1;      // particle id if known
};

// Collects removal events (in any order) and counts them per time window.
class RemovalCounter {
 public:
  void record(double t, Vec2 where, long id = -1) { events_.push_back({t, where, id}); }
  void record(const RemovalEvent& e) { events_.push_back(e); }
  // Number of events with t0 <= t < t1.
  std::size_t count(double t0, double t1) const;
  // Same, only events for which `select` is true (e.g. removed past a given x).
  std::size_t count(double t0, double t1, const std::function<bool(const RemovalEvent&)>& select) const;
  // Counts in consecutive windows [t0 + k dt, t0 + (k+1) dt), k = 0 .. n-1.
  std::vector<std::size_t> histogram(double t0, double dt, std::size_t n) const;
  const std::vector<RemovalEvent>& events() const { return events_; }

 private:
  std::vector<RemovalEvent> events_;
};

// ---- Front / back / size ----------------------------------------------------------------
enum class FrontAt { min_x, max_x };

struct ExtentOptions {
  FrontAt front = FrontAt::min_x;
  std::size_t trim = 0;         // extreme particles ignored on each side
  double trim_fraction = 0.0;   // or this fraction of the particles (the larger of the two)
};

struct Extent {
  double t = 0;
  double front = 0, back = 0;   // [m]
  double size = 0;              // |back - front| [m]
  std::size_t n = 0;            // particles considered
};

// Front/back/size from particle x positions at time t. Throws InputError if, after trimming,
// no particle is left.
Extent assembly_extent(double t, const std::vector<double>& x, const ExtentOptions& opt = {});
// One Extent per frame: x_per_frame[k] are the particle x positions at time t[k].
std::vector<Extent> assembly_extents(const std::vector<double>& t, const std::vector<std::vector<double>>& x_per_frame,
                                     const ExtentOptions& opt = {});

// ---- Least squares line ------------------------------------------------------------------
struct LinearFit {
  double slope = 0, intercept = 0;
  double slope_stderr = 0, intercept_stderr = 0;  // from the residual variance (n - 2 dof)
  double r2 = 0;
  std::size_t n = 0;
};
LinearFit linear_fit(const std::vector<double>& x, const std::vector<double>& y);

struct ReductionSpeed {
  double speed = 0;         // -d(size)/dt [m/s], positive when the assembly shrinks
  double speed_stderr = 0;  // [m/s]
  LinearFit size_fit;       // size vs t
  LinearFit front_fit, back_fit;
};
// Needs at least 3 samples at distinct times.
ReductionSpeed reduction_speed(const std::vector<Extent>& samples);

}  // namespace nipdem::analysis
