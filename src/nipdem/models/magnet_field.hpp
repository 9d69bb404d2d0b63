// Magnet field sources: B [T] and its gradient dB_i/dx_j [T/m] at a point of the 2D process plane.
//
// Frame (the "magnet frame"): x along the process direction, origin at the magnet edge (the knife's
// sharp edge) projected on the imaging-roller surface, positive towards the supply roller; y points
// away from the roller into the gap (the roller surface is y = 0 locally, the magnet lies at y < 0).
// The magnet does not rotate with the sleeve. The engine maps particle positions into this frame
// (see PlacedField for a rigid placement).
//
// Why an interface with one virtual call per particle: the engine asks once per particle per step
// (~1e4 particles); a virtual call is ~1 ns next to the ~100 ns of the field formula, and it lets an
// analytic assembly and an imported FEM map (io/field_map.hpp) be swapped by configuration.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "nipdem/core/vec2.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::magnet {

// 2x2 matrix; as a field gradient, xy = dB_x/dy etc. (row = component, column = derivative).
struct Mat2 {
  double xx = 0.0, xy = 0.0, yx = 0.0, yy = 0.0;
};
inline Vec2 operator*(const Mat2& g, Vec2 v) { return {g.xx * v.x + g.xy * v.y, g.yx * v.x + g.yy * v.y}; }

// One evaluation of a field source.
struct Sample {
  Vec2 B;    // flux density [T]
  Mat2 dB;   // gradient dB_i/dx_j [T/m]
};

class MagnetField {
 public:
  virtual ~MagnetField() = default;
  // Field at p [m] in the magnet frame. May throw InputError when p lies outside the source's domain
  // (a field map); analytic sources are defined everywhere.
  virtual Sample at(Vec2 p) const = 0;
  // One line saying what the source is (for output headers and logs).
  virtual std::string describe() const = 0;
  // False if the field may be discontinuous (a magnet face: tangential B jumps by mu0 M) inside
  // the closed box [lo, hi]; an interpolating table must not span such a box.
  virtual bool smooth_in(Vec2 /*lo*/, Vec2 /*hi*/) const { return true; }
  // Cross-sections of the magnet material (polygons, [m]), where the field is not a field a toner
  // can feel: empty if the source does not know its material (a field map).
  virtual std::vector<std::vector<Vec2>> material() const { return {}; }
};

// Force on a point dipole m [A m^2] in the field sample: F = (m . grad) B [N] (eq. 2.4.28/2.4.34).
inline Vec2 dipole_force(Vec2 m, const Sample& s) { return s.dB * m; }

// Force [N] on a toner sphere of radius R [m] whose moment is induced by the sampled field through
// the magnetisation curve: m = m(B) of eq. 4.5.1, F = (m . grad) B (eq. 2.4.34). For a curl-free field
// this equals |m(B)| grad|B|, i.e. it points up the gradient of |B|.
inline Vec2 induced_dipole_force(const MagnetisationParams& p, double radius_m, const Sample& s) {
  return dipole_force(induced_moment(p, radius_m, s.B), s);
}

// A uniformly magnetised, infinitely long (along z) prism with a simple polygonal cross-section.
struct MagnetBlock {
  std::vector<Vec2> vertices_m;  // polygon vertices [m], either orientation, no self-intersection
  Vec2 magnetisation_A_per_m;    // uniform magnetisation M [A/m] in the plane

  // Block from its remanence B_r = mu0 M [T] (the usual catalogue figure of a permanent magnet).
  static MagnetBlock from_remanence(std::vector<Vec2> vertices_m, Vec2 Br_T);
};

// Sum of uniformly magnetised polygonal prisms: exact 2D closed form.
//
// Each block is replaced by its magnetisation surface current K = M x n on every edge (a current
// sheet along z). With f(z) = B_x - i B_y, z = x + i y, an edge from a to b with unit tangent
// t = e^{i phi} contributes
//     f(z) = -i mu0 K / (2 pi) * conj(t) * Log((z - a)/(z - b)),
//     f'(z) = -i mu0 K / (2 pi) * conj(t) * (1/(z - a) - 1/(z - b)),
// so B is exact everywhere (inside the blocks too) and the gradient follows analytically from
// f'(z): dBx/dx = Re f', dBy/dx = -Im f', dBx/dy = dBy/dx, dBy/dy = -dBx/dx (curl- and
// divergence-free by construction). The field is singular (log) on block corners, as it should be.
class BlockAssembly final : public MagnetField {
 public:
  // Validates every block (>= 3 finite vertices, non-zero area, no self-intersection, finite
  // |M| <= 1e7 A/m, i.e. |B_r| <= 12.6 T) and throws InputError naming block and key otherwise.
  explicit BlockAssembly(std::vector<MagnetBlock> blocks, std::string name = "block assembly");
  Sample at(Vec2 p) const override;
  std::string describe() const override;
  bool smooth_in(Vec2 lo, Vec2 hi) const override;  // no block edge touches the box
  std::vector<std::vector<Vec2>> material() const override;
  const std::vector<MagnetBlock>& blocks() const { return blocks_; }

 private:
  struct Edge {
    double ax, ay, bx, by;  // end points [m]
    double cr, ci;          // complex coefficient -i mu0 K/(2 pi) conj(t) [T]
  };
  std::vector<MagnetBlock> blocks_;
  std::vector<Edge> edges_;  // only edges that carry current
  std::string name_;
};

// Geometry of the default "magnetic knife" (black unit). All lengths in metres, remanences in tesla.
// A pole blade magnetised +y whose top is bevelled down to the left so that its sharp edge (the
// knife) sits at (0, -tip_depth), plus a return magnet to its right magnetised -x (towards the blade),
// whose top lies `return_recess` below the tip. See docs/magnetic.md for the reasoning.
struct KnifeParams {
  double tip_depth_m = 100e-6;      // depth of the knife edge below the roller surface (sleeve + gap)
  double blade_width_m = 0.5e-3;    // width of the blade (x from -blade_width to 0)
  double bevel_deg = 60.0;          // angle of the bevelled top of the blade to the x axis
  double height_m = 3e-3;           // height of blade and return magnet
  double blade_Br_T = 1.2;          // remanence of the blade, along +y
  double return_width_m = 8e-3;     // width of the return magnet (x from 0 to return_width)
  double return_recess_m = 100e-6;  // top of the return magnet below the knife edge
  double return_Br_T = 0.8;         // remanence of the return magnet, along -x
};
// Colour unit: a symmetric pole of width `pole_width` occupying x in [-pole_width, 0], magnetised +y,
// so the force across the process direction changes sign above its centre, x = -pole_width/2 =
// -150 um by default (thesis §5.1, fig. 5.7). Its right face x = 0 is the "magnet edge".
struct ColorPoleParams {
  double tip_depth_m = 100e-6;    // depth of the pole face below the roller surface
  double pole_width_m = 300e-6;   // width of the pole
  double height_m = 3e-3;         // height of the pole
  double Br_T = 1.2;              // remanence, along +y
};
// Throw InputError (component "magnet.knife" / "magnet.color_pole", naming the key) when out of range.
void validate(const KnifeParams& k);
void validate(const ColorPoleParams& c);
BlockAssembly make_knife(const KnifeParams& k = {});
BlockAssembly make_color_pole(const ColorPoleParams& c = {});

// Which magnet and toner a preset uses is the presets' knowledge (nip/presets.hpp).

// A field source placed rigidly in the engine frame: p_engine = origin + R(angle) p_magnet.
// at() takes an engine-frame point and returns B and dB in the engine frame (B' = R B, dB' = R dB R^T).
class PlacedField final : public MagnetField {
 public:
  PlacedField(std::shared_ptr<const MagnetField> inner, Vec2 origin_m, double angle_rad);
  Sample at(Vec2 p) const override;
  std::string describe() const override;
  bool smooth_in(Vec2 lo, Vec2 hi) const override;  // asks the inner source for the box's bounding box
  std::vector<std::vector<Vec2>> material() const override;

 private:
  std::shared_ptr<const MagnetField> inner_;
  Vec2 origin_;
  double c_, s_;
};

}  // namespace nipdem::magnet
