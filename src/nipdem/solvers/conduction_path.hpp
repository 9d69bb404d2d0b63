// Shortest conducting path from every particle to the imaging roller (thesis §2.5.5,
// fig. 2.26): the contact network is a resistor graph whose edges are toner–toner contacts
// (resistance R_tt each) and toner–roller contacts (R_ti); the roller is one multi-source
// node at potential 0. The path resistance of particle i is the minimum over paths of the
// summed edge resistances (Dijkstra from the roller), +inf when no path exists.
//
// Why a shortest path and not the full network: the thesis replaces the node-voltage
// solution of the whole circuit by the 1-D circuit along the shortest path (cheap, and it
// captures the two features that matter: an RC time, and no charging without a path).
//
// Incremental use: call update() with the current contact list every step. The list is
// canonicalised and diffed against the previous one; added contacts are relaxed locally
// (exact for insertions), removed contacts that are not on the shortest-path tree change
// nothing (exact), and only removal of a tree edge triggers a full Dijkstra. An unchanged
// contact list costs one O(E) comparison.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

namespace nipdem::conduction {

// A toner–toner contact between particle ids i != j, resistance [ohm] > 0.
struct Contact {
  int i = 0, j = 0;
  double resistance_ohm = 0.0;
};
// A toner–roller contact of particle i, resistance [ohm] > 0.
struct RollerContact {
  int i = 0;
  double resistance_ohm = 0.0;
};

inline constexpr int kRoller = -1;   // parent of a particle whose path ends at the roller
inline constexpr int kNoPath = -2;   // parent of a particle without a conducting path

// Full multi-source Dijkstra (the reference implementation). Outputs per particle the path
// resistance [ohm] (inf if none), the parent (next particle towards the roller, kRoller, or
// kNoPath) and the number of toner–toner contacts on the path (-1 if none).
// Throws InputError for ids outside [0, n), i == j, or a non-positive/non-finite resistance.
void shortest_paths(int n, const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller,
                    std::vector<double>& R_path, std::vector<int>& parent, std::vector<int>& hops);

class ConductionPaths {
 public:
  explicit ConductionPaths(int num_particles = 0);

  // Sets the current contacts. Returns true if any path resistance may have changed.
  // Duplicate contacts between the same pair keep the smallest resistance.
  bool update(const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller);
  // Changes the number of particles (ids are 0..n-1); forces a full recompute.
  void resize(int num_particles);

  int size() const { return n_; }
  double path_resistance(int i) const { return dist_[static_cast<std::size_t>(i)]; }
  bool connected(int i) const { return parent_[static_cast<std::size_t>(i)] != kNoPath; }
  int parent(int i) const { return parent_[static_cast<std::size_t>(i)]; }
  int hops(int i) const { return hops_[static_cast<std::size_t>(i)]; }
  // Particle ids from i to the particle touching the roller (empty if no path).
  std::vector<int> path(int i) const;
  const std::vector<double>& path_resistances() const { return dist_; }

  struct Stats {
    std::uint64_t updates = 0, unchanged = 0, incremental = 0, full = 0;
  };
  const Stats& stats() const { return stats_; }

 private:
  struct Edge {
    int a, b;  // a < b; the roller is node n_ (so roller edges are (i, n_))
    double r;
    bool operator<(const Edge& o) const { return a != o.a ? a < o.a : b < o.b; }
    bool operator==(const Edge& o) const { return a == o.a && b == o.b && r == o.r; }
  };
  std::vector<Edge> canonical(const std::vector<Contact>& c, const std::vector<RollerContact>& r) const;
  void full_recompute();
  void relax_from(std::vector<int>& seeds);
  void add_adj(const Edge& e);
  void remove_adj(const Edge& e);

  int n_ = 0;
  std::vector<Edge> edges_;                                // canonical, sorted
  std::vector<std::vector<std::pair<int, double>>> adj_;   // n_+1 nodes (roller last)
  std::vector<double> dist_;                               // per particle
  std::vector<int> parent_, hops_;
  Stats stats_;
};

}  // namespace nipdem::conduction
