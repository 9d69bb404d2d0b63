// Structure-of-arrays storage of rigid bodies (clusters) and the discs they are made of
// (thesis §2.1: a toner particle is n kinematically clustered spheres). The discs of a body
// are contiguous, so removing a body removes one index range. The engine's hot loops read
// these arrays directly; nothing here knows about toner.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

namespace nipdem {

struct BodyStore {
  // Kinematics of the centre of mass [m, m/s, rad, rad/s].
  std::vector<double> x, y, vx, vy, theta, omega;
  // cos/sin of theta, advanced with it by a rotation each step (no per-step trigonometry);
  // the disc placement reads these, theta is the accumulated angle for output.
  std::vector<double> cth, sth;
  // Total force [N] and torque about the centre of mass [N m] from the last force evaluation.
  std::vector<double> fx, fy, torque;
  std::vector<double> mass, inertia;     // [kg], [kg m^2] about the centre of mass (z axis)
  std::vector<std::int64_t> id;          // stable identity (never reused within a run; in no particular order)
  std::vector<int> first_disc, n_discs;  // discs [first_disc, first_disc + n_discs)
  std::vector<int> tag;                  // user tag (e.g. cluster template index)
  std::vector<double> size;              // user size measure (e.g. volume-equivalent diameter) [m]

  std::size_t size_n() const { return x.size(); }

  // Calls f(name, array, per) for every per-body array, in checkpoint order (per = entries per
  // body). The engine adds, removes, saves and loads bodies through this one list, so a new
  // field is declared here and in the visitor, nowhere else. Changing the order changes the
  // checkpoint format (engine/checkpoint.cpp's magic).
  template <class F> void for_each_array(F&& f) { visit(*this, f); }
  template <class F> void for_each_array(F&& f) const { visit(*this, f); }

 private:
  template <class S, class F> static void visit(S& s, F& f) {
    f("x", s.x, 1); f("y", s.y, 1); f("vx", s.vx, 1); f("vy", s.vy, 1); f("theta", s.theta, 1); f("omega", s.omega, 1);
    f("cos theta", s.cth, 1); f("sin theta", s.sth, 1); f("fx", s.fx, 1); f("fy", s.fy, 1); f("torque", s.torque, 1);
    f("mass", s.mass, 1); f("inertia", s.inertia, 1); f("size", s.size, 1);
    f("id", s.id, 1); f("first_disc", s.first_disc, 1); f("n_discs", s.n_discs, 1); f("tag", s.tag, 1);
  }
};

// Index of the first body id that repeats an earlier one, or -1 if all are distinct. Ids are
// distinct but in no particular order (the engine may reorder bodies); state read from a file
// that keys anything by id checks this.
inline long first_repeated_id(const std::vector<std::int64_t>& ids) {
  std::vector<std::pair<std::int64_t, std::size_t>> s(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) s[i] = {ids[i], i};
  std::sort(s.begin(), s.end());
  long first = -1;
  for (std::size_t k = 1; k < s.size(); ++k)
    if (s[k].first == s[k - 1].first && (first < 0 || static_cast<long>(s[k].second) < first)) first = static_cast<long>(s[k].second);
  return first;
}

// Wall contact history slots per disc: enough for a disc touching a drum, a roller face
// and the two faces of a pit at once.
inline constexpr int kWallSlots = 4;

struct DiscStore {
  std::vector<double> x, y;    // world position of the disc centre [m]
  std::vector<double> ox, oy;  // offset from the body's centre of mass in the body frame [m]
  std::vector<double> r;       // radius [m]
  std::vector<int> body;       // owning body index
  std::vector<double> wx, wy;  // current world-frame offset from the body centre of mass [m]
  // Force [N] and torque about the disc centre [N m] accumulated in one evaluation.
  std::vector<double> fx, fy, tq;
  // Adhesive part of (fx, fy) [N], for output: filled on request (Simulation::update_adhesive_parts),
  // not by each force evaluation.
  std::vector<double> fax, fay;
  // Wall contact history: key (-1 = empty), tangential stretch, sliding flag.
  std::vector<std::int64_t> wall_key;    // kWallSlots per disc
  std::vector<double> wall_eta;          // kWallSlots per disc
  std::vector<std::uint8_t> wall_slide;  // kWallSlots per disc

  std::size_t size_n() const { return x.size(); }

  // Calls f(name, array, per) for every per-disc array, in checkpoint order (per = entries per
  // disc); as BodyStore::for_each_array.
  template <class F> void for_each_array(F&& f) { visit(*this, f); }
  template <class F> void for_each_array(F&& f) const { visit(*this, f); }

 private:
  template <class S, class F> static void visit(S& s, F& f) {
    f("x", s.x, 1); f("y", s.y, 1); f("ox", s.ox, 1); f("oy", s.oy, 1); f("wx", s.wx, 1); f("wy", s.wy, 1);
    f("r", s.r, 1); f("fx", s.fx, 1); f("fy", s.fy, 1); f("tq", s.tq, 1); f("fax", s.fax, 1); f("fay", s.fay, 1);
    f("body", s.body, 1); f("wall_key", s.wall_key, kWallSlots); f("wall_eta", s.wall_eta, kWallSlots);
    f("wall_slide", s.wall_slide, kWallSlots);
  }
};

}  // namespace nipdem
