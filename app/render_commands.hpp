// The image subcommands (SPEC.md section 1): compare and movie. Each takes the arguments after the subcommand
// word and returns the process exit code; errors go to stderr.
#pragma once

#include <string>
#include <vector>

namespace aortasph {

// aortasph compare A B [--diff DIFF.png] [--tolerance T]
// A and B: two PNG files, or two folders holding PNGs with the same names. Per image it prints PSNR, the
// largest channel difference and the share of differing pixels. T is the largest allowed difference of one
// colour channel (integer 0..255, default 0 = identical pixels). --diff writes a visual diff (red = differing
// pixels); for folders DIFF is a folder that receives one diff per differing image. Exit 0 within tolerance,
// 1 beyond, 2 on bad input (missing file, unreadable PNG, sizes differ, folders with different file sets).
int cmd_compare(const std::vector<std::string>& args);

// aortasph movie DIR [--fps N]
// Every folder under DIR (DIR included) holding frame_NNNNN.png becomes <folder>.mp4 next to it, via
//   ffmpeg -framerate N -start_number S -i frame_%05d.png -c:v libx264 -crf 20 -pix_fmt yuv420p <folder>.mp4
// N defaults to 30. Exit 2 when ffmpeg is not on PATH, DIR does not exist or holds no frames; 1 if ffmpeg
// fails.
int cmd_movie(const std::vector<std::string>& args);

}  // namespace aortasph
