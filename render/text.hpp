// Text for figure sheets: stb_truetype rasterising a TrueType font (DejaVu Sans from fonts-dejavu-core).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "image.hpp"

namespace aortasph {

// $AORTASPH_FONT if set, else /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf.
std::filesystem::path default_font_path();

class Font {
 public:
  // Throws RenderError when the file is missing or not a font (the message says which package provides it).
  explicit Font(const std::filesystem::path& path = default_font_path());
  ~Font();
  Font(const Font&) = delete;
  Font& operator=(const Font&) = delete;

  // Width in pixels of `text` at a pixel height of `px`.
  int width(const std::string& text, float px) const;
  // Draws `text` with its top-left corner at (x, y); alpha-blends the glyph coverage in `color`.
  void draw(Image& image, int x, int y, const std::string& text, float px,
            std::array<uint8_t, 3> color) const;

 private:
  std::vector<unsigned char> data_;
  void* info_ = nullptr;  // stbtt_fontinfo
};

}  // namespace aortasph
