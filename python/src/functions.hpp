// The CLI's functions for Python, each returning the JSON document the matching `--json`
// command prints (serialised; nipdem/__init__.py turns it into a dict). They call the library
// functions the apps/cli/cmd_*.cpp commands call and apply the same checks in the same order,
// so an invalid input raises the same InputError message (tests/python compares with the CLI).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nipdem/models/dipole_pigments.hpp"
#include "nipdem/models/electric_force.hpp"
#include "nipdem/nip/presets.hpp"

namespace nipdem::python {

// `nipdem params collision` for the configuration `text` (named `file`) with `overrides`.
std::string collision_params(const std::string& text, const std::string& file, const std::vector<std::string>& overrides);

using ElectricArgs = electric::ForceQuery;  // the CLI's options: given or not
std::string force_electric(const ElectricArgs& a);  // `nipdem force electric`

using DipoleArgs = dipole::DipoleQuery;  // moment, distance, angle [deg], radius, pigments, samples, seed
std::string force_dipole(const DipoleArgs& a);  // `nipdem force dipole`

using FieldArgs = nip::FieldOptions;  // the CLI's options: given or not
std::string field_probe(const FieldArgs& f, double x, double y);  // `nipdem field probe`
// Samples the magnet of `f` (a preset, or its knife/pole with tip_depth/br changed) on a grid and
// writes the field-map CSV a config's magnet.map_file reads (atomically). Returns {"out", "source"}.
std::string field_export(const FieldArgs& f, double x0, double x1, int nx, double y0, double y1, int ny,
                         const std::string& out);

std::string rc_response(double R, double Rd, double C, double Rm, double voltage, const std::string& freq);
double rc_default_Rm();
std::string ldc_verify();  // `nipdem ldc verify`

// `nipdem experiment NAME` (front-position, reduction, vo-level, edge-sharpness): `options` is a
// JSON object of ExperimentOptions fields (preset, config, sets, seed, jobs, out, progress) and
// the experiment's own (see docs/python.md); an unknown key is an InputError. Writes OUT/NAME.json
// like the CLI and throws std::runtime_error as the CLI does when the target was not bracketed
// or a point failed (after writing it).
std::string run_experiment(const std::string& name, const std::string& options);

}  // namespace nipdem::python
