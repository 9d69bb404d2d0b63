#include "nipdem/nip/toner.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "nipdem/core/error.hpp"
#include "nipdem/embedded_clusters.hpp"
#include "nipdem/io/toml_reader.hpp"

namespace nipdem::nip {

namespace {
constexpr double kZ95 = 1.6448536269514722;  // standard normal 95 % quantile
}

double SizeDistribution::sigma() const { return (d_large - d_small) / (2.0 * kZ95); }
double SizeDistribution::d_min() const { return std::max(d50 - 3.0 * sigma(), 0.1 * d50); }
double SizeDistribution::d_max() const { return d50 + 3.0 * sigma(); }

double SizeDistribution::sample(Rng& rng) const {
  const double s = sigma(), lo = d_min(), hi = d_max();
  for (;;) {
    const double d = rng.normal(d50, s);
    if (d < lo || d > hi) continue;
    if (!number_weighted) return d;
    // accept with probability (lo/d)^3: turns the volume density into the number density
    const double ratio = lo / d;
    if (rng.uniform() < ratio * ratio * ratio) return d;
  }
}

void SizeDistribution::validate(const std::string& file) const {
  require_range(file, "toner.d_small_m", d_small, 1e-7, 1e-3);
  require_range(file, "toner.d50_m", d50, d_small, d_large);
  require_range(file, "toner.d_large_m", d_large, d_small, 1e-3);
  if (!(d_large > d_small)) throw_input(file, "toner.d_large_m", fmt::format("{:g}", d_large), "must exceed toner.d_small_m");
}

std::vector<ClusterTemplate> parse_templates(const std::string& text, const std::string& file) {
  toml::table root = io::parse_toml(text, file);
  std::vector<ClusterTemplate> out;
  const toml::array* arr = root["template"].as_array();
  if (!arr) throw_input(file, "template", "", "no [[template]] entries");
  int idx = 0;
  for (const auto& node : *arr) {
    const std::string key = fmt::format("template[{}]", idx++);
    const toml::table* t = node.as_table();
    if (!t) throw_input(file, key, "", "must be a table");
    ClusterTemplate ct;
    auto name = (*t)["name"].value<std::string>();
    if (!name || name->empty()) throw_input(file, key + ".name", "", "missing template name");
    ct.name = *name;
    const toml::array* discs = (*t)["discs"].as_array();
    if (!discs || discs->empty() || discs->size() > 64) throw_input(file, key + ".discs", "", "need 1..64 discs [[x, y, r], ...]");
    for (const auto& d : *discs) {
      const toml::array* a = d.as_array();
      if (!a || a->size() != 3) throw_input(file, key + ".discs", "", "each disc is [x, y, radius]");
      const double x = a->get(0)->value<double>().value_or(NAN), y = a->get(1)->value<double>().value_or(NAN),
                   r = a->get(2)->value<double>().value_or(NAN);
      if (!std::isfinite(x) || !std::isfinite(y)) throw_input(file, key + ".discs", "", "disc position must be numbers");
      if (!(r > 0.0)) throw_input(file, key + ".discs", fmt::format("{:g}", r), "disc radius must be positive", "(0, inf)");
      ct.offsets.push_back({x, y});
      ct.radii.push_back(r);
    }
    // A toner particle is a cluster of touching spheres (eq. 2.1.1): its members span a few
    // member radii. Members far apart, or of radii many decades apart, would scale to discs of
    // no size beside a particle of the sampled volume (a time step of 0 or inf), reported far
    // from this file: refused here. The bounds leave room for any real cluster (the library's
    // span at most 2 largest radii).
    const double rmax = *std::max_element(ct.radii.begin(), ct.radii.end());
    const double rmin = *std::min_element(ct.radii.begin(), ct.radii.end());
    if (!(rmin >= 1e-3 * rmax))
      throw_input(file, key + ".discs", fmt::format("radii {:g} .. {:g}", rmin, rmax), "member radii more than 1000x apart",
                  "smallest radius >= 1e-3 x largest");
    double span = 0.0;
    for (std::size_t a = 0; a < ct.offsets.size(); ++a)
      for (std::size_t b = a + 1; b < ct.offsets.size(); ++b)
        span = std::max(span, std::hypot(ct.offsets[a].x - ct.offsets[b].x, ct.offsets[a].y - ct.offsets[b].y));
    if (!(span <= 100.0 * rmax))
      throw_input(file, key + ".discs", fmt::format("centres {:g} apart", span),
                  "members too far apart for a cluster of touching spheres", fmt::format("centres within 100 x the largest radius ({:g})", 100.0 * rmax));
    out.push_back(std::move(ct));
  }
  return out;
}

const std::vector<ClusterTemplate>& builtin_templates() {
  static const std::vector<ClusterTemplate> lib = parse_templates(kEmbeddedClustersToml, "data/clusters.toml");
  return lib;
}

const ClusterTemplate& find_template(const std::vector<ClusterTemplate>& lib, const std::string& name,
                                     const std::string& file, const std::string& key) {
  std::string names;
  for (const auto& t : lib) {
    if (t.name == name) return t;
    names += (names.empty() ? "" : ", ") + t.name;
  }
  throw_input(file, key, "\"" + name + "\"", "unknown cluster template", names);
}

double template_scale(const ClusterTemplate& t, double d) {
  double v = 0.0;
  for (double r : t.radii) v += r * r * r;
  return 0.5 * d / std::cbrt(v);
}

engine::BodySpec make_toner(const ClusterTemplate& t, double d, double density) {
  const double s = template_scale(t, d);
  engine::BodySpec b;
  for (std::size_t k = 0; k < t.radii.size(); ++k) {
    b.offsets.push_back(s * t.offsets[k]);
    b.radii.push_back(s * t.radii[k]);
  }
  b.density = density;
  b.size = d;
  return b;
}

}  // namespace nipdem::nip
