// ParaView output: one VTK XML PolyData file (.vtp) per snapshot with a vertex per disc and
// a .pvd collection that lists them with their times. ASCII, so other tools (and
// `nipdem render`) can read it without a VTK library.
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "nipdem/engine/simulation.hpp"

namespace nipdem::io {

// Writes DIR/particles/frame_<index>.vtp for the current state (atomic) and returns its path
// relative to DIR. Point data: radius_m, body_id, tag, velocity_m_per_s, speed_m_per_s,
// force_contact_N, force_adhesion_N (per disc), force_<provider>_N and force_total_N (per
// body, repeated on its discs). Field data: time_s and each wall's rotation angle. The adhesive
// part is the discs' fax, fay: call sim.update_adhesive_parts() first.
std::string write_vtp(const std::filesystem::path& dir, int index, const engine::Simulation& sim);
// Writes DIR/particles.pvd listing (time, relative path) pairs (atomic).
void write_pvd(const std::filesystem::path& dir, const std::vector<std::pair<double, std::string>>& frames);

// Minimal reader of the files write_vtp produces (for rendering).
struct Frame {
  double time = 0.0;
  std::vector<double> wall_angle;
  std::vector<double> x, y, r, speed, force;  // force: |force_total| per disc [N]
  std::vector<int> body;
};
Frame read_vtp(const std::filesystem::path& file);

}  // namespace nipdem::io
