// Body forces of the DI toner assembly, plugged into the engine as BodyForce providers:
// the magnet inside the imaging roller acting on induced toner moments (eq. 2.4.34 with
// eq. 4.5.1) and the dipole-dipole force between toner particles (eqs. 2.4.38-2.4.39).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "nipdem/engine/simulation.hpp"
#include "nipdem/models/magnet_field.hpp"
#include "nipdem/models/magnetisation.hpp"

namespace nipdem::experiments {

struct MagnetConfig {
  std::string field = "knife";     // "knife" (black unit), "color_pole", "map" or "none"
  std::string map_file;            // CSV field map (field = "map")
  magnet::MagnetisationParams toner = magnet::black_toner();  // Tables 2.1-2.2
  bool dipole_dipole = true;
  double dipole_cutoff = 42e-6;    // [m]: 8 R50 (docs/magnetic.md: ~1.3 % mean truncation error)
  int dipole_interval = 10;        // steps between dipole-dipole re-evaluations
};

// Magnet force on every toner body: moment m = 4/3 pi R^3 eta M(B) at the centre of mass
// ("cherry pit"), R the volume-equivalent radius (body size / 2), F = (m . grad) B.
// Optionally the dipole-dipole force between the induced moments within a cut-off, with the
// moments induced by the magnet's field only (§4.5); it is re-evaluated every
// `dipole_interval` steps and held in between (multiple time stepping; docs/magnetic.md).
class MagnetForce final : public engine::BodyForce {
 public:
  MagnetForce(std::shared_ptr<const magnet::MagnetField> field, MagnetConfig cfg);
  std::string name() const override { return "magnetic"; }
  void add(const BodyStore& b, const DiscStore& d, double t, std::span<double> fx, std::span<double> fy,
           std::span<double> torque) override;
  // Dipole-dipole part of the last evaluation, per body [N] (for tests and output).
  const std::vector<double>& dipole_fx() const { return dfx_; }
  const std::vector<double>& dipole_fy() const { return dfy_; }

 private:
  void dipole_pass(const BodyStore& b);
  std::shared_ptr<const magnet::MagnetField> field_;
  MagnetConfig cfg_;
  std::vector<Vec2> moment_;
  std::vector<double> dfx_, dfy_;
  std::vector<std::int64_t> dipole_ids_;  // body ids the held dipole forces belong to
  long calls_ = 0;
  // cell list scratch
  std::vector<int> head_, next_;
};

// The field a MagnetConfig names (throws InputError for an unreadable map).
std::shared_ptr<const magnet::MagnetField> make_magnet_field(const MagnetConfig& c);

}  // namespace nipdem::experiments
