// Image comparison shared by `aortasph compare` and the golden-image tests.
//
// Tolerance: the largest allowed absolute difference of any single colour channel (0..255) between two
// pixels at the same position. Two images match when their sizes agree and max_channel_diff <= tolerance.
// The default tolerance is 0 (bitwise identical pixels): llvmpipe renders deterministically, so same
// binary + same input gives identical frames. PSNR and the share of differing pixels are reported to say
// how much differs, not used to decide.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "image.hpp"

namespace aortasph {

struct ImageDiff {
  int max_channel_diff = 0;      // 0..255
  double psnr_db = 0.0;          // infinity for identical images
  double differing_share = 0.0;  // share of pixels with any channel differing (0..1)
  bool within(int tolerance) const { return max_channel_diff <= tolerance; }
};

// Throws RenderError when the sizes differ (the message gives both sizes).
ImageDiff compare_images(const Image& a, const Image& b);

// A visual diff: A in faint grey, pixels differing by more than `tolerance` in red (brighter = larger).
Image diff_image(const Image& a, const Image& b, int tolerance = 0);

// Formats one result line: "name: PSNR 43.2 dB, max channel diff 3, 0.12 % of pixels differ".
std::string describe(const std::string& name, const ImageDiff& diff);

// Lists the *.png file names (sorted) in a folder.
std::vector<std::string> png_names(const std::filesystem::path& dir);

}  // namespace aortasph
