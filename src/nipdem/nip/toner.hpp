// Toner particles: size distribution (Table 2.1, §4.1) and cluster templates (§2.1).
#pragma once
#include <string>
#include <vector>

#include "nipdem/core/rng.hpp"
#include "nipdem/core/vec2.hpp"
#include "nipdem/engine/simulation.hpp"

namespace nipdem::nip {

// Volume size distribution approximated by a normal distribution in the diameter (§4.1),
// fitted through the table's quantiles: mean = d50, sigma = (d_large - d_small)/(2 z_0.95)
// with z_0.95 = 1.6449 (Table 2.1 lists the 5 % and 95 % volume quantiles as "d95 - d5").
// Truncated at mean +- 3 sigma. Particles are drawn by number: the number density is the
// volume density divided by d^3 (docs/toner.md), unless weighting = volume.
struct SizeDistribution {
  double d_small = 7e-6;    // diameter exceeded by 95 % of the toner volume [m] (Table 2.1 "d95")
  double d50 = 10.5e-6;     // median of the volume distribution [m]
  double d_large = 14.5e-6; // diameter exceeded by 5 % of the volume [m] ("d5")
  bool number_weighted = true;

  double sigma() const;
  double d_min() const;
  double d_max() const;
  double sample(Rng& rng) const;
  void validate(const std::string& file) const;
};

struct ClusterTemplate {
  std::string name;
  std::vector<Vec2> offsets;    // template units
  std::vector<double> radii;    // template units
};

// Reads [[template]] entries (name, discs = [[x, y, r], ...]); `file` names the source.
std::vector<ClusterTemplate> parse_templates(const std::string& toml_text, const std::string& file);
const std::vector<ClusterTemplate>& builtin_templates();
const ClusterTemplate& find_template(const std::vector<ClusterTemplate>& lib, const std::string& name,
                                     const std::string& file, const std::string& key);

// Body spec of a toner particle of volume-equivalent diameter d built from template t: members
// scaled so that their sphere volumes add up to pi d^3/6.
engine::BodySpec make_toner(const ClusterTemplate& t, double d, double density);
// The scale factor of that construction: member radius = scale * template radius.
double template_scale(const ClusterTemplate& t, double d);

}  // namespace nipdem::nip
