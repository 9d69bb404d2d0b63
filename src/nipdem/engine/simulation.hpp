// The DEM step loop for rigid clusters of discs between prescribed moving walls.
// Knows nothing of toner or printers: physics beyond contacts, adhesion and gravity comes in
// through BodyForce providers (magnet, electric field, ...), set up by experiments/.
//
// Design notes
//  - Forces are accumulated per disc (force + torque about the disc centre) in one pair loop
//    over a half Verlet list, then reduced per body. The rows are split into
//    EngineParams::threads parts; a part writes its own discs, and its forces on partners in
//    later parts go to slots of their own, summed per part in part order: a run is bitwise
//    reproducible for a given part count, however many threads run the parts.
//  - A pair contributes nothing unless it interacts, and history is reset the moment a
//    contact opens, so results do not depend on when the neighbour list was rebuilt: this
//    is what makes checkpoint/resume bitwise exact. The same holds for the pair kernel's
//    per-step sublist of the list (EngineParams::inner_skin_fraction) and for the skins per
//    disc both are taken with (EngineParams::skin_speed_quantile).
//  - Bodies are added/removed/reordered between steps; the neighbour list is rebuilt with the
//    index mapping so tangential history survives renumbering. The engine never reorders on its
//    own: a caller that changes the body set anyway (the nip's inflow/outflow pass) sorts then
//    (sort_bodies_spatially), at moments fixed by the run, so a resumed run sorts at the same steps.
#pragma once
#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <iosfwd>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "nipdem/core/particles.hpp"
#include "nipdem/core/vec2.hpp"
#include "nipdem/engine/block_steal.hpp"
#include "nipdem/engine/team_tuner.hpp"
#include "nipdem/geometry/neighbor_list.hpp"
#include "nipdem/geometry/walls.hpp"
#include "nipdem/models/contact.hpp"
#include "nipdem/models/hamaker.hpp"

namespace nipdem::engine {

enum class Integrator {
  velocity_verlet,   // second order, symplectic without damping
  newmark_explicit,  // thesis eq. 4.2.15 with xi = theta = 0 (first order)
};

// Contact + adhesion parameters of one kind of interaction (e.g. toner-drum).
struct Interaction {
  std::string name;
  models::ContactParams contact;
  models::HamakerParams adhesion;
};

// An external force on bodies (magnet, electric field, drag, ...). add() is called once per
// force evaluation and adds to the per-body arrays (cleared before each evaluation); it must
// not resize them. The BodyStore's force sums are not complete during add(): the engine adds
// all providers' arrays to them after the last add().
class BodyForce {
 public:
  virtual ~BodyForce() = default;
  virtual std::string name() const = 0;
  virtual void add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
                   std::span<double> torque) = 0;
  // State the provider carries between evaluations (held forces, charges, counters), saved
  // with the engine's checkpoint so that a resumed run is bitwise identical.
  virtual void save(std::ostream&) const {}
  virtual void load(std::istream&) {}
  // Threads the engine runs its own loops with in this evaluation (its measured choice,
  // EngineParams::run_threads), set before add(); 0 if add() is called from elsewhere. A
  // provider that splits its work into a fixed number of parts may run them on this many
  // threads, so that it gives way on a contended machine as the engine does, with the same results.
  int running_threads() const { return running_threads_; }
  void set_running_threads(int n) { running_threads_ = n; }
  // Per-body force arrays a provider keeps between evaluations (e.g. the magnet's forces of its
  // last field pass, held for several steps) may be added by the engine in its own pass over
  // the bodies instead of by add() in a pass (a parallel region) of its own. The engine sets
  // hand_held(true) before add(); a provider that takes it up leaves those terms out of add()
  // and returns them from held() after it. The engine then adds, per body, the provider's
  // array value + term 0 + term 1 (the same operations as add() adding them into the cleared
  // array, so the same bits) and stores that sum back in the provider's array.
  struct Held {
    static constexpr int kMaxTerms = 2;
    std::array<const double*, kMaxTerms> fx{}, fy{};  // [N] per body, valid until the next add()
    int terms = 0;
  };
  virtual Held held() const { return {}; }
  bool hand_held() const { return hand_held_; }
  void set_hand_held(bool on) { hand_held_ = on; }
  // A number the engine changes whenever its bodies are added, removed or reordered (unique in
  // the process, never 0), set before add() and 0 after it; 0 = unknown (a direct call). A
  // provider that keeps values per body may take an unchanged number for an unchanged body set
  // instead of comparing the ids at every call.
  std::uint64_t body_set_version() const { return body_set_version_; }
  void set_body_set_version(std::uint64_t v) { body_set_version_ = v; }
  // Whether add() reads what the engine's contact forces of the same step write (the contact
  // network, the discs' forces, the contact count). A provider whose add() reads only bodies,
  // discs' positions and time may say false: the engine then calls it before the contact forces
  // of a step and adds its forces (and the closing half kick) in their pass over the bodies,
  // one parallel region per step fewer, with the same operations in the same order.
  virtual bool reads_contacts() const { return true; }

 private:
  int running_threads_ = 0;
  bool hand_held_ = false;
  std::uint64_t body_set_version_ = 0;
};

struct EngineParams {
  Integrator integrator = Integrator::velocity_verlet;
  double dt = 1e-9;                         // time step [s]
  Vec2 gravity{};                           // [m/s^2]
  std::vector<Interaction> interactions;    // [0] is disc-disc; walls refer to the others
  double skin = 1e-6;                       // Verlet skin [m]
  // The pair kernel tests at each step only the listed pairs within their range plus this
  // fraction of the skin: a sublist of the Verlet list, taken again when the two largest
  // displacements since it was taken add up to that margin (docs/performance.md, sixth pass).
  // Outputs do not depend on it (the same pairs interact, summed in the same order); 0 = off.
  double inner_skin_fraction = 0.25;
  // Skins per disc (geometry::NeighborList): at each list build, a disc faster than this
  // quantile of the disc speeds gets a skin in proportion to its speed (at most kMaxSkinFactor
  // times its share skin/2), so that the list lasts about as long as skin/2 lasts a disc at the
  // quantile, not as long as the skin lasts the two fastest (docs/performance.md, twelfth
  // pass). Outputs do not depend on it (the same pairs interact); 0 = one skin for all.
  double skin_speed_quantile = 0.9;
  static constexpr double kMaxSkinFactor = 4.0;
  bool periodic_x = false;                  // periodic box along x
  double x_lo = 0.0, x_hi = 0.0;            // its extent [m]
  int threads = 1;                          // OpenMP threads for the force loops
  // How many of them run: 0 = chosen by measurement, all or 1, whichever runs the steps faster
  // (another job may hold a core; engine/team_tuner.hpp), else that many (1..threads). The work is
  // always split into `threads` parts summed in one order: the choice changes speed, not results.
  int run_threads = 0;
};

// Shape and state of a body to add. Disc offsets are relative to any reference point; the
// engine moves them to the centre of mass. Mass and inertia follow from the member spheres
// (each a solid sphere of its radius, parallel-axis theorem), or discs if !sphere_inertia.
struct BodySpec {
  std::vector<Vec2> offsets;    // [m]
  std::vector<double> radii;    // [m]
  double density = 0.0;         // [kg/m^3]
  bool sphere_inertia = true;
  Vec2 position{};              // centre of mass [m]
  double angle = 0.0;           // [rad]
  Vec2 velocity{};              // [m/s]
  double omega = 0.0;           // [rad/s]
  int tag = 0;
  double size = 0.0;            // caller's size measure [m]
};

// Mass [kg], centre of mass [m] (in the frame of the spec's offsets) and moment of inertia about
// it [kg m^2] of a body spec: each member a solid sphere of its radius (thesis §2.1), or a disc
// if !sphere_inertia, combined by the parallel-axis theorem. The one place a cluster's mass is
// computed; add_body uses it.
struct MassProperties {
  double mass = 0.0;
  Vec2 com{};
  double inertia = 0.0;
};
MassProperties mass_properties(const BodySpec& spec);

struct Energy {
  double kinetic = 0.0;   // translational + rotational [J]
  double elastic = 0.0;   // normal + tangential springs of open contacts [J]
  double gravity = 0.0;   // -m g.x [J]
  double total() const { return kinetic + elastic + gravity; }
};

class Simulation {
 public:
  Simulation(EngineParams params, std::vector<geometry::Wall> walls);

  // Adds a body; returns its index (valid until bodies are removed).
  int add_body(const BodySpec& spec);
  // Removes every body for which pred(index) is true; returns how many.
  std::size_t remove_bodies_if(const std::function<bool(int)>& pred);
  // Reorders the bodies (and their discs): new index k holds the body that was at order[k], a
  // permutation of [0, bodies). Everything kept by index moves along (contact histories, the
  // providers' last forces); the neighbour list is rebuilt at once. Forces stay valid: the next
  // step is the same motion, its sums taken in the new order (equal up to rounding).
  void permute_bodies(std::span<const int> order);
  // Puts the bodies in spatial order, for memory locality in the pair loops and a thread split
  // whose rows touch few discs beyond their own: strips strip_m wide in x (from the leftmost
  // centre), by y within a strip, ties in the present order. Deterministic for a given state.
  void sort_bodies_spatially(double strip_m);
  void add_force(std::shared_ptr<BodyForce> f);

  // Advances one time step (forces are (re)evaluated as needed).
  void step();
  // Evaluates forces for the current state without moving anything.
  void compute_forces();
  // Fills discs().fax, fay with the adhesive (Hamaker) part of each disc's force at the present
  // positions (evaluating the forces first if they are not valid). step() does not keep them:
  // call this before reading them (frames, Python's fx_adhesion).
  void update_adhesive_parts();

  double time() const { return time_; }
  std::int64_t step_count() const { return step_; }
  const EngineParams& params() const { return params_; }
  EngineParams& mutable_params() { return params_; }
  BodyStore& bodies() { return b_; }
  const BodyStore& bodies() const { return b_; }
  DiscStore& discs() { return d_; }
  const DiscStore& discs() const { return d_; }
  std::vector<geometry::Wall>& walls() { return walls_; }
  const std::vector<geometry::Wall>& walls() const { return walls_; }
  const geometry::NeighborList& neighbor_list() const { return nlist_; }
  // How often the pair kernel's per-step sublist was taken (EngineParams::inner_skin_fraction).
  int pair_sublist_builds() const { return sub_takes_; }
  // The sublist's margins per disc, g_i = inner_skin_fraction x the disc's skin share (empty
  // with one skin for all); for tests.
  const std::vector<double>& pair_sublist_margins() const { return sub_g_; }
  // List entries whose partner lies in a later part than their row (their forces go through the
  // cross slots), for the list and part split of the last force evaluation; 0 with one part.
  std::int64_t pair_cross_entries() const { return cross_count_; }
  const std::vector<std::shared_ptr<BodyForce>>& forces() const { return forces_; }
  // Per-provider force on each body from the last evaluation (for output) [N].
  const std::vector<double>& provider_fx(std::size_t k) const { return prov_fx_[k]; }
  const std::vector<double>& provider_fy(std::size_t k) const { return prov_fy_[k]; }
  const std::vector<double>& provider_torque(std::size_t k) const { return prov_tq_[k]; }  // [N m]
  // Number of disc-disc and disc-wall contacts (overlap > 0) in the last evaluation.
  std::int64_t contacts() const { return n_contacts_; }
  // The thread-count choice (EngineParams::run_threads): threads in use, probes and switches so far.
  const TeamTuner& team_tuner() const { return tuner_; }

  Energy energy() const;
  // Serialises the complete dynamic state (bodies, discs, histories, walls, time).
  void save(std::ostream& out) const;
  void load(std::istream& in);

 private:
  void place_body(std::size_t b);
  void pack_disc(int i);
  void update_disc_positions(std::size_t b0, std::size_t b1);
  bool ensure_neighbor_list(int moved);  // true if it rebuilt the list
  void list_displacements(double& d1, double& d2, double& l1) const;
  void choose_skins();  // half_skin_ for the next list build (EngineParams::skin_speed_quantile)
  // kick_h > 0: also the closing half kick of velocity Verlet, body by body as its force is summed
  // (step() without force providers: one parallel region fewer per step); packed: step() has
  // already made the pair kernel's copy of the discs (pdisc_) from the present state
  // providers: call_providers() has run, and the body phase adds their forces before the kick
  // (step() when no provider reads_contacts(): the provider loop's region goes)
  void contact_forces(double kick_h = 0.0, bool packed = false, bool providers = false);
  void prepare_walls();
  void wall_disc(std::size_t i, std::uint32_t mask, std::vector<geometry::WallHit>& hits, std::int64_t& nc);
  std::uint32_t walls_near(std::size_t i, double margin, std::vector<geometry::WallHit>& hits);  // (updates wall_hint_)
  bool walls_within_margin() const;
  void reduce_bodies(std::size_t b0, std::size_t b1);  // disc forces into body sums (+ gravity)
  void provider_forces(double kick_h);  // call_providers(), then their sums (and kick) per body
  void call_providers();  // each provider's add() into its cleared arrays, held_ from it
  void add_provider_forces(std::size_t b0, std::size_t b1);  // into the bodies' sums, held terms stored back
  void update_thread_split();
  void build_wall_candidates();
  struct WallShape {
    int kind; double px, py, nx, ny, cx, cy, radius; int inside; double reach, skin;
    bool operator==(const WallShape&) const = default;
  };
  WallShape shape_of(std::size_t wall) const;  // what the candidate masks depend on
  bool wall_shapes_changed() const;

  // Hot-loop copies of the per-disc data the pair kernel reads, packed so that one neighbour
  // costs two cache lines to read and one to write instead of ~12 scattered SoA loads
  // (docs/performance.md). Rebuilt from the SoA stores at every force evaluation.
  // centre [m], radius [m], body mass [kg], disc-centre velocity [m/s], body spin [rad/s]: one
  // cache line, so a scattered partner costs one line, not two (docs/performance.md, 22nd pass)
  struct alignas(64) PackedDisc { double x, y, r, m, vx, vy, w, pad; };
  struct alignas(32) PackedForce { double fx, fy, tq, pad; };
  // One entry of the per-step sublist: the Verlet list entry and its two discs.
  struct SubEntry { int e, i, j; };
  // kCross: rows before the last part's, whose partners from i1 on go to their cross slots.
  // kList: 0 = test every entry of rows [i0, i1); 1 = the same, and take the sublist of those
  // rows into sub/sub_n (and with kCross the places of its cross entries into xs/xs_n, room for
  // the part's cross entries + 1); 2 = test only the sublist sub[0, sub_n).
  template <bool kAdhesion, bool kPeriodic, int kList, bool kCross>
  void pair_rows(int i0, int i1, PackedForce* f, std::int64_t& nc, SubEntry* sub, int& sub_n, int* xs, int& xs_n);
  // The pair sums of discs [k0, k1) (a block of bodies) into d_.fx/fy/tq, the buffers cleared.
  void reduce_pair_sums(int k0, int k1);
  bool sublist_moved() const;  // two largest displacements since the sublist exceed its margin

  EngineParams params_;
  std::vector<geometry::Wall> walls_;
  BodyStore b_;
  DiscStore d_;
  geometry::NeighborList nlist_;
  geometry::NeighborListParams nl_params_;
  std::vector<int> old_of_new_;  // disc renumbering since the last list build
  std::vector<double> half_skin_, speed_;  // per disc: skin of its own [m], speed (scratch) [m/s]
  bool structure_changed_ = true;
  // Bodies added, removed or reordered: structure_changed_, and a new body_set_version_.
  void body_set_changed();
  std::uint64_t body_set_version_ = 0;
  bool forces_valid_ = false;
  std::vector<std::shared_ptr<BodyForce>> forces_;
  std::vector<std::vector<double>> prov_fx_, prov_fy_, prov_tq_;
  std::vector<BodyForce::Held> held_;  // per provider, the held terms of its last add()
  std::vector<PackedDisc> pdisc_;
  // Pair-force sums per disc, one buffer for all parts: a part writes only its own discs there.
  std::vector<PackedForce> pforce_;
  // contact_forces()' per-body phase: blocks of kBodyBlock bodies, shared out by stealing
  static constexpr int kBodyBlock = 256;
  BlockSteal body_blocks_;
  // Part t (of EngineParams::threads) owns list rows [split_[t], split_[t+1]) and writes its own
  // discs. A listed partner beyond its rows (j >= split_[t+1]: the next part, or across a
  // periodic seam the far end of the order) is a cross entry: its force on j goes into a slot of
  // its own (cross_val_[cross_slot_[e]]), and the per-body phase sums the slots of disc j per
  // part in entry order, parts in order, then adds j's own part's sum: the same operations in the
  // same order as when each part had a buffer of all discs (one thread running several parts
  // reads one buffer, not one per part). Part t's slots are [rs[split_[t]], +its cross count),
  // sorted by the block of 2^kTouchShift discs their disc is in (entry order within a block);
  // cross_block_[t * (touch_blocks_ + 2) + b] is the first slot of block b. Every slot is zero
  // between steps (the per-body phase clears what it reads).
  struct CrossForce { double fx, fy, tq; };
  static constexpr int kTouchShift = 6;
  std::vector<int> split_;
  int touch_blocks_ = 0;
  std::vector<int> cross_slot_;         // per list entry: its slot, if a cross entry
  std::vector<int> cross_disc_;         // per slot: the disc j it acts on
  std::vector<CrossForce> cross_val_;   // per slot: the pair's force on i (fx, fy) and torque on j
  std::vector<int> cross_block_;        // per part: block offsets into its slots
  std::int64_t cross_count_ = 0;        // cross entries of the list in use (all parts)
  std::vector<int> entry_row_;  // the list row (disc i) of each list entry, for the flat pair loop
  std::vector<std::int64_t> thread_nc_;
  std::vector<double> inv_mass_, inv_inertia_, dtheta_;  // per body, 1/m, 1/I and the rotation of this step (scratch of step())
  std::vector<double> thread_disp_;  // per thread: two largest squared disc displacements
  int split_builds_ = -1, split_threads_ = 0;
  // Per-thread wall query scratch, each on cache lines of its own: the queries write the
  // vector's end pointer, and two threads writing one line take it from each other at every
  // query (false sharing: the walls' part of the step cost 1.5x the CPU time on two threads).
  struct alignas(64) ThreadHits {
    std::vector<geometry::WallHit> v;
  };
  std::vector<ThreadHits> thread_hits_;
  std::vector<std::exception_ptr> thread_fail_;              // per thread: first failure of its wall queries
  std::vector<double> wall_reach_;                          // adhesion reach of each wall [m]
  std::vector<std::uint32_t> wall_mask_;                    // per disc: walls it may touch until the next list build
  std::vector<WallShape> wall_shape_;                       // wall shapes the masks were built for
  std::vector<int> wall_hint_;                              // per disc and wall: period hint for Wall::query
  double time_ = 0.0;
  std::int64_t step_ = 0;
  std::int64_t next_id_ = 0;
  std::int64_t n_contacts_ = 0;
  TeamTuner tuner_;
  int tuner_threads_ = 0, tuner_fixed_ = -1;  // the params the tuner was set up for
  int team();                                 // threads to run the loops of this step with
  double pair_reach_ = 0.0;  // max adhesion cut-off of disc-disc interaction
  // The per-step sublist (EngineParams::inner_skin_fraction): per row chunk of the thread
  // split, its entries, and what it was taken for (list build, threads, reach, margin, positions).
  std::vector<std::vector<SubEntry>> sub_;
  std::vector<int> sub_n_;
  std::vector<std::vector<int>> subx_;  // per part: the places of the sublist's cross entries
  std::vector<int> subx_n_;
  std::vector<double> sub_x0_, sub_y0_;
  std::vector<std::uint32_t> wall_near_;  // per disc: candidate walls within reach + margin when taken
  std::vector<double> sub_wall_angle_;    // wall angles when taken
  bool sub_valid_ = false;
  int sub_moved_ = -1;  // set by step(): 0/1 = checked in its drift loop, -1 = unknown
  int sub_builds_ = -1, sub_threads_ = 0, sub_takes_ = 0;
  double sub_reach_ = -1.0, sub_margin_ = 0.0;
  double sub_disp2(std::size_t k) const {
    double dx = d_.x[k] - sub_x0_[k];
    const double dy = d_.y[k] - sub_y0_[k];
    if (params_.periodic_x) {  // a disc that crossed the periodic boundary moved by about +-L
      const double L = params_.x_hi - params_.x_lo;
      dx = dx > 0.5 * L ? dx - L : dx;
      dx = dx < -0.5 * L ? dx + L : dx;
    }
    return dx * dx + dy * dy;
  }
  // True if two discs may have closed the margin since the sublist was taken: twice the largest
  // squared displacement m. Reached a little early (0.99), so that rounding in the displacements
  // never lets a pair left out of the sublist come into range unseen. (Twice the largest, not the
  // two largest as for the list: the sublist is cheap to take again, and a plain max vectorises.)
  // With margins per disc (skins per disc: NeighborList::per_disc), m is the largest squared
  // displacement weighted by sub_w_, 1 / (0.99 g_i)^2, each disc's margin g_i = inner_skin_fraction
  // h_i (its share of a pair's margin g_i + g_j): true if some disc moved more than 0.99 g_i.
  bool sub_exceeds(double m) const {
    return sub_per_disc_ ? !(m <= 1.0) : !(2.0 * std::sqrt(m) <= 0.99 * sub_margin_);  // (NaN: true)
  }
  // Bodies that are one disc at their centre of mass ("simple": a packing's grains) need no
  // placement by rotation: step() copies a block of them at once. simple_prefix_[b]: how many
  // of bodies [0, b) are simple (a block is simple if all its bodies are); rebuilt when the
  // body set changes.
  std::vector<int> simple_prefix_;
  bool simple_valid_ = false;
  void update_simple();
  bool sub_per_disc_ = false;
  // Whether the list has room for the sublist's margins at this step's evaluation: 1 if every
  // disc may still move its margin g_i (or, one skin, two discs the whole margin) without
  // leaving the list's skin, 0 if not, -1 unknown (set by step() and compute_forces()). A
  // sublist taken with room holds only while every disc stays within its margin of where it
  // was, so the list holds too and step() checks only the sublist (list_check_ = false).
  int list_room_ = -1;
  bool list_check_ = true;
  std::vector<double> sub_g_, sub_w_;  // per disc: margin g_i [m], 1 / (0.99 g_i)^2 [1/m^2]
  int sub_g_builds_ = -1;              // the list build they were made for
  double sub_g_fraction_ = 0.0;        // and the inner_skin_fraction
};

}  // namespace nipdem::engine
