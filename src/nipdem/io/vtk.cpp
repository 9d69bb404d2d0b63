#include "nipdem/io/vtk.hpp"

#include <cmath>
#include <fmt/format.h>
#include <sstream>

#include "nipdem/core/error.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace nipdem::io {

namespace {
void array_open(std::string& s, const char* type, const std::string& name, int comps) {
  s += fmt::format("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n", type, name, comps);
}
void array_close(std::string& s) { s += "\n        </DataArray>\n"; }
}  // namespace

std::string write_vtp(const std::filesystem::path& dir, int index, const engine::Simulation& sim) {
  const auto& b = sim.bodies();
  const auto& d = sim.discs();
  const std::size_t n = d.x.size();
  std::string s;
  s.reserve(400 * n + 4096);
  s += "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <PolyData>\n";
  s += "    <FieldData>\n";
  s += fmt::format("      <DataArray type=\"Float64\" Name=\"time_s\" NumberOfTuples=\"1\" format=\"ascii\">{:.17g}</DataArray>\n", sim.time());
  s += fmt::format("      <DataArray type=\"Float64\" Name=\"wall_angle_rad\" NumberOfTuples=\"{}\" format=\"ascii\">", sim.walls().size());
  for (const auto& w : sim.walls()) s += fmt::format(" {:.17g}", w.angle);
  s += "</DataArray>\n    </FieldData>\n";
  s += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n", n, n);
  s += "      <Points>\n";
  array_open(s, "Float64", "position_m", 3);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.9g} {:.9g} 0 ", d.x[i], d.y[i]);
  array_close(s);
  s += "      </Points>\n      <Verts>\n";
  array_open(s, "Int64", "connectivity", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{} ", i);
  array_close(s);
  array_open(s, "Int64", "offsets", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{} ", i + 1);
  array_close(s);
  s += "      </Verts>\n      <PointData Scalars=\"radius_m\">\n";
  array_open(s, "Float64", "radius_m", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} ", d.r[i]);
  array_close(s);
  array_open(s, "Int64", "body_id", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{} ", b.id[d.body[i]]);
  array_close(s);
  array_open(s, "Int32", "tag", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{} ", b.tag[d.body[i]]);
  array_close(s);
  std::vector<double> vx(n), vy(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int k = d.body[i];
    vx[i] = b.vx[k] - b.omega[k] * d.wy[i];
    vy[i] = b.vy[k] + b.omega[k] * d.wx[i];
  }
  array_open(s, "Float64", "velocity_m_per_s", 3);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} {:.6g} 0 ", vx[i], vy[i]);
  array_close(s);
  array_open(s, "Float64", "speed_m_per_s", 1);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} ", std::hypot(vx[i], vy[i]));
  array_close(s);
  // (the adhesive part fax, fay as the caller filled it: Simulation::update_adhesive_parts)
  array_open(s, "Float64", "force_contact_N", 3);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} {:.6g} 0 ", d.fx[i] - d.fax[i], d.fy[i] - d.fay[i]);
  array_close(s);
  array_open(s, "Float64", "force_adhesion_N", 3);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} {:.6g} 0 ", d.fax[i], d.fay[i]);
  array_close(s);
  for (std::size_t k = 0; k < sim.forces().size(); ++k) {
    array_open(s, "Float64", "force_" + sim.forces()[k]->name() + "_N", 3);
    const auto& fx = sim.provider_fx(k);
    const auto& fy = sim.provider_fy(k);
    for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} {:.6g} 0 ", fx[d.body[i]], fy[d.body[i]]);
    array_close(s);
  }
  array_open(s, "Float64", "force_total_N", 3);
  for (std::size_t i = 0; i < n; ++i) s += fmt::format("{:.6g} {:.6g} 0 ", b.fx[d.body[i]], b.fy[d.body[i]]);
  array_close(s);
  s += "      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  const std::string rel = fmt::format("particles/frame_{:06d}.vtp", index);
  write_file_atomic(dir / rel, s);
  return rel;
}

void write_pvd(const std::filesystem::path& dir, const std::vector<std::pair<double, std::string>>& frames) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (const auto& [t, f] : frames) s += fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\"/>\n", t, f);
  s += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(dir / "particles.pvd", s);
}

namespace {
// Returns the text between the opening tag of DataArray Name="name" and its closing tag.
std::string array_text(const std::string& doc, const std::string& name, const std::string& file) {
  const auto a = doc.find("Name=\"" + name + "\"");
  if (a == std::string::npos) throw InputError(file + ": no DataArray '" + name + "' (not a nipdem .vtp?)");
  const auto open_end = doc.find('>', a);
  const auto close = doc.find("</DataArray>", open_end);
  return doc.substr(open_end + 1, close - open_end - 1);
}
std::vector<double> numbers(const std::string& text) {
  std::vector<double> v;
  std::istringstream ss(text);
  double x;
  while (ss >> x) v.push_back(x);
  return v;
}
}  // namespace

Frame read_vtp(const std::filesystem::path& file) {
  const std::string doc = read_file(file);
  Frame f;
  const std::string fn = file.string();
  auto t = numbers(array_text(doc, "time_s", fn));
  if (t.size() != 1) throw InputError(fn + ": bad time_s");
  f.time = t[0];
  f.wall_angle = numbers(array_text(doc, "wall_angle_rad", fn));
  auto pos = numbers(array_text(doc, "position_m", fn));
  f.r = numbers(array_text(doc, "radius_m", fn));
  f.speed = numbers(array_text(doc, "speed_m_per_s", fn));
  auto force = numbers(array_text(doc, "force_total_N", fn));
  auto body = numbers(array_text(doc, "body_id", fn));
  const std::size_t n = f.r.size();
  if (pos.size() != 3 * n || f.speed.size() != n || force.size() != 3 * n || body.size() != n)
    throw InputError(fn + ": inconsistent array lengths");
  for (std::size_t i = 0; i < n; ++i) {
    f.x.push_back(pos[3 * i]);
    f.y.push_back(pos[3 * i + 1]);
    f.force.push_back(std::hypot(force[3 * i], force[3 * i + 1]));
    f.body.push_back(static_cast<int>(body[i]));
  }
  return f;
}

}  // namespace nipdem::io
