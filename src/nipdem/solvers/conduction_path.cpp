#include "nipdem/solvers/conduction_path.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <queue>

#include "nipdem/core/error.hpp"

namespace nipdem::conduction {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr const char* kWhere = "conduction path";

void check_contact(int n, int i, int j, double r) {
  if (i < 0 || i >= n) throw_input(kWhere, "contact particle id", std::to_string(i), "out of range", fmt::format("[0, {})", n));
  if (j < 0 || j >= n) throw_input(kWhere, "contact particle id", std::to_string(j), "out of range", fmt::format("[0, {})", n));
  if (i == j) throw_input(kWhere, "contact", fmt::format("({}, {})", i, j), "a particle cannot contact itself");
  if (!(r > 0.0) || !std::isfinite(r)) require_positive(kWhere, "contact resistance_ohm", r);
}

using QItem = std::pair<double, int>;
using MinQueue = std::priority_queue<QItem, std::vector<QItem>, std::greater<>>;
}  // namespace

void shortest_paths(int n, const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller,
                    std::vector<double>& R_path, std::vector<int>& parent, std::vector<int>& hops) {
  if (n < 0) throw_input(kWhere, "num_particles", std::to_string(n), "must be >= 0");
  // CSR adjacency of the toner–toner graph.
  std::vector<int> deg(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& c : contacts) {
    check_contact(n, c.i, c.j, c.resistance_ohm);
    ++deg[c.i + 1];
    ++deg[c.j + 1];
  }
  for (int i = 0; i < n; ++i) deg[i + 1] += deg[i];
  std::vector<int> nb(deg[n]);
  std::vector<double> w(deg[n]);
  std::vector<int> fill(deg.begin(), deg.end() - 1);
  for (const auto& c : contacts) {
    nb[fill[c.i]] = c.j; w[fill[c.i]++] = c.resistance_ohm;
    nb[fill[c.j]] = c.i; w[fill[c.j]++] = c.resistance_ohm;
  }
  R_path.assign(n, kInf);
  parent.assign(n, kNoPath);
  hops.assign(n, -1);
  MinQueue q;
  for (const auto& rc : roller) {
    if (rc.i < 0 || rc.i >= n)
      throw_input(kWhere, "roller contact particle id", std::to_string(rc.i), "out of range", fmt::format("[0, {})", n));
    require_positive(kWhere, "roller contact resistance_ohm", rc.resistance_ohm);
    if (rc.resistance_ohm < R_path[rc.i]) {
      R_path[rc.i] = rc.resistance_ohm;
      parent[rc.i] = kRoller;
      hops[rc.i] = 0;
      q.push({rc.resistance_ohm, rc.i});
    }
  }
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > R_path[u]) continue;
    for (int k = deg[u]; k < deg[u + 1]; ++k) {
      const int v = nb[k];
      const double nd = d + w[k];
      if (nd < R_path[v]) {
        R_path[v] = nd;
        parent[v] = u;
        hops[v] = hops[u] + 1;
        q.push({nd, v});
      }
    }
  }
}

ConductionPaths::ConductionPaths(int num_particles) { resize(num_particles); }

void ConductionPaths::resize(int num_particles) {
  if (num_particles < 0) throw_input(kWhere, "num_particles", std::to_string(num_particles), "must be >= 0");
  n_ = num_particles;
  edges_.clear();
  adj_.assign(static_cast<std::size_t>(n_) + 1, {});
  dist_.assign(n_, kInf);
  parent_.assign(n_, kNoPath);
  hops_.assign(n_, -1);
}

std::vector<ConductionPaths::Edge> ConductionPaths::canonical(const std::vector<Contact>& c,
                                                              const std::vector<RollerContact>& r) const {
  std::vector<Edge> e;
  e.reserve(c.size() + r.size());
  for (const auto& x : c) {
    check_contact(n_, x.i, x.j, x.resistance_ohm);
    e.push_back({std::min(x.i, x.j), std::max(x.i, x.j), x.resistance_ohm});
  }
  for (const auto& x : r) {
    if (x.i < 0 || x.i >= n_) throw_input(kWhere, "roller contact particle id", std::to_string(x.i), "out of range", fmt::format("[0, {})", n_));
    require_positive(kWhere, "roller contact resistance_ohm", x.resistance_ohm);
    e.push_back({x.i, n_, x.resistance_ohm});
  }
  std::sort(e.begin(), e.end(), [](const Edge& a, const Edge& b) {
    return a.a != b.a ? a.a < b.a : (a.b != b.b ? a.b < b.b : a.r < b.r);
  });
  // Keep the smallest resistance of duplicate pairs.
  e.erase(std::unique(e.begin(), e.end(), [](const Edge& a, const Edge& b) { return a.a == b.a && a.b == b.b; }), e.end());
  return e;
}

void ConductionPaths::add_adj(const Edge& e) {
  adj_[e.a].push_back({e.b, e.r});
  adj_[e.b].push_back({e.a, e.r});
}

void ConductionPaths::remove_adj(const Edge& e) {
  auto drop = [](std::vector<std::pair<int, double>>& v, int other, double r) {
    for (std::size_t k = 0; k < v.size(); ++k)
      if (v[k].first == other && v[k].second == r) {
        v[k] = v.back();
        v.pop_back();
        return;
      }
  };
  drop(adj_[e.a], e.b, e.r);
  drop(adj_[e.b], e.a, e.r);
}

void ConductionPaths::full_recompute() {
  std::fill(dist_.begin(), dist_.end(), kInf);
  std::fill(parent_.begin(), parent_.end(), kNoPath);
  std::fill(hops_.begin(), hops_.end(), -1);
  std::vector<int> seeds{n_};
  relax_from(seeds);
}

// Dijkstra started from the given nodes with their current distances (the roller, node n_,
// has distance 0). Only improvements propagate, so this is exact after edge insertions.
void ConductionPaths::relax_from(std::vector<int>& seeds) {
  MinQueue q;
  auto dist = [&](int u) { return u == n_ ? 0.0 : dist_[u]; };
  for (int s : seeds) q.push({dist(s), s});
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist(u)) continue;
    for (const auto& [v, r] : adj_[u]) {
      if (v == n_) continue;
      const double nd = d + r;
      if (nd < dist_[v]) {
        dist_[v] = nd;
        parent_[v] = (u == n_) ? kRoller : u;
        hops_[v] = (u == n_) ? 0 : hops_[u] + 1;
        q.push({nd, v});
      }
    }
  }
}

bool ConductionPaths::update(const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller) {
  ++stats_.updates;
  std::vector<Edge> e = canonical(contacts, roller);
  if (e == edges_) {
    ++stats_.unchanged;
    return false;
  }
  // Merge-diff the sorted lists.
  std::vector<Edge> added, removed;
  std::size_t a = 0, b = 0;
  while (a < edges_.size() || b < e.size()) {
    if (b == e.size() || (a < edges_.size() && edges_[a] < e[b])) removed.push_back(edges_[a++]);
    else if (a == edges_.size() || e[b] < edges_[a]) added.push_back(e[b++]);
    else {
      if (!(edges_[a].r == e[b].r)) { removed.push_back(edges_[a]); added.push_back(e[b]); }
      ++a; ++b;
    }
  }
  // A removed edge matters only if it is a shortest-path-tree edge.
  bool tree_hit = false;
  for (const Edge& x : removed) {
    remove_adj(x);
    if (x.b == n_) tree_hit |= parent_[x.a] == kRoller && dist_[x.a] == x.r;
    else tree_hit |= parent_[x.b] == x.a || parent_[x.a] == x.b;
  }
  for (const Edge& x : added) add_adj(x);
  edges_ = std::move(e);
  if (tree_hit) {
    ++stats_.full;
    full_recompute();
  } else {
    ++stats_.incremental;
    std::vector<int> seeds;
    for (const Edge& x : added) {
      seeds.push_back(x.a);
      seeds.push_back(x.b);
    }
    relax_from(seeds);
  }
  return true;
}

std::vector<int> ConductionPaths::path(int i) const {
  std::vector<int> p;
  if (!connected(i)) return p;
  for (int u = i; u >= 0; u = parent_[u]) p.push_back(u);
  return p;
}

}  // namespace nipdem::conduction
