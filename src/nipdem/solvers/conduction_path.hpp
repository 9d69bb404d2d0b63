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
// Incremental use: call update() with the current contact list every step (or every few
// steps). The list is diffed against the stored graph in O(E) without sorting (per-node
// adjacency lookup with round stamps). Removed contacts that are not on the shortest-path
// tree change nothing; removing a tree contact invalidates only the subtree below it, whose
// particles are re-seeded from their valid neighbours; added contacts are relaxed locally.
// One label-correcting Dijkstra pass over the affected particles then gives exactly the
// same path resistances as a full recompute (tested).
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

// The same on a graph already in CSR form (e.g. the engine's neighbour/contact lists):
// neighbours of particle i are neighbors[offsets[i] .. offsets[i+1]) with resistances
// resistance_ohm[...] (each contact listed from both ends). Throws InputError on bad sizes,
// ids or resistances.
void shortest_paths_csr(int n, const std::vector<int>& offsets, const std::vector<int>& neighbors,
                        const std::vector<double>& resistance_ohm, const std::vector<RollerContact>& roller,
                        std::vector<double>& R_path, std::vector<int>& parent, std::vector<int>& hops);

class ConductionPaths {
 public:
  explicit ConductionPaths(int num_particles = 0);

  // Sets the current contacts (any order). Returns true if any contact changed, i.e. path
  // resistances may have changed. Throws InputError for a bad id/resistance (state
  // unchanged) or a pair listed twice in one call (the graph is cleared; the next valid
  // update rebuilds it).
  bool update(const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller);
  // Changes the number of particles (ids are 0..n-1) and clears all contacts.
  void resize(int num_particles);
  // Recomputes all paths from scratch (never needed for correctness; for checks/benchmarks).
  void recompute_all();

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
    std::uint64_t invalidated = 0;  // particles whose path was rebuilt after removals (summed)
  };
  const Stats& stats() const { return stats_; }

 private:
  struct Adj {
    int v;
    double r;
    std::uint64_t stamp;
  };
  struct Edge {
    int a, b;  // a < b; the roller is node n_
    double r;
  };
  Adj* find(int u, int v);
  void erase(int u, int v);
  void full_recompute();
  void relax(std::vector<int>& seeds);

  int n_ = 0;
  std::uint64_t round_ = 0;
  std::vector<std::vector<Adj>> adj_;  // n_+1 nodes (roller last)
  std::vector<double> dist_;           // per particle
  std::vector<int> parent_, hops_;
  std::vector<char> mark_;
  Stats stats_;
};

// Mean number of toner–toner contacts on the shortest paths of the connected particles among
// `ids` (e.g. the particles touching the drum), and the fraction of them that is connected.
// With uniform R_tt this is the <k> of charge::calibrate_contacts (docs/charge-model.md).
struct HopStats {
  double mean_hops = 0.0;
  double connected_fraction = 0.0;
  int count = 0;
};
HopStats hop_statistics(const ConductionPaths& paths, const std::vector<int>& ids);

}  // namespace nipdem::conduction
