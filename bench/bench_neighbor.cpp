// Contact-list build speed (geometry::NeighborList::rebuild), the step that runs at every body
// exchange of the nip and whenever two discs may have closed the skin: ns per disc and build.
// A fixed random state (seeded): --discs discs of radii uniform in [3.5, 7.25] um, dropped
// without overlap at area fraction ~0.6 into a box (periodic in x or not), numbered along x as
// the nip's inflow numbers them, grouped into rigid
// clusters of --per-body consecutive discs (pairs of one cluster are skipped by the list), moved
// by a small random step between builds so that the list's history carry-over runs as in a run.
// Prints one RESULT line (bench/README.md): builds, pairs, ns_per_disc_build and a checksum of
// the list (equal checksums: equal lists, so two builds of the program can be compared).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "nipdem/geometry/neighbor_list.hpp"

int main(int argc, char** argv) {
  int discs = 20000, builds = 200, per_body = 3, threads = 1, periodic = 0;
  double skin = 2.4e-6, extra = 4e-9;
  std::uint64_t seed = 1;
  nipdem::bench::parse_args(
      argc, argv,
      "bench_neighbor [--discs N=20000] [--builds K=200] [--per-body M=3] [--periodic 0|1] [--skin M=2.4e-6] "
      "[--extra-range M=4e-9] [--threads T=1] [--seed S=1]",
      {{"--discs", [&](const std::string& v) { discs = nipdem::bench::to_int(v); }},
       {"--builds", [&](const std::string& v) { builds = nipdem::bench::to_int(v); }},
       {"--per-body", [&](const std::string& v) { per_body = nipdem::bench::to_int(v); }},
       {"--periodic", [&](const std::string& v) { periodic = nipdem::bench::to_int(v); }},
       {"--skin", [&](const std::string& v) { skin = nipdem::bench::to_double(v); }},
       {"--extra-range", [&](const std::string& v) { extra = nipdem::bench::to_double(v); }},
       {"--threads", [&](const std::string& v) { threads = nipdem::bench::to_int(v); }},
       {"--seed", [&](const std::string& v) { seed = std::stoull(v); }}});
  if (discs < 1 || builds < 1 || per_body < 1 || threads < 1) {
    std::fprintf(stderr, "bench_neighbor: --discs, --builds, --per-body and --threads must be >= 1\n");
    return 2;
  }
  // Random sequential placement on a grid of trial points: area fraction about 0.6, a box 4:1.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double area = 0.0;
  std::vector<double> r(discs);
  for (auto& ri : r) { ri = 3.5e-6 + 3.75e-6 * U(rng); area += M_PI * ri * ri; }
  const double H = std::sqrt(area / 0.6 / 4.0), W = 4.0 * H;
  std::vector<double> x(discs), y(discs);
  {
    const double cell = 2.0 * 7.25e-6;
    const int nx = static_cast<int>(W / cell) + 1, ny = static_cast<int>(H / cell) + 1;
    std::vector<std::vector<int>> grid(static_cast<std::size_t>(nx) * ny);
    for (int i = 0; i < discs; ++i) {
      for (int attempt = 0;; ++attempt) {
        const double px = W * U(rng), py = H * U(rng);
        const int cx = static_cast<int>(px / cell), cy = static_cast<int>(py / cell);
        bool free = true;
        for (int a = cy - 1; a <= cy + 1 && free; ++a)
          for (int b = cx - 1; b <= cx + 1 && free; ++b) {
            if (a < 0 || a >= ny) continue;
            const int bb = (b + nx) % nx;
            for (int j : grid[static_cast<std::size_t>(a) * nx + bb]) {
              double dx = px - x[j];
              if (periodic) dx -= W * std::nearbyint(dx / W);
              const double dy = py - y[j];
              if (dx * dx + dy * dy < (r[i] + r[j]) * (r[i] + r[j]) * 0.7) { free = false; break; }
            }
          }
        if (free || attempt > 2000) {
          x[i] = px; y[i] = py;
          grid[static_cast<std::size_t>(cy) * nx + cx].push_back(i);
          break;
        }
      }
    }
  }
  {  // number the discs along x, as the nip's inflow does (bodies enter at one end, in order)
    std::vector<int> order(discs);
    for (int i = 0; i < discs; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return x[a] < x[b]; });
    std::vector<double> x2(discs), y2(discs), r2(discs);
    for (int k = 0; k < discs; ++k) { x2[k] = x[order[k]]; y2[k] = y[order[k]]; r2[k] = r[order[k]]; }
    x.swap(x2); y.swap(y2); r.swap(r2);
  }
  std::vector<int> body(discs);
  for (int i = 0; i < discs; ++i) body[i] = i / per_body;
  nipdem::geometry::NeighborListParams p;
  p.skin = skin;
  p.extra_range = extra;
  p.periodic_x = periodic != 0;
  p.x_lo = 0.0;
  p.x_hi = W;
  p.threads = threads;
  nipdem::geometry::NeighborList list;
  list.rebuild(x, y, r, body, {}, p);  // warm-up: scratch sized, first history
  std::normal_distribution<double> step(0.0, 0.05 * skin);
  double seconds = 0.0;
  std::uint64_t check = 1469598103934665603ull;
  for (int k = 0; k < builds; ++k) {
    for (int i = 0; i < discs; ++i) {
      x[i] += step(rng); y[i] += step(rng);
      if (periodic) x[i] = x[i] < 0.0 ? x[i] + W : (x[i] >= W ? x[i] - W : x[i]);
    }
    for (std::size_t e = 0; e < list.eta_.size(); ++e) list.eta_[e] = 1e-9 * static_cast<double>(e % 7);  // history to carry
    const auto t0 = std::chrono::steady_clock::now();
    list.rebuild(x, y, r, body, {}, p);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (std::size_t e = 0; e < list.nbr_.size(); ++e)  // FNV-1a over the list and its history
      check = (check ^ static_cast<std::uint64_t>(list.nbr_[e] + 7 * list.row_start_[e % list.size()] +
                                                  static_cast<std::int64_t>(list.eta_[e] * 1e10))) * 1099511628211ull;
  }
  std::printf("bench_neighbor discs=%d builds=%d per_body=%d periodic=%d skin_m=%g threads=%d box_m=%gx%g\n", discs,
              builds, per_body, periodic, skin, threads, W, H);
  std::printf("RESULT bench_neighbor pairs=%zu build_s=%.6g ns_per_disc_build=%.4g checksum=%016llx\n",
              list.pair_count(), seconds / builds, 1e9 * seconds / builds / discs,
              static_cast<unsigned long long>(check));
  return 0;
}
