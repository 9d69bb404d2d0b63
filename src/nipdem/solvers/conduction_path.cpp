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

void shortest_paths_csr(int n, const std::vector<int>& deg, const std::vector<int>& nb, const std::vector<double>& w,
                        const std::vector<RollerContact>& roller, std::vector<double>& R_path, std::vector<int>& parent,
                        std::vector<int>& hops) {
  if (n < 0) throw_input(kWhere, "num_particles", std::to_string(n), "must be >= 0");
  if (deg.size() != static_cast<std::size_t>(n) + 1 || deg[0] != 0 || nb.size() != static_cast<std::size_t>(deg[n]) ||
      w.size() != nb.size())
    throw_input(kWhere, "CSR arrays", fmt::format("offsets {}, neighbors {}, resistances {}", deg.size(), nb.size(), w.size()),
                "inconsistent sizes", "offsets n+1 starting at 0, neighbors and resistances offsets[n]");
  for (int i = 0; i < n; ++i) {
    if (deg[i + 1] < deg[i]) throw_input(kWhere, "CSR offsets", std::to_string(i), "must be non-decreasing");
    for (int k = deg[i]; k < deg[i + 1]; ++k) check_contact(n, i, nb[k], w[k]);
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
  shortest_paths_csr(n, deg, nb, w, roller, R_path, parent, hops);
}

ConductionPaths::ConductionPaths(int num_particles) { resize(num_particles); }

void ConductionPaths::resize(int num_particles) {
  if (num_particles < 0) throw_input(kWhere, "num_particles", std::to_string(num_particles), "must be >= 0");
  n_ = num_particles;
  adj_.assign(static_cast<std::size_t>(n_) + 1, {});
  dist_.assign(n_, kInf);
  parent_.assign(n_, kNoPath);
  hops_.assign(n_, -1);
  mark_.assign(n_, 0);
}

ConductionPaths::Adj* ConductionPaths::find(int u, int v) {
  for (auto& e : adj_[u])
    if (e.v == v) return &e;
  return nullptr;
}

void ConductionPaths::erase(int u, int v) {
  auto& l = adj_[u];
  for (std::size_t k = 0; k < l.size(); ++k)
    if (l[k].v == v) {
      l[k] = l.back();
      l.pop_back();
      return;
    }
}

void ConductionPaths::recompute_all() { full_recompute(); }

void ConductionPaths::full_recompute() {
  std::fill(dist_.begin(), dist_.end(), kInf);
  std::fill(parent_.begin(), parent_.end(), kNoPath);
  std::fill(hops_.begin(), hops_.end(), -1);
  std::vector<int> seeds{n_};
  relax(seeds);
}

// Label-correcting Dijkstra from the seeds with their current labels (the roller, node n_,
// has label 0). Labels only decrease, and every particle whose label may be too large is a
// seed or reachable from one, so the result is the exact shortest-path forest.
void ConductionPaths::relax(std::vector<int>& seeds) {
  MinQueue q;
  auto dist = [&](int u) { return u == n_ ? 0.0 : dist_[u]; };
  for (int s : seeds)
    if (dist(s) < kInf) q.push({dist(s), s});
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist(u)) continue;
    for (const Adj& e : adj_[u]) {
      if (e.v == n_) continue;
      const double nd = d + e.r;
      if (nd < dist_[e.v]) {
        dist_[e.v] = nd;
        parent_[e.v] = (u == n_) ? kRoller : u;
        hops_[e.v] = (u == n_) ? 0 : hops_[u] + 1;
        q.push({nd, e.v});
      }
    }
  }
}

bool ConductionPaths::update(const std::vector<Contact>& contacts, const std::vector<RollerContact>& roller) {
  ++stats_.updates;
  const std::uint64_t stamp = ++round_;
  std::vector<Edge> added, removed;
  auto visit = [&](int a, int b, double r) {
    if (Adj* e = find(a, b)) {
      if (e->stamp == stamp)
        throw_input(kWhere, "contact", b == n_ ? fmt::format("(particle {}, roller)", a) : fmt::format("({}, {})", a, b),
                    "listed twice in one update");
      e->stamp = stamp;
      if (e->r != r) {
        removed.push_back({a, b, e->r});
        added.push_back({a, b, r});
        e->r = r;
        find(b, a)->r = r;
      }
    } else {
      adj_[a].push_back({b, r, stamp});
      adj_[b].push_back({a, r, stamp});
      added.push_back({a, b, r});
    }
  };
  // Validate everything before touching the graph.
  for (const auto& c : contacts) check_contact(n_, c.i, c.j, c.resistance_ohm);
  for (const auto& rc : roller) {
    if (rc.i < 0 || rc.i >= n_)
      throw_input(kWhere, "roller contact particle id", std::to_string(rc.i), "out of range", fmt::format("[0, {})", n_));
    require_positive(kWhere, "roller contact resistance_ohm", rc.resistance_ohm);
  }
  try {
    for (const auto& c : contacts) visit(std::min(c.i, c.j), std::max(c.i, c.j), c.resistance_ohm);
    for (const auto& rc : roller) visit(rc.i, n_, rc.resistance_ohm);
  } catch (...) {
    resize(n_);  // a duplicate pair was found mid-way: drop the half-applied graph (next update rebuilds it)
    throw;
  }
  // Contacts not listed this round are gone (each edge checked from its smaller end).
  std::vector<Edge> gone;
  for (int u = 0; u < n_; ++u)
    for (const Adj& e : adj_[u])
      if (e.v > u && e.stamp != stamp) gone.push_back({u, e.v, e.r});
  for (const Edge& e : gone) {
    erase(e.a, e.b);
    erase(e.b, e.a);
  }
  removed.insert(removed.end(), gone.begin(), gone.end());
  if (added.empty() && removed.empty()) {
    ++stats_.unchanged;
    return false;
  }
  // Roots of invalidated subtrees: the child end of every removed tree edge.
  std::vector<int> stack;
  for (const Edge& e : removed) {
    if (e.b == n_) {
      if (parent_[e.a] == kRoller && dist_[e.a] == e.r) stack.push_back(e.a);
    } else {
      if (parent_[e.b] == e.a) stack.push_back(e.b);
      if (parent_[e.a] == e.b) stack.push_back(e.a);
    }
  }
  std::vector<int> invalid;
  for (int r : stack) mark_[r] = 1;
  while (!stack.empty()) {
    const int u = stack.back();
    stack.pop_back();
    invalid.push_back(u);
    for (const Adj& e : adj_[u])
      if (e.v != n_ && !mark_[e.v] && parent_[e.v] == u) {
        mark_[e.v] = 1;
        stack.push_back(e.v);
      }
  }
  stats_.invalidated += invalid.size();
  if (invalid.size() * 2 > static_cast<std::size_t>(n_)) {
    for (int u : invalid) mark_[u] = 0;
    ++stats_.full;
    full_recompute();
    return true;
  }
  ++stats_.incremental;
  for (int u : invalid) {
    dist_[u] = kInf;
    parent_[u] = kNoPath;
    hops_[u] = -1;
  }
  // Re-seed invalidated particles from their valid neighbours (and the roller).
  std::vector<int> seeds;
  for (int u : invalid) {
    for (const Adj& e : adj_[u]) {
      if (e.v == n_) {
        if (e.r < dist_[u]) { dist_[u] = e.r; parent_[u] = kRoller; hops_[u] = 0; }
      } else if (!mark_[e.v] && dist_[e.v] + e.r < dist_[u]) {
        dist_[u] = dist_[e.v] + e.r;
        parent_[u] = e.v;
        hops_[u] = hops_[e.v] + 1;
      }
    }
    seeds.push_back(u);
  }
  for (int u : invalid) mark_[u] = 0;
  for (const Edge& e : added) {
    seeds.push_back(e.a);
    seeds.push_back(e.b);
  }
  relax(seeds);
  return true;
}

std::vector<int> ConductionPaths::path(int i) const {
  std::vector<int> p;
  if (!connected(i)) return p;
  for (int u = i; u >= 0; u = parent_[u]) p.push_back(u);
  return p;
}

HopStats hop_statistics(const ConductionPaths& paths, const std::vector<int>& ids) {
  HopStats h;
  long sum = 0;
  int connected = 0;
  for (int i : ids) {
    if (i < 0 || i >= paths.size())
      throw_input(kWhere, "particle id", std::to_string(i), "out of range", fmt::format("[0, {})", paths.size()));
    ++h.count;
    if (paths.connected(i)) {
      ++connected;
      sum += paths.hops(i);
    }
  }
  h.mean_hops = connected ? static_cast<double>(sum) / connected : 0.0;
  h.connected_fraction = h.count ? static_cast<double>(connected) / h.count : 0.0;
  return h;
}

}  // namespace nipdem::conduction
