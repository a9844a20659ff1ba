#include "text.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

// stb_truetype is a single-header library: its implementation is compiled here, once, with its own
// warnings silenced (they are in third-party code we do not change).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#define STB_TRUETYPE_IMPLEMENTATION
#define STBTT_STATIC
#include <stb/stb_truetype.h>
#pragma GCC diagnostic pop

namespace aortasph {

std::filesystem::path default_font_path() {
  if (const char* env = std::getenv("AORTASPH_FONT"); env && *env) return env;
  return "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

Font::Font(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw RenderError("font " + path.string() +
                      " not found (install fonts-dejavu-core, or set AORTASPH_FONT to a .ttf file)");
  data_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  auto* info = new stbtt_fontinfo;
  if (data_.empty() || !stbtt_InitFont(info, data_.data(), stbtt_GetFontOffsetForIndex(data_.data(), 0))) {
    delete info;
    throw RenderError("font " + path.string() + " is not a TrueType font");
  }
  info_ = info;
}

Font::~Font() {
  delete static_cast<stbtt_fontinfo*>(info_);
}

int Font::width(const std::string& text, float px) const {
  const auto* info = static_cast<const stbtt_fontinfo*>(info_);
  const float scale = stbtt_ScaleForPixelHeight(info, px);
  float x = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    int advance = 0, lsb = 0;
    stbtt_GetCodepointHMetrics(info, static_cast<unsigned char>(text[i]), &advance, &lsb);
    x += advance * scale;
    if (i + 1 < text.size())
      x += scale * stbtt_GetCodepointKernAdvance(info, static_cast<unsigned char>(text[i]),
                                                 static_cast<unsigned char>(text[i + 1]));
  }
  return static_cast<int>(std::ceil(x));
}

void Font::draw(Image& image, int x0, int y0, const std::string& text, float px,
                std::array<uint8_t, 3> color) const {
  const auto* info = static_cast<const stbtt_fontinfo*>(info_);
  const float scale = stbtt_ScaleForPixelHeight(info, px);
  int ascent = 0, descent = 0, gap = 0;
  stbtt_GetFontVMetrics(info, &ascent, &descent, &gap);
  const int baseline = y0 + static_cast<int>(std::lround(ascent * scale));
  float pen = static_cast<float>(x0);
  // Text is ASCII in our figures (labels, numbers, units written as "m/s", "Pa").
  for (size_t i = 0; i < text.size(); ++i) {
    const int cp = static_cast<unsigned char>(text[i]);
    int advance = 0, lsb = 0;
    stbtt_GetCodepointHMetrics(info, cp, &advance, &lsb);
    int gw = 0, gh = 0, gx = 0, gy = 0;
    const float shift = pen - std::floor(pen);
    unsigned char* bitmap =
        stbtt_GetCodepointBitmapSubpixel(info, scale, scale, shift, 0.0f, cp, &gw, &gh, &gx, &gy);
    const int ox = static_cast<int>(std::floor(pen)) + gx, oy = baseline + gy;
    for (int v = 0; v < gh; ++v) {
      for (int u = 0; u < gw; ++u) {
        const int X = ox + u, Y = oy + v;
        if (X < 0 || Y < 0 || X >= image.w || Y >= image.h) continue;
        const int a = bitmap[v * gw + u];
        uint8_t* p = image.at(X, Y);
        for (int c = 0; c < 3; ++c)
          p[c] = static_cast<uint8_t>((p[c] * (255 - a) + color[c] * a + 127) / 255);
      }
    }
    stbtt_FreeBitmap(bitmap, nullptr);
    pen += advance * scale;
    if (i + 1 < text.size())
      pen += scale * stbtt_GetCodepointKernAdvance(info, cp, static_cast<unsigned char>(text[i + 1]));
  }
}

}  // namespace aortasph
