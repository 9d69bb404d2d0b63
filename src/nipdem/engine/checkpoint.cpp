// Simulation::save / load: the engine's part of a checkpoint (docs/reliability.md).
//
// Why a file of its own: the checkpoint is the one place where the engine reads data it did not
// make, so everything it reads is checked here before it replaces the state: sizes of all
// arrays against the body and disc counts, the body -> disc ranges, disc owners, the neighbour
// list's CSR structure and indices, wall history keys and finite, positive physical values. A
// damaged file must never index out of range or resume a corrupted state silently; the file
// frame's CRC (io/checkpoint_file.hpp) catches random damage, these checks catch everything a
// checksum cannot (a consistent file from a different build or a bug, a crafted file).
// On failure the Simulation is left unchanged (state is read into temporaries first), except for
// the providers' state, which is loaded last.
#include <cmath>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "nipdem/core/binary_io.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/engine/simulation.hpp"

namespace nipdem::engine {

namespace {
constexpr std::uint64_t kMagic = 0x334b43504d454450ULL;  // "PDEMPCK3" (3: body orientation cos/sin; 2: flags and renumbering saved)
using binary::get;
using binary::get_vec;
using binary::put;
using binary::put_vec;

// Prefixed with "engine state: " by load() (as are the readers' own truncation messages).
[[noreturn]] void bad(const std::string& what) { throw InputError(what); }

template <class T> void require_size(const std::vector<T>& v, std::size_t n, const char* name, const char* of) {
  if (v.size() != n) bad(fmt::format("{} has {} entries, expected {} ({})", name, v.size(), n, of));
}
void require_finite(const std::vector<double>& v, const char* name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) bad(fmt::format("{}[{}] = {} is not finite", name, i, v[i]));
}
void require_positive(const std::vector<double>& v, const char* name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!(v[i] > 0.0) || !std::isfinite(v[i])) bad(fmt::format("{}[{}] = {} is not a positive finite number", name, i, v[i]));
}
void require_flags(const std::vector<std::uint8_t>& v, const char* name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] > 1) bad(fmt::format("{}[{}] = {} is not 0 or 1", name, i, static_cast<int>(v[i])));
}
}  // namespace

void Simulation::save(std::ostream& o) const {
  put(o, kMagic);
  put(o, time_); put(o, step_); put(o, next_id_);
  const auto put_array = [&](const char*, const auto& v, std::size_t) { put_vec(o, v); };
  b_.for_each_array(put_array);
  d_.for_each_array(put_array);
  put_vec(o, nlist_.row_start_); put_vec(o, nlist_.nbr_); put_vec(o, nlist_.eta_); put_vec(o, nlist_.slide_);
  // A checkpoint taken right after bodies were added or removed (the runner's exchange) holds
  // the list of the previous numbering and the map to it: both are needed to carry the contact
  // history over exactly as the uninterrupted run does, and the forces must then be recomputed.
  put(o, static_cast<std::uint8_t>(structure_changed_));
  put(o, static_cast<std::uint8_t>(forces_valid_));
  put_vec(o, old_of_new_);
  const std::uint64_t nw = walls_.size();
  put(o, nw);
  for (const auto& w : walls_) put(o, w.angle);
  const std::uint64_t np = prov_fx_.size();
  put(o, np);
  for (std::size_t k = 0; k < np; ++k) { put_vec(o, prov_fx_[k]); put_vec(o, prov_fy_[k]); put_vec(o, prov_tq_[k]); }
  put(o, n_contacts_);
  for (const auto& f : forces_) f->save(o);
}

void Simulation::load(std::istream& in) try {
  std::uint64_t magic;
  get(in, magic);
  if (magic != kMagic) bad("not the engine state this build writes (bad engine magic)");
  double time;
  std::int64_t step, next_id;
  get(in, time); get(in, step); get(in, next_id);
  if (!std::isfinite(time) || time < 0.0) bad(fmt::format("time {} s is not a finite number >= 0", time));
  if (step < 0) bad(fmt::format("step count {} < 0", step));

  BodyStore b;
  DiscStore d;
  b.for_each_array([&](const char* name, auto& v, std::size_t) { get_vec(in, v, ("body " + std::string(name)).c_str()); });
  d.for_each_array([&](const char* name, auto& v, std::size_t) { get_vec(in, v, ("disc " + std::string(name)).c_str()); });
  std::vector<int> row_start, nbr, old_of_new;
  std::vector<double> eta;
  std::vector<std::uint8_t> slide;
  get_vec(in, row_start, "neighbour row_start"); get_vec(in, nbr, "neighbour nbr"); get_vec(in, eta, "neighbour eta");
  get_vec(in, slide, "neighbour slide");
  std::uint8_t structure_changed, forces_valid;
  get(in, structure_changed); get(in, forces_valid);
  if (structure_changed > 1 || forces_valid > 1) bad("state flags are not 0 or 1");
  get_vec(in, old_of_new, "disc renumbering");

  // ---- bodies and discs: every array sized by the count of its first, every double finite ----
  const std::size_t nb = b.x.size(), nd = d.x.size();
  b.for_each_array([&](const char* name, const auto& v, std::size_t per) {
    const std::string what = "body " + std::string(name);
    require_size(v, nb * per, what.c_str(), "body count from body x");
    if constexpr (std::is_same_v<typename std::decay_t<decltype(v)>::value_type, double>) require_finite(v, what.c_str());
  });
  d.for_each_array([&](const char* name, const auto& v, std::size_t per) {
    const std::string what = "disc " + std::string(name);
    require_size(v, nd * per, what.c_str(), "disc count from disc x");
    if constexpr (std::is_same_v<typename std::decay_t<decltype(v)>::value_type, double>) require_finite(v, what.c_str());
  });
  for (std::size_t i = 0; i < nb; ++i)  // a unit vector (kept so by the engine's renormalisation)
    if (!(std::fabs(b.cth[i] * b.cth[i] + b.sth[i] * b.sth[i] - 1.0) < 1e-9))
      bad(fmt::format("body orientation {} (cos {}, sin {}) is not a unit vector", i, b.cth[i], b.sth[i]));
  require_positive(b.mass, "body mass");
  require_positive(b.inertia, "body inertia");
  if (next_id < static_cast<std::int64_t>(nb)) bad(fmt::format("next body id {} < body count {}", next_id, nb));
  for (std::size_t i = 0; i < nb; ++i)
    if (b.id[i] < 0 || b.id[i] >= next_id) bad(fmt::format("body id[{}] = {} is not within [0, {})", i, b.id[i], next_id));
  if (const long k = first_repeated_id(b.id); k >= 0) bad(fmt::format("body id[{}] = {} repeats an earlier body's", k, b.id[k]));
  require_positive(d.r, "disc r");
  require_flags(d.wall_slide, "disc wall_slide");
  for (std::size_t k = 0; k < d.wall_key.size(); ++k) {
    const std::int64_t key = d.wall_key[k];
    if (key != -1 && (key < 0 || (key >> 40) >= static_cast<std::int64_t>(walls_.size())))
      bad(fmt::format("disc wall_key[{}] = {} names no wall of this configuration ({} walls)", k, key, walls_.size()));
  }
  // Body -> disc ranges: contiguous, in order, covering every disc once, owners matching.
  std::size_t next_disc = 0;
  for (std::size_t i = 0; i < nb; ++i) {
    if (b.first_disc[i] < 0 || static_cast<std::size_t>(b.first_disc[i]) != next_disc || b.n_discs[i] < 1 ||
        static_cast<std::size_t>(b.n_discs[i]) > nd - next_disc)
      bad(fmt::format("body {} has discs [{}, {} + {}), expected a range starting at {} within {} discs", i, b.first_disc[i],
                      b.first_disc[i], b.n_discs[i], next_disc, nd));
    for (int k = 0; k < b.n_discs[i]; ++k)
      if (d.body[next_disc + k] != static_cast<int>(i))
        bad(fmt::format("disc {} is owned by body {}, but lies in the range of body {}", next_disc + k, d.body[next_disc + k], i));
    next_disc += static_cast<std::size_t>(b.n_discs[i]);
  }
  if (next_disc != nd) bad(fmt::format("bodies own {} discs, the state has {}", next_disc, nd));
  // ---- neighbour list (CSR over the numbering of its last build) ----
  std::size_t rows = 0;
  if (!row_start.empty()) {
    rows = row_start.size() - 1;
    if (row_start[0] != 0) bad(fmt::format("neighbour row_start[0] = {}, expected 0", row_start[0]));
    for (std::size_t i = 0; i < rows; ++i)
      if (row_start[i + 1] < row_start[i]) bad(fmt::format("neighbour row_start is not monotone at row {}", i));
    if (static_cast<std::size_t>(row_start.back()) != nbr.size())
      bad(fmt::format("neighbour row_start ends at {}, the list holds {} pairs", row_start.back(), nbr.size()));
    for (std::size_t i = 0; i < rows; ++i)
      for (int k = row_start[i]; k < row_start[i + 1]; ++k) {
        const int j = nbr[k];
        if (j <= static_cast<int>(i) || static_cast<std::size_t>(j) >= rows || (k > row_start[i] && j <= nbr[k - 1]))
          bad(fmt::format("neighbour nbr[{}] = {} in row {} is not increasing within ({}, {})", k, j, i, i, rows));
      }
  } else if (!nbr.empty()) {
    bad("neighbour list has pairs but no rows");
  }
  require_size(eta, nbr.size(), "neighbour eta", "pair count");
  require_size(slide, nbr.size(), "neighbour slide", "pair count");
  require_finite(eta, "neighbour eta");
  require_flags(slide, "neighbour slide");
  require_size(old_of_new, nd, "disc renumbering", "disc count");
  for (std::size_t i = 0; i < nd; ++i) {
    const int o = old_of_new[i];
    if (structure_changed ? (o < -1 || o >= static_cast<int>(rows)) : o != static_cast<int>(i))
      bad(fmt::format("disc renumbering[{}] = {} is out of range (list of {} rows{})", i, o, rows,
                      structure_changed ? "" : ", unchanged structure: identity expected"));
  }
  if (!structure_changed && rows != nd)
    bad(fmt::format("neighbour list has {} rows for {} discs although nothing was added or removed since its build", rows, nd));
  // ---- walls, providers ----
  std::uint64_t nw;
  get(in, nw);
  if (nw != walls_.size())
    bad(fmt::format("{} walls, the configuration has {}", nw, walls_.size()));
  std::vector<double> angle(walls_.size());
  for (auto& a : angle) {
    get(in, a);
    if (!std::isfinite(a)) bad("a wall angle is not finite");
  }
  std::uint64_t np;
  get(in, np);
  if (np != prov_fx_.size())
    bad(fmt::format("{} force providers, the configuration has {}", np, prov_fx_.size()));
  std::vector<std::vector<double>> pfx(np), pfy(np), ptq(np);
  for (std::size_t k = 0; k < np; ++k) {
    get_vec(in, pfx[k], "provider fx"); get_vec(in, pfy[k], "provider fy"); get_vec(in, ptq[k], "provider torque");
    for (auto* v : {&pfx[k], &pfy[k], &ptq[k]}) {
      require_size(*v, nb, "a provider force array", "body count");
      require_finite(*v, "a provider force array");
    }
  }
  std::int64_t n_contacts;
  get(in, n_contacts);
  if (n_contacts < 0) bad(fmt::format("contact count {} < 0", n_contacts));

  // ---- commit ----
  time_ = time; step_ = step; next_id_ = next_id;
  b_ = std::move(b);
  d_ = std::move(d);
  nlist_.row_start_ = std::move(row_start); nlist_.nbr_ = std::move(nbr);
  nlist_.eta_ = std::move(eta); nlist_.slide_ = std::move(slide);
  for (std::size_t w = 0; w < walls_.size(); ++w) walls_[w].angle = angle[w];
  for (std::size_t k = 0; k < np; ++k) { prov_fx_[k] = std::move(pfx[k]); prov_fy_[k] = std::move(pfy[k]); prov_tq_[k] = std::move(ptq[k]); }
  n_contacts_ = n_contacts;
  // The list is rebuilt at the next evaluation (its reference positions are not saved), with
  // the saved renumbering if bodies changed since its build; forces of the saved state are in
  // the body arrays if they were valid when it was saved.
  old_of_new_ = std::move(old_of_new);
  body_set_changed();
  simple_valid_ = false;
  forces_valid_ = forces_valid != 0;
  for (auto& f : forces_) f->load(in);
} catch (const InputError& e) {
  throw InputError(std::string("engine state: ") + e.what());
}

}  // namespace nipdem::engine
