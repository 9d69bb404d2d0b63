// Boundary surfaces the discs collide with: planes, smooth cylinders (a roller modelled as one
// large disc, thesis §2.1) and cylinders carrying a periodic chain of line pieces (the
// imaging-roller roughness, §2.1, figs 2.6-2.7). A cylinder rotates about its axis at a
// prescribed angular speed; its line pieces are attached to it and move with it.
// Queries return every contact "feature" within reach of a disc: a line piece (segment) or
// a convex vertex of the chain, each with a stable key so tangential history follows the
// feature as the roller turns.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "nipdem/core/vec2.hpp"

namespace nipdem::geometry {

struct WallHit {
  std::int64_t key;   // stable feature id within this wall
  Vec2 point;         // closest point on the surface [m]
  Vec2 normal;        // unit normal from the surface towards the disc centre
  double gap;         // surface separation: distance(centre, point) - r [m] (< 0: overlap)
  Vec2 velocity;      // velocity of the surface material at `point` [m/s]
};

struct Wall {
  enum class Kind { plane, cylinder };
  Kind kind = Kind::plane;
  std::string name;
  int interaction = 0;  // index of the interaction (contact + adhesion parameters)

  // plane: point on the plane and unit normal pointing into the domain; the surface moves
  // tangentially with `surface_velocity` (a conveyor).
  Vec2 point{}, normal{0, 1};
  Vec2 surface_velocity{};

  // cylinder: axis position, radius, angular velocity (counter-clockwise positive) and
  // current rotation angle. Discs live outside (a roller) unless `inside` (a container).
  Vec2 centre{};
  double radius = 0.0;
  double omega = 0.0;
  double angle = 0.0;
  bool inside = false;

  // Optional roughness on a cylinder: one period of a closed profile given as vertices
  // (s, depth) with s the arc length along the base circle [0, period] and depth measured
  // into the cylinder (>= 0). The first and last vertex must have the same depth; the
  // profile repeats n_periods times around the circumference (period * n_periods = 2 pi R).
  std::vector<Vec2> profile;  // (s, depth) pairs [m]
  int n_periods = 0;
  double phase = 0.0;         // arc-length offset of period 0 at angle 0 [m]

  double period() const;
  bool rough() const { return !profile.empty(); }
  // Appends all features within `reach` of a disc (centre c, radius r) to hits. On a rough
  // cylinder, `hint` (optional) is the caller's memory of the disc's period: tried first, then
  // updated if it no longer holds; the hits do not depend on it (tests/unit/test_walls.cpp).
  void query(Vec2 c, double r, double reach, std::vector<WallHit>& hits, int* hint = nullptr) const;
  // Cheap conservative pre-test (inline, no trigonometry): false only if query() would find
  // nothing. The engine calls it for every disc and wall each step, query() only if true.
  bool may_touch(Vec2 c, double r, double reach) const {
    constexpr double kSlack = 1e-9;  // relative margin: never reject what query() accepts
    if (kind == Kind::plane) return dot(c - point, normal) - r <= reach + kSlack * r;
    const double d2 = norm2(c - centre);
    if (inside) {
      const double a = radius - r - reach;  // query finds nothing while |c - centre| < a
      return a <= 0.0 || d2 >= a * a * (1.0 - kSlack);
    }
    const double a = radius + r + reach;  // features lie at depth >= 0 inside the base circle
    return d2 <= a * a * (1.0 + kSlack);
  }
  // Precomputes the rotations query() needs on a rough cylinder (one sin/cos per query instead
  // of one per profile vertex). Called by set_pyramid_roughness and the engine; query() falls
  // back to direct trigonometry when the cache is missing or stale (radius or period changed).
  void prepare();
  // Caches (cos, sin) of the current angle for query(); the engine calls it (serially) before
  // each force evaluation. A query at another angle falls back to direct trigonometry.
  void prepare_angle();
  std::vector<Vec2> unit_offsets_;  // (cos, sin) of s_j / radius for each profile vertex
  Vec2 period_rotation_{1.0, 0.0};  // (cos, sin) of period / radius
  std::vector<Vec2> period_units_;  // (cos, sin) of (k P + phase) / radius, roller frame, per period
  double prepared_radius_ = 0.0, prepared_period_ = 0.0, prepared_phase_ = 0.0;
  double max_depth_ = 0.0;          // deepest profile vertex [m]
  // One period in its own frame (period start on the +x axis, origin at the centre): vertices,
  // segment vectors and 1/|segment|^2, and which vertices are convex; query() turns the disc
  // centre into that frame instead of every vertex into the world (prepare(); the profile they
  // were made from is kept, so a changed profile falls back to the direct path).
  std::vector<Vec2> local_vertex_, local_edge_;
  std::vector<double> local_inv_len2_;
  std::vector<std::uint8_t> convex_;
  std::vector<Vec2> prepared_profile_;
  Vec2 angle_rotation_{1.0, 0.0};   // (cos, sin) of angle at the last prepare_angle()
  double prepared_angle_ = std::numeric_limits<double>::quiet_NaN();
  // Advances the prescribed motion by dt.
  void advance(double dt) { angle += omega * dt; }
  // Distance from the axis of the cylinder's surface in the direction of p (radius minus the
  // profile depth there; the radius for a smooth cylinder). A point p outside a roller lies in
  // the open space iff |p - centre| > surface_radius(p).
  double surface_radius(Vec2 p) const;
  // World position of profile point (s, depth) in period k, at the current angle.
  Vec2 profile_point(int k, Vec2 sd) const;
  // Validates the geometry; throws InputError naming the wall and key.
  void validate() const;
};

// The pyramid roughness of the imaging roller cut along the diagonal (thesis §2.1, fig. 2.6):
// flat land of length `spacing`, then a V-shaped pit of width `base` and depth `height`.
// The period is adjusted so that an integer number fits the circumference; returns the
// profile and sets n_periods on the wall. See docs/geometry.md.
void set_pyramid_roughness(Wall& w, double height, double base, double spacing);

}  // namespace nipdem::geometry
