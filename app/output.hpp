// Files a run writes: CSV tables (probes.csv, diagnostics.csv) and VTK particle files for ParaView.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "world.hpp"

namespace aortasph {

// A CSV file written row by row and flushed after each row, so that a run stopped by an instability or a
// signal leaves every row before intact. Numbers are written with 17 significant digits: round-trip exact,
// so bitwise reproducibility is visible in the file.
class CsvWriter {
 public:
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns);
  // Resuming: keeps the header (which must match columns) and the first keep_rows rows of the existing file,
  // drops everything after them (rows written after the checkpoint, a torn last line) and appends from there.
  // Throws InputError when the file is missing, has other columns or fewer rows.
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
            std::size_t keep_rows);
  void row(const std::vector<double>& values);

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

// VTK XML PolyData (.vtp) of the particles, and the .pvd collection that indexes them by time.
class VtkWriter {
 public:
  explicit VtkWriter(const std::filesystem::path& dir);
  // Resuming: keeps the entries of frames 0 .. keep_frames-1 from the existing particles.pvd, which must
  // list every one of them that is a multiple of `every` (--vtk-every; the run's last output may be there
  // too).
  VtkWriter(const std::filesystem::path& dir, int keep_frames, int every = 1);
  void write(const World& world, int frame);
  ~VtkWriter();

 private:
  void write_index();
  std::filesystem::path dir_;
  std::vector<std::pair<double, std::string>> files_;
};

std::string format_number(double v);

// Writes text to path through a temporary file renamed over it, so that a kill leaves the old or the new
// file, never a shorter one. Throws InputError when it cannot.
void replace_file(const std::filesystem::path& path, const std::string& text);

}  // namespace aortasph
