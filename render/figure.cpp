#include "figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "colormap.hpp"
#include "text.hpp"

namespace aortasph {

std::string panel_label(int index) {
  std::string s;
  for (int k = index; k >= 0; k = k / 26 - 1) s.insert(s.begin(), static_cast<char>('a' + k % 26));
  return "(" + s + ")";
}

namespace {
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
int even_up(int v) {
  return v + (v & 1);
}
}  // namespace

Image compose_figure(const std::vector<FigurePanel>& panels, int columns,
                     const std::optional<ColorBar>& bar) {
  if (panels.empty()) throw RenderError("figure: no panels");
  if (columns < 1) throw RenderError("figure: columns must be at least 1");
  const int pw = panels[0].image.w, ph = panels[0].image.h;
  for (const auto& p : panels)
    if (p.image.w != pw || p.image.h != ph) throw RenderError("figure: panels differ in size");
  const Font font;
  const int n = static_cast<int>(panels.size());
  const int cols = std::min(columns, n), rows = (n + cols - 1) / cols;
  // Text and spacing scale with the panel so that labels stay legible on small and large frames alike.
  const float px = std::clamp(static_cast<float>(ph) / 16.0f, 12.0f, 36.0f);
  const int margin = static_cast<int>(px * 0.8f);
  const int label_h = static_cast<int>(px * 1.5f);
  const int bar_title_h = label_h, bar_h = static_cast<int>(px), bar_ticks_h = label_h;
  const int bar_block = bar ? bar_title_h + bar_h + bar_ticks_h + margin : 0;
  const int W = even_up(margin + cols * (pw + margin));
  const int H = even_up(margin + rows * (label_h + ph + margin) + bar_block);
  Image sheet(W, H, 255, 255, 255);
  const std::array<uint8_t, 3> black = {0, 0, 0};

  for (int i = 0; i < n; ++i) {
    const int r = i / cols, c = i % cols;
    const int x = margin + c * (pw + margin);
    const int y = margin + r * (label_h + ph + margin);
    std::string text = panel_label(i);
    // The caption only where it fits above its panel; the label always.
    if (!panels[i].caption.empty() && font.width(text + "  " + panels[i].caption, px) <= pw)
      text += "  " + panels[i].caption;
    font.draw(sheet, x, y, text, px, black);
    for (int v = 0; v < ph; ++v)
      std::copy_n(panels[i].image.at(0, v), static_cast<size_t>(pw) * 3, sheet.at(x, y + label_h + v));
  }

  if (bar) {
    const Colormap map(bar->colormap);
    const int y0 = margin + rows * (label_h + ph + margin);
    const int bw = std::max(64, std::min(W - 2 * margin, static_cast<int>(px * 24)));
    const int bx = (W - bw) / 2;
    const std::string title = bar->unit.empty() ? bar->name : bar->name + " [" + bar->unit + "]";
    font.draw(sheet, (W - font.width(title, px)) / 2, y0, title, px, black);
    const int by = y0 + bar_title_h;
    for (int u = 0; u < bw; ++u) {
      const auto col = map((u + 0.5) / bw);
      for (int v = 0; v < bar_h; ++v) std::copy_n(col.data(), 3, sheet.at(bx + u, by + v));
    }
    // Ticks and numbers at both ends and the middle.
    for (int k = 0; k <= 2; ++k) {
      const int tx = std::min(bx + bw - 1, bx + k * bw / 2);
      for (int v = by + bar_h; v < by + bar_h + static_cast<int>(px * 0.3f); ++v)
        std::copy_n(black.data(), 3, sheet.at(tx, v));
      const std::string value = number(bar->lo + (bar->hi - bar->lo) * k / 2.0);
      const int tw = font.width(value, px);
      const int lx = std::clamp(tx - tw / 2, 0, W - tw);
      font.draw(sheet, lx, by + bar_h + static_cast<int>(px * 0.35f), value, px, black);
    }
  }
  return sheet;
}

}  // namespace aortasph
