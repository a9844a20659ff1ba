// Waveform files (issue 17): a CSV of time [s] and value, one sample a line, for an open boundary's pressure.
#pragma once

#include <filesystem>
#include <string>

#include "physiology/waveform.hpp"

namespace aortasph {

// Reads `file`: lines `t, value` (comma separated, spaces allowed), times strictly increasing; empty lines
// and lines starting with '#' (after spaces) are skipped; a first data line whose cells are not numbers is a
// header and is skipped too. Values are multiplied by `scale` (units -> Pa). Throws InputError naming the
// file, and the line where one is at fault ("waveforms/lv.csv:12: ..."), when the file is missing or
// unreadable, holds no sample, has a line that is not two numbers, or times that do not increase.
// `shown` is the name used in messages (the path as the scene wrote it, or with its folder).
Waveform read_waveform_csv(const std::filesystem::path& file, const std::string& shown, double scale);

}  // namespace aortasph
