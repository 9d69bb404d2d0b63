#include "nipdem/solvers/ldc/ldc_solver.hpp"

#include <algorithm>
#include <cmath>

#include "nipdem/solvers/ldc/annulus.hpp"
#include "nipdem/solvers/ldc/local_domains.hpp"
#include "nipdem/solvers/ldc/local_fd.hpp"
#include "nipdem/solvers/ldc/schwarz.hpp"

namespace nipdem::ldc {

namespace {
// State of one local group during a solve.
struct Group {
  LocalGroup def;
  std::vector<AnnulusSolution> ann;  // analytic / schwarz, per member
  std::vector<int> samples;          // 2N+1 per member
  std::vector<double> buffer;        // analytic: samples of u^H on Γ
  std::unique_ptr<SchwarzSolver> schwarz;
  std::unique_ptr<FdLocalProblem> fd;
  std::vector<int> owned, defect;  // coarse nodes
  bool local_warm = false;
};
}  // namespace

struct LdcSolver::Impl {
  Params p;
  CoarseGrid grid;
  CoarseSolver coarse;
  std::vector<Disc> discs;
  std::vector<Group> groups;
  std::vector<int> group_of_disc, slot_of_disc;
  std::vector<double> u, w, source, g, g_new;
  std::vector<std::uint8_t> cond_mask;
  std::vector<int> cond_disc, owner;
  std::vector<double> depth;  // distance of an owned coarse node to its Γ
  std::vector<Vec2> gamma_pts;
  std::vector<double> gamma_prev, gamma_cur;
  std::vector<Vec2> forces;
  SolveStats stats;
  bool have_warm = false;
  // Finite-difference problems of the previous solve, reused by a group with the same rectangle,
  // refinement and members (the factorisation is kept while no fine node changes its kind).
  std::vector<Group> previous_groups;
  int fd_factorisations_before = 0;

  explicit Impl(const Params& prm) : p(prm), grid(prm), coarse(grid) {
    const int n = grid.size();
    u.assign(n, 0.0);
    w.assign(n, 0.0);
    source.assign(n, 0.0);
    cond_mask.assign(n, 0);
    cond_disc.assign(n, -1);
    owner.assign(n, -1);
  }

  void node_range(Vec2 c, double r, int& i0, int& i1, int& j0, int& j1) const;
  void mark_conductor_nodes();
  void setup_annulus_group(int gi);
  void setup_fd_group(int gi);
  void select_defect_nodes();
  void setup_geometry();
  void local_solve();
  double local_value(const Group& gr, int n) const;
  void run();
  void aitken_step(int it);
  std::vector<double> source_prev, g_prev;
  int last_extrapolation = 0;
  bool aitken_off = false;
  std::function<void(const SolveStats&)> progress;
};

// Aitken extrapolation of the LDC state (defect d and potentials g, which determine the next
// iterate). In dense configurations the iteration converges with one dominant factor ρ shared by
// all discs (measured 0.71 for 200 discs in 1 mm², docs/ldc.md); once both quantities of the
// stopping test (change of g and change of u^H on Γ) shrink by the same steady factor (the last
// two ratios of each within 2 %, the two within 5 %, 0.3 < ρ < 0.95), the geometric tail is
// summed: x += ρ/(1-ρ) (x_i - x_{i-1}). The iteration then continues from the extrapolated state,
// so the stopping test still compares two plain iterations. At most every third iteration; if
// the first plain change after an extrapolation is larger than the one before it, the iteration
// is not a single geometric mode and extrapolation stops for this solve.
void LdcSolver::Impl::aitken_step(int it) {
  const auto& pc = stats.potential_change;
  const auto& dl = stats.delta;  // dl[j] compares coarse solves j+1 and j+2
  if (last_extrapolation > 0 && it == last_extrapolation + 1 && pc[it - 1] > pc[it - 2]) aitken_off = true;
  if (aitken_off || it < 5 || it - last_extrapolation < 3) return;
  auto steady = [](double a, double b, double c, double& r) {
    if (!(a > 0 && b > 0)) return false;
    const double r1 = c / b, r0 = b / a;
    r = r1;
    return r1 > 0.3 && r1 < 0.95 && std::abs(r1 - r0) <= 0.02 * r1;
  };
  double rg, rd;
  if (!steady(pc[it - 3], pc[it - 2], pc[it - 1], rg)) return;
  if (dl.size() < 3 || !steady(dl[dl.size() - 3], dl[dl.size() - 2], dl[dl.size() - 1], rd)) return;
  if (std::abs(rg - rd) > 0.05 * rg) return;
  const double f = rg / (1.0 - rg);
  for (std::size_t n = 0; n < source.size(); ++n) source[n] += f * (source[n] - source_prev[n]);
  for (std::size_t k = 0; k < g.size(); ++k) g[k] += f * (g[k] - g_prev[k]);
  last_extrapolation = it;
  ++stats.extrapolations;
}

void LdcSolver::Impl::node_range(Vec2 c, double r, int& i0, int& i1, int& j0, int& j1) const {
  const Vec2 o = grid.lower();
  i0 = std::max(0, int(std::floor((c.x - r - o.x) / grid.hx())));
  i1 = std::min(grid.nx() - 1, int(std::ceil((c.x + r - o.x) / grid.hx())));
  j0 = std::max(0, int(std::floor((c.y - r - o.y) / grid.hy())));
  j1 = std::min(grid.ny() - 1, int(std::ceil((c.y + r - o.y) / grid.hy())));
}

// Coarse nodes inside a disc (closed, as in eq. 3.8.4): Dirichlet nodes u = g_k in the thesis
// formulation, otherwise free nodes whose local value is g_k.
void LdcSolver::Impl::mark_conductor_nodes() {
  std::fill(cond_mask.begin(), cond_mask.end(), 0);
  std::fill(cond_disc.begin(), cond_disc.end(), -1);
  for (int k = 0; k < int(discs.size()); ++k) {
    int i0, i1, j0, j1;
    node_range(discs[k].center_m, discs[k].radius_m, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i)
        if (norm(grid.node(i, j) - discs[k].center_m) <= discs[k].radius_m * (1 + 1e-12)) {
          const int n = grid.index(i, j);
          if (!grid.box_dirichlet(n)) {
            cond_mask[n] = p.dirichlet_conductor_nodes ? 1 : 0;
            cond_disc[n] = k;
          }
        }
  }
  if (coarse.set_extra_dirichlet(cond_mask)) ++stats.coarse_factorisations;
}

void LdcSolver::Impl::setup_annulus_group(int gi) {
  Group& gr = groups[gi];
  const auto& mem = gr.def.members;
  const double hmin = std::min(grid.hx(), grid.hy());
  gr.ann.resize(mem.size());
  gr.samples.resize(mem.size());
  for (int m = 0; m < int(mem.size()); ++m) {
    const Disc& d = discs[mem[m]];
    const double r2 = gr.def.r2[m];
    gr.samples[m] = AnnulusSolution::samples_for(r2, hmin / p.gamma_points_per_cell);
    for (int j = 0; j < gr.samples[m]; ++j) gamma_pts.push_back(AnnulusSolution::sample_point(d.center_m, r2, j, gr.samples[m]));
    int i0, i1, j0, j1;
    node_range(d.center_m, r2, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const int n = grid.index(i, j);
        const double dd = r2 - norm(grid.node(i, j) - d.center_m);
        if (dd < 0) continue;
        if (owner[n] < 0) { owner[n] = gi; gr.owned.push_back(n); }
        if (owner[n] == gi) depth[n] = std::max(depth[n], dd);
      }
  }
  if (gr.def.method == LocalMethod::schwarz) {
    std::vector<Disc> ds;
    for (int k : mem) ds.push_back(discs[k]);
    gr.schwarz = std::make_unique<SchwarzSolver>(ds, gr.def.r2, gr.samples);
  }
}

void LdcSolver::Impl::setup_fd_group(int gi) {
  Group& gr = groups[gi];
  const LocalGroup& g = gr.def;
  const int nx = grid.nx(), ny = grid.ny(), r = g.refinement;
  const std::array<bool, 4> neu = {g.i0 == 0 && grid.neumann_x_min(), g.i1 == nx - 1 && grid.neumann_x_max(),
                                   g.j0 == 0 && grid.neumann_y_min(), g.j1 == ny - 1 && grid.neumann_y_max()};
  std::vector<FdConductor> cs;
  for (int k : g.members) cs.push_back({false, discs[k].center_m, discs[k].radius_m, {}, {}, discs[k].charge_C_per_m});
  ++stats.fd_groups;
  for (Group& old : previous_groups) {
    const LocalGroup& o = old.def;
    if (!old.fd || o.i0 != g.i0 || o.i1 != g.i1 || o.j0 != g.j0 || o.j1 != g.j1 || o.refinement != r ||
        o.members != g.members)
      continue;
    gr.fd = std::move(old.fd);
    fd_factorisations_before += gr.fd->counters().factorisations;
    if (gr.fd->update_conductors(std::move(cs))) ++stats.fd_kept;
    break;
  }
  if (!gr.fd)
    gr.fd = std::make_unique<FdLocalProblem>(grid.node(g.i0, g.j0), grid.hx() / r, grid.hy() / r, (g.i1 - g.i0) * r,
                                             (g.j1 - g.j0) * r, neu, std::move(cs), p.permittivity_F_per_m);
  // Γ = the sides of the rectangle that are not box sides.
  const bool open[4] = {g.i0 > 0, g.i1 < nx - 1, g.j0 > 0, g.j1 < ny - 1};
  const double eps_depth = 1e-9 * std::min(grid.hx(), grid.hy());
  for (int j = g.j0; j <= g.j1; ++j)
    for (int i = g.i0; i <= g.i1; ++i) {
      const int n = grid.index(i, j);
      double d = 1e300;
      if (open[0]) d = std::min(d, (i - g.i0) * grid.hx());
      if (open[1]) d = std::min(d, (g.i1 - i) * grid.hx());
      if (open[2]) d = std::min(d, (j - g.j0) * grid.hy());
      if (open[3]) d = std::min(d, (g.j1 - j) * grid.hy());
      if (owner[n] < 0) { owner[n] = gi; depth[n] = d; gr.owned.push_back(n); }
      if (d < eps_depth) gamma_pts.push_back(grid.node(i, j));
    }
}

// Defect region (eqs. 3.2.5, 3.2.8): whole stencil inside the node's own local domain, and
// farther than safety_m from Γ.
void LdcSolver::Impl::select_defect_nodes() {
  const int nx = grid.nx(), ny = grid.ny();
  const double eps_depth = 1e-9 * std::min(grid.hx(), grid.hy());
  for (int gi = 0; gi < int(groups.size()); ++gi) {
    Group& gr = groups[gi];
    for (int n : gr.owned) {
      if (coarse.is_dirichlet(n) || depth[n] <= p.safety_m + eps_depth) continue;
      const int i = n % nx, j = n / nx;
      const int ni[4] = {i + 1 < nx ? i + 1 : i - 1, i > 0 ? i - 1 : i + 1, i, i};
      const int nj[4] = {j, j, j + 1 < ny ? j + 1 : j - 1, j > 0 ? j - 1 : j + 1};
      bool inside = true;
      for (int s = 0; s < 4 && inside; ++s) {
        const int q = grid.index(ni[s], nj[s]);
        inside = owner[q] == gi || grid.box_dirichlet(q);
      }
      if (inside) gr.defect.push_back(n);
    }
  }
}

void LdcSolver::Impl::setup_geometry() {
  const int nd = int(discs.size());
  mark_conductor_nodes();
  const std::vector<LocalGroup> defs = build_local_groups(grid, discs, p);
  previous_groups = std::move(groups);
  groups.clear();
  fd_factorisations_before = 0;
  groups.resize(defs.size());
  group_of_disc.assign(nd, -1);
  slot_of_disc.assign(nd, -1);
  std::fill(owner.begin(), owner.end(), -1);
  depth.assign(grid.size(), -1.0);
  gamma_pts.clear();
  for (int gi = 0; gi < int(defs.size()); ++gi) {
    groups[gi].def = defs[gi];
    for (int m = 0; m < int(defs[gi].members.size()); ++m) {
      group_of_disc[defs[gi].members[m]] = gi;
      slot_of_disc[defs[gi].members[m]] = m;
    }
  }
  // Annuli claim their coarse nodes first; a finite-difference rectangle that overlaps an annulus
  // keeps only the rest (both local solutions are valid there, but each node needs one owner
  // whose local domain contains its whole stencil for the defect).
  for (int gi = 0; gi < int(defs.size()); ++gi)
    if (defs[gi].method != LocalMethod::finite_difference) setup_annulus_group(gi);
  for (int gi = 0; gi < int(defs.size()); ++gi)
    if (defs[gi].method == LocalMethod::finite_difference) setup_fd_group(gi);
  previous_groups.clear();
  select_defect_nodes();
  gamma_prev.assign(gamma_pts.size(), 0.0);
  gamma_cur.assign(gamma_pts.size(), 0.0);
}

double LdcSolver::Impl::local_value(const Group& gr, int n) const {
  const Vec2 x = grid.node(n);
  switch (gr.def.method) {
    case LocalMethod::analytic: return gr.ann[0].value(x);
    case LocalMethod::schwarz: return SchwarzSolver::value(gr.ann, x);
    case LocalMethod::finite_difference: {
      const int r = gr.def.refinement;
      return gr.fd->node_value((n % grid.nx() - gr.def.i0) * r, (n / grid.nx() - gr.def.j0) * r);
    }
  }
  return 0.0;
}

void LdcSolver::Impl::local_solve() {
  const double eps = p.permittivity_F_per_m;
  auto outer = [this](Vec2 x) { return grid.interpolate(u, x); };
  double scale = 0.0;
  for (double v : u) scale = std::max(scale, std::abs(v));
  const double schwarz_tol = std::max(p.schwarz_tolerance, 0.0) * std::max(scale, 1e-300);
  for (Group& gr : groups) {
    const auto& mem = gr.def.members;
    switch (gr.def.method) {
      case LocalMethod::analytic: {
        const Disc& d = discs[mem[0]];
        gr.buffer.resize(gr.samples[0]);
        for (int j = 0; j < gr.samples[0]; ++j)
          gr.buffer[j] = grid.interpolate(u, AnnulusSolution::sample_point(d.center_m, gr.def.r2[0], j, gr.samples[0]));
        gr.ann[0].fit(d.center_m, d.radius_m, gr.def.r2[0], d.charge_C_per_m, eps, gr.buffer);
        g_new[mem[0]] = gr.ann[0].potential();
        break;
      }
      case LocalMethod::schwarz: {
        const auto res = gr.schwarz->solve(outer, eps, schwarz_tol, p.schwarz_max_iterations, gr.local_warm, gr.ann);
        stats.schwarz_sweeps += res.sweeps;
        gr.local_warm = true;
        for (int m = 0; m < int(mem.size()); ++m) g_new[mem[m]] = gr.ann[m].potential();
        break;
      }
      case LocalMethod::finite_difference: {
        gr.fd->solve(outer);
        for (int m = 0; m < int(mem.size()); ++m) g_new[mem[m]] = gr.fd->potential(m);
        break;
      }
    }
  }
}

void LdcSolver::Impl::run() {
  const int nd = int(discs.size());
  const int nx = grid.nx();
  stats = SolveStats{};
  const bool warm = have_warm && int(g.size()) == nd;
  if (!warm) {
    groups.clear();  // a cold solve builds every finite-difference problem afresh
    g.assign(nd, p.initial_potential_V);
    std::fill(u.begin(), u.end(), 0.0);
    std::fill(source.begin(), source.end(), 0.0);
  }
  g_new.assign(nd, 0.0);
  last_extrapolation = 0;
  aitken_off = false;
  setup_geometry();
  // Defect entries outside the new defect region (from a previous geometry) are dropped.
  std::vector<char> in_defect(grid.size(), 0);
  for (const Group& gr : groups)
    for (int n : gr.defect) in_defect[n] = 1;
  for (int n = 0; n < grid.size(); ++n)
    if (!in_defect[n]) source[n] = 0.0;

  for (int it = 1; it <= p.max_iterations; ++it) {
    for (int n = 0; n < grid.size(); ++n)
      if (cond_mask[n]) u[n] = g[cond_disc[n]];
    coarse.solve(source, u);
    double delta = 0.0;
    for (std::size_t s = 0; s < gamma_pts.size(); ++s) {
      gamma_cur[s] = grid.interpolate(u, gamma_pts[s]);
      delta = std::max(delta, std::abs(gamma_cur[s] - gamma_prev[s]));
    }
    std::swap(gamma_cur, gamma_prev);
    if (it > 1) stats.delta.push_back(delta);

    local_solve();
    // w = local solution inside the local domains, u^H elsewhere; κ and the defect from it.
    std::copy(u.begin(), u.end(), w.begin());
    double kappa = 0.0;
    for (const Group& gr : groups)
      for (int n : gr.owned) {
        if (grid.box_dirichlet(n)) continue;
        w[n] = cond_disc[n] >= 0 ? g_new[cond_disc[n]] : local_value(gr, n);
        if (!coarse.is_dirichlet(n)) kappa = std::max(kappa, std::abs(w[n] - u[n]));
      }
    if (p.aitken) source_prev = source;
    for (const Group& gr : groups)
      for (int n : gr.defect) source[n] = grid.laplacian(w, n % nx, n / nx);
    stats.kappa.push_back(kappa);
    double dg = 0.0, scale = 0.0;
    g_prev = g;
    for (int k = 0; k < nd; ++k) {
      dg = std::max(dg, std::abs(g_new[k] - g[k]));
      scale = std::max(scale, std::abs(g_new[k]));
      g[k] = g_new[k];
    }
    for (double v : u) scale = std::max(scale, std::abs(v));
    stats.potential_change.push_back(dg);
    stats.iterations = it;
    if (progress) progress(stats);
    const double tol = p.tolerance * std::max(scale, 1e-300);
    if (it > 1 && dg <= tol && delta <= tol) {
      stats.converged = true;
      break;
    }
    if (p.aitken) aitken_step(it);
  }
  int fd_factorisations = 0;
  for (const Group& gr : groups)
    if (gr.fd) fd_factorisations += gr.fd->counters().factorisations;
  stats.fd_factorisations = fd_factorisations - fd_factorisations_before;
  forces.assign(nd, Vec2{});
  for (int k = 0; k < nd; ++k) {
    const Group& gr = groups[group_of_disc[k]];
    const int m = slot_of_disc[k];
    forces[k] = gr.def.method == LocalMethod::finite_difference ? gr.fd->force(m) : gr.ann[m].force(p.permittivity_F_per_m);
  }
  have_warm = true;
}

LdcSolver::LdcSolver(const Params& p) {
  validate(p);
  impl_ = std::make_unique<Impl>(p);
}
LdcSolver::~LdcSolver() = default;
LdcSolver::LdcSolver(LdcSolver&&) noexcept = default;
LdcSolver& LdcSolver::operator=(LdcSolver&&) noexcept = default;

const SolveStats& LdcSolver::solve(std::span<const Disc> discs) {
  validate_discs(impl_->p, discs);
  impl_->discs.assign(discs.begin(), discs.end());
  impl_->run();
  return impl_->stats;
}

void LdcSolver::reset_warm_start() { impl_->have_warm = false; }
void LdcSolver::set_progress(std::function<void(const SolveStats&)> progress) { impl_->progress = std::move(progress); }
int LdcSolver::disc_count() const { return int(impl_->discs.size()); }
double LdcSolver::potential(int k) const { return impl_->g.at(k); }
Vec2 LdcSolver::force(int k) const { return impl_->forces.at(k); }
LocalMethod LdcSolver::method(int k) const { return impl_->groups[impl_->group_of_disc.at(k)].def.method; }
const SolveStats& LdcSolver::stats() const { return impl_->stats; }
const CoarseGrid& LdcSolver::grid() const { return impl_->grid; }
std::span<const double> LdcSolver::coarse_solution() const { return impl_->u; }
const Params& LdcSolver::params() const { return impl_->p; }

double LdcSolver::potential_at(Vec2 x) const {
  for (const auto& gr : impl_->groups) {
    if (gr.def.method == LocalMethod::finite_difference) {
      if (gr.fd->contains(x)) return gr.fd->value(x);
      continue;
    }
    for (std::size_t m = 0; m < gr.ann.size(); ++m)
      if (norm(x - gr.ann[m].center()) <= gr.ann[m].r2())
        return gr.def.method == LocalMethod::analytic ? gr.ann[0].value(x) : SchwarzSolver::value(gr.ann, x);
  }
  return impl_->grid.interpolate(impl_->u, x);
}

Vec2 LdcSolver::field(Vec2 x) const {
  for (const auto& gr : impl_->groups) {
    if (gr.def.method == LocalMethod::finite_difference) {
      if (gr.fd->contains(x)) return gr.fd->field(x);
      continue;
    }
    for (std::size_t m = 0; m < gr.ann.size(); ++m)
      if (norm(x - gr.ann[m].center()) <= gr.ann[m].r2())
        return gr.def.method == LocalMethod::analytic ? gr.ann[0].field(x) : SchwarzSolver::field(gr.ann, x);
  }
  return impl_->grid.field(impl_->u, x);
}

}  // namespace nipdem::ldc
