// Magnet field imported from a file: B on a regular grid (as exported from an FEM package such as
// Flux2D, thesis §2.4.2), interpolated so that B and its gradient -- hence the magnet force -- are
// continuous.
//
// File format (CSV, one header line, '#' comment lines allowed anywhere, blank lines ignored):
//     # any comment, e.g. where the map came from
//     x_m,y_m,Bx_T,By_T
//     -1.0e-3,0.0,0.1234,0.5678
//     ...
// Columns are exactly x, y, Bx, By in this order; the unit suffix is required and may be
//   x_m | x_mm | x_um,  y_m | y_mm | y_um,  Bx_T | Bx_mT,  By_T | By_mT
// (values are converted to SI). Rows may come in any order but must fill a regular grid:
// every (x_i, y_j) of nx uniformly spaced x values times ny uniformly spaced y values exactly once,
// nx, ny >= 5. Spacing must be uniform within 0.1 % of the step (so exports printed with ~6
// significant digits pass); nodes are snapped to the uniform grid. Coordinates are in the magnet frame of magnet_field.hpp.
//
// Interpolation: bicubic Hermite patches per component, with nodal derivatives dB/dx, dB/dy and
// d2B/dxdy from 4th-order finite differences (central inside, one-sided at the border). The result
// is C1 (B and grad B continuous across cells); the error is O(h^4) in B and O(h^3) in grad B for
// a smooth field (measured in tests/unit/test_field_map.cpp). Points outside the grid throw
// InputError (use contains() to test first).
#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "nipdem/models/magnet_field.hpp"

namespace nipdem::io {

class FieldMap final : public magnet::MagnetField {
 public:
  // Grid given directly: node (i, j) is at (x0 + i hx, y0 + j hy), values stored with i fastest
  // (index j*nx + i). Throws InputError for nx or ny < 5, non-positive spacing, NaN/inf values, or
  // size mismatch. `where` names the source in messages.
  FieldMap(double x0_m, double y0_m, double hx_m, double hy_m, int nx, int ny, std::vector<double> Bx_T,
           std::vector<double> By_T, std::string where = "field map");

  // Parses the CSV format above; `where` (file name) is used in every error message.
  static FieldMap from_csv(std::string_view text, const std::string& where);
  static FieldMap from_file(const std::filesystem::path& path);
  // Samples any field source on the regular grid [x0,x1] x [y0,y1] (nx x ny nodes) -- e.g. to turn
  // the analytic knife into a cheaper table for the engine (see docs/magnetic.md, Speed).
  static FieldMap sample(const magnet::MagnetField& field, double x0_m, double x1_m, int nx, double y0_m, double y1_m,
                         int ny);

  magnet::Sample at(Vec2 p) const override;
  std::string describe() const override;
  bool contains(Vec2 p) const;

  double x_min() const { return x0_; }
  double x_max() const { return x0_ + (nx_ - 1) * hx_; }
  double y_min() const { return y0_; }
  double y_max() const { return y0_ + (ny_ - 1) * hy_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }

 private:
  struct Node {  // per component: value, d/dx * hx, d/dy * hy, d2/dxdy * hx * hy (scaled to the cell)
    double f, fx, fy, fxy;
  };
  struct alignas(64) Node2 {  // both components of one node in one cache line
    Node c[2];
  };
  double x0_, y0_, hx_, hy_;
  int nx_, ny_;
  std::vector<Node2> nodes_;
  std::string where_;
};

// Samples `field` on the regular grid [x0,x1] x [y0,y1] with nx x ny nodes and returns the CSV text
// of the format above (header x_m,y_m,Bx_T,By_T, full double precision). Used to write example maps
// and to test the map path against the analytic field.
std::string field_to_csv(const magnet::MagnetField& field, double x0_m, double x1_m, int nx, double y0_m, double y1_m,
                         int ny, const std::string& comment = {});

}  // namespace nipdem::io
