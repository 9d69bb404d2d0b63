// `nipdem calibrate magnetisation`: saturation magnetisation and saturation flux of the
// linear-saturated M(H) curve (thesis §4.5, Table 2.2) from a VSM record.
// See src/nipdem/experiments/calibrate_magnetisation.hpp and docs/calibration.md.
#include <fmt/format.h>
#include <memory>

#include "nipdem/experiments/calibrate_magnetisation.hpp"
#include "registry.hpp"

namespace {

struct Opts {
  std::string data, out;
  nipdem::calibrate::MagnetisationOptions o;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* cal = nipdem::cli::group(app, "calibrate");
  auto* sub = cal->add_subcommand("magnetisation", "Ms and saturation flux of the linear-saturated M(H) curve from a VSM record (§4.5)");
  auto c = std::make_shared<Opts>();
  sub->add_option("--data", c->data, "CSV with columns H_A_per_m, M_A_per_m (any order)")->required();
  sub->add_option("--demag-factor", c->o.demag_factor,
                  "demagnetising factor N of the sample: fit against H - N M (0: the bulk curve vs the external field, §4.5)")
      ->capture_default_str();
  sub->add_option("--volume-fraction", c->o.volume_fraction, "pigment volume fraction of the sample (M_pigment = M / eta)")
      ->capture_default_str();
  sub->add_option("--out", c->out, "output folder (default runs/calibrate_magnetisation)");
  sub->add_flag("--json", c->json, "print one JSON object on stdout");
  sub->callback([c] {
    using namespace nipdem::calibrate;
    c->o.validate();
    const Record r = read_vsm_record(c->data);
    const MagnetisationFit f = calibrate_magnetisation(r, c->o);
    const std::string out = c->out.empty() ? "runs/calibrate_magnetisation" : c->out;
    const auto j = magnetisation_report(r, c->o, f, out);
    nipdem::cli::finish_report(j, out, "magnetisation", c->json,
                               fmt::format("magnetisation (§4.5, N = {:g}): Ms = {:.4g} +- {:.2g} A/m, "
                                           "B_sat = {:.4g} +- {:.2g} T (corr {:.2f}), rms residual {:.3g} A/m\n",
                                           c->o.demag_factor, f.Ms_A_per_m, f.Ms_std_A_per_m, f.B_sat_T, f.B_sat_std_T,
                                           f.corr, f.rms_residual_A_per_m));
  });
});

}  // namespace
