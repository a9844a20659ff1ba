#include "output.hpp"

#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <optional>

#include "errors.hpp"

namespace aortasph {

std::string format_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void replace_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.close();
    if (!f) throw InputError(tmp.string() + ": write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path.string() + ": cannot replace: " + ec.message());
}

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
    : path_(path), out_(path, std::ios::trunc) {
  if (!out_) throw InputError(path.string() + ": cannot open for writing");
  out_ << "time";
  for (const auto& c : columns) out_ << ',' << c;
  out_ << '\n';
  out_.flush();
}

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
                     std::size_t keep_rows)
    : path_(path) {
  std::string header = "time";
  for (const auto& c : columns) header += "," + c;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": missing; cannot resume");
  std::string kept, line;
  std::size_t rows = 0;
  if (!std::getline(in, line) || line != header)
    throw InputError(path.string() + ": its columns differ from this scene's; cannot resume");
  kept = header + "\n";
  // Only whole lines count: a line without its newline was torn by a kill.
  while (rows < keep_rows && std::getline(in, line) && !in.eof()) {
    kept += line + "\n";
    ++rows;
  }
  if (rows < keep_rows)
    throw InputError(path.string() + ": has " + std::to_string(rows) +
                     " complete rows, the checkpoint needs " + std::to_string(keep_rows) + "; cannot resume");
  in.close();
  replace_file(path, kept);
  out_.open(path, std::ios::binary | std::ios::app);
  if (!out_) throw InputError(path.string() + ": cannot open for writing");
}

void CsvWriter::row(const std::vector<double>& values) {
  for (std::size_t k = 0; k < values.size(); ++k) out_ << (k ? "," : "") << format_number(values[k]);
  out_ << '\n';
  out_.flush();
  if (!out_) throw InputError(path_.string() + ": write failed (disk full?)");
}

VtkWriter::VtkWriter(const std::filesystem::path& dir) : dir_(dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw InputError(dir_.string() + ": cannot create folder: " + ec.message());
}

VtkWriter::VtkWriter(const std::filesystem::path& dir, int keep_frames, int every) : VtkWriter(dir) {
  std::ifstream in(dir_ / "particles.pvd");
  std::string line;
  auto attribute = [&](const std::string& key) -> std::optional<std::string> {
    const auto at = line.find(key + "=\"");
    if (at == std::string::npos) return std::nullopt;
    const auto from = at + key.size() + 2, to = line.find('"', from);
    if (to == std::string::npos) return std::nullopt;
    return line.substr(from, to - from);
  };
  int strided = 0;
  while (std::getline(in, line)) {
    const auto t = attribute("timestep"), file = attribute("file");
    if (!t || !file) continue;
    int frame = -1;
    if (std::sscanf(file->c_str(), "particles_%d.vtp", &frame) != 1 || frame < 0 || frame >= keep_frames)
      continue;
    files_.emplace_back(std::strtod(t->c_str(), nullptr), *file);
    if (frame % every == 0) ++strided;
  }
  const int expected = (keep_frames + every - 1) / every;  // frames 0, every, 2 every, ... below keep_frames
  if (strided != expected)
    throw InputError((dir_ / "particles.pvd").string() + ": lists " + std::to_string(strided) + " of the " +
                     std::to_string(expected) + " frames written before the checkpoint; cannot resume");
}

VtkWriter::~VtkWriter() = default;

void VtkWriter::write(const World& world, int frame) {
  const Particles& P = world.particles();
  char name[64];
  std::snprintf(name, sizeof name, "particles_%05d.vtp", frame);
  const auto path = dir_ / name;
  std::ofstream f(path, std::ios::trunc);
  if (!f) throw InputError(path.string() + ": cannot open for writing");
  const std::size_t n = P.size();
  // Shell sheets (sim/solid/shell_mesh.hpp) as polygons through the shell particles, so ParaView shows a
  // surface; by particle index now.
  const Shells& shells = world.shells();
  std::vector<std::array<uint32_t, 3>> polys;
  for (const auto& t : world.shell_sheets().triangles())
    polys.push_back({shells.at(t[0]), shells.at(t[1]), shells.at(t[2])});
  f << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    << "<PolyData>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
    << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << polys.size() << "\">\n";
  f << std::setprecision(9);
  f << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.x[i].x() << ' ' << P.x[i].y() << ' ' << P.x[i].z() << '\n';
  f << "</DataArray>\n</Points>\n<PointData Scalars=\"pressure\" Vectors=\"velocity\">\n";
  f << "<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.v[i].x() << ' ' << P.v[i].y() << ' ' << P.v[i].z() << '\n';
  f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.p[i] << '\n';
  f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"density\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.rho[i] << '\n';
  f << "</DataArray>\n<DataArray type=\"Int32\" Name=\"body\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.body[i] << '\n';
  f << "</DataArray>\n<DataArray type=\"Int32\" Name=\"id\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << P.id[i] << '\n';
  // Von Mises stress [Pa] of elastic solids (eqs. 16-17) and shells (the largest over a particle's Gauss
  // points); zero for the other particles: the report's stress maps (scripts/study_report.py).
  {
    std::vector<double> vm(n, 0.0);
    const Solids& S = world.solids();
    for (std::size_t s = 0; s < S.size(); ++s) vm[S.at(s)] = S.von_mises(s);
    for (std::size_t s = 0; s < world.shells().size(); ++s)
      vm[world.shells().at(s)] = world.shells().von_mises(s);
    f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"von_mises\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) f << vm[i] << '\n';
  }
  // Shells (sim/solid/shell.hpp): the director (the through-thickness direction), the mid-surface normal and
  // the thickness of each shell particle; zero for the others.
  if (const Shells& sh = world.shells(); !sh.empty()) {
    std::vector<Vec3> d(n, Vec3::Zero()), nrm(n, Vec3::Zero());
    std::vector<double> t(n, 0.0);
    for (std::size_t s = 0; s < sh.size(); ++s) {
      d[sh.at(s)] = sh.director(s);
      nrm[sh.at(s)] = sh.normal(s);
      t[sh.at(s)] = sh.thickness(s);
    }
    f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"director\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) f << d[i].x() << ' ' << d[i].y() << ' ' << d[i].z() << '\n';
    f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"normal\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) f << nrm[i].x() << ' ' << nrm[i].y() << ' ' << nrm[i].z() << '\n';
    f << "</DataArray>\n<DataArray type=\"Float64\" Name=\"thickness\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) f << t[i] << '\n';
  }
  f << "</DataArray>\n</PointData>\n<Verts>\n<DataArray type=\"Int32\" Name=\"connectivity\" "
       "format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << i << '\n';
  f << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << i + 1 << '\n';
  f << "</DataArray>\n</Verts>\n";
  if (!polys.empty()) {
    f << "<Polys>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : polys) f << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    f << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t k = 0; k < polys.size(); ++k) f << 3 * (k + 1) << '\n';
    f << "</DataArray>\n</Polys>\n";
  }
  f << "</Piece>\n</PolyData>\n</VTKFile>\n";
  f.close();
  if (!f) throw InputError(path.string() + ": write failed (disk full?)");
  files_.emplace_back(world.time(), name);
  write_index();
}

void VtkWriter::write_index() {
  std::ofstream f(dir_ / "particles.pvd", std::ios::trunc);
  f << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    << "<Collection>\n";
  for (const auto& [t, file] : files_)
    f << "<DataSet timestep=\"" << format_number(t) << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
  f << "</Collection>\n</VTKFile>\n";
}

}  // namespace aortasph
