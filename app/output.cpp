#include "output.hpp"

#include <cstdio>
#include <iomanip>

#include "errors.hpp"

namespace aortasph {

std::string format_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
    : path_(path), out_(path, std::ios::trunc) {
  if (!out_) throw InputError(path.string() + ": cannot open for writing");
  out_ << "time";
  for (const auto& c : columns) out_ << ',' << c;
  out_ << '\n';
  out_.flush();
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

VtkWriter::~VtkWriter() = default;

void VtkWriter::write(const World& world, int frame) {
  const Particles& P = world.particles();
  char name[64];
  std::snprintf(name, sizeof name, "particles_%05d.vtp", frame);
  const auto path = dir_ / name;
  std::ofstream f(path, std::ios::trunc);
  if (!f) throw InputError(path.string() + ": cannot open for writing");
  const std::size_t n = P.size();
  f << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    << "<PolyData>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
    << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
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
  f << "</DataArray>\n</PointData>\n<Verts>\n<DataArray type=\"Int32\" Name=\"connectivity\" "
       "format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << i << '\n';
  f << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) f << i + 1 << '\n';
  f << "</DataArray>\n</Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n";
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
