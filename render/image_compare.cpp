#include "image_compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace aortasph {

ImageDiff compare_images(const Image& a, const Image& b) {
  if (a.w != b.w || a.h != b.h)
    throw RenderError("image sizes differ: " + std::to_string(a.w) + "x" + std::to_string(a.h) + " vs " +
                      std::to_string(b.w) + "x" + std::to_string(b.h));
  ImageDiff d;
  double sq = 0.0;
  size_t differing = 0;
  const size_t n = static_cast<size_t>(a.w) * a.h;
  for (size_t i = 0; i < n; ++i) {
    int pixel_max = 0;
    for (int c = 0; c < 3; ++c) {
      const int e = std::abs(static_cast<int>(a.rgb[3 * i + c]) - static_cast<int>(b.rgb[3 * i + c]));
      sq += static_cast<double>(e) * e;
      pixel_max = std::max(pixel_max, e);
    }
    d.max_channel_diff = std::max(d.max_channel_diff, pixel_max);
    differing += pixel_max > 0;
  }
  d.differing_share = n ? static_cast<double>(differing) / static_cast<double>(n) : 0.0;
  const double mse = n ? sq / (3.0 * static_cast<double>(n)) : 0.0;
  d.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity();
  return d;
}

Image diff_image(const Image& a, const Image& b, int tolerance) {
  compare_images(a, b);  // size check
  Image out(a.w, a.h);
  for (size_t i = 0; i < static_cast<size_t>(a.w) * a.h; ++i) {
    int e = 0, lum = 0;
    for (int c = 0; c < 3; ++c) {
      e = std::max(e, std::abs(static_cast<int>(a.rgb[3 * i + c]) - static_cast<int>(b.rgb[3 * i + c])));
      lum += a.rgb[3 * i + c];
    }
    uint8_t* p = &out.rgb[3 * i];
    if (e > tolerance) {
      // Small differences still show clearly: at least half intensity.
      p[0] = static_cast<uint8_t>(std::min(255, 128 + e));
      p[1] = 0;
      p[2] = 0;
    } else {
      const auto grey = static_cast<uint8_t>(192 + lum / 3 / 4);  // faint context
      p[0] = p[1] = p[2] = grey;
    }
  }
  return out;
}

std::string describe(const std::string& name, const ImageDiff& d) {
  char buf[256];
  if (std::isinf(d.psnr_db))
    std::snprintf(buf, sizeof buf, "%s: identical (PSNR inf, max channel diff 0, 0 %% of pixels differ)",
                  name.c_str());
  else
    std::snprintf(buf, sizeof buf, "%s: PSNR %.2f dB, max channel diff %d, %.4g %% of pixels differ",
                  name.c_str(), d.psnr_db, d.max_channel_diff, 100.0 * d.differing_share);
  return buf;
}

std::vector<std::string> png_names(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".png")
      names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace aortasph
