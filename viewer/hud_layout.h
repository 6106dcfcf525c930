// Where the 2-D overlays go in the window, shared by the renderer and the tests (which
// must know which pixels belong to the 3-D view).
#pragma once

namespace snapthread::viewer {

struct PixelRect {
  int x = 0;  // left, pixels from the window's left edge
  int y = 0;  // top, pixels from the window's top edge
  int width = 0;
  int height = 0;
  bool Contains(double px, double py) const {
    return px >= x && px < x + width && py >= y && py < y + height;
  }
};

struct HudLayout {
  PixelRect text;   // status text, top-left
  PixelRect chart;  // |force| strip chart, bottom-right
  PixelRect legend; // twist colour bar, bottom-left (rods only)
};

inline HudLayout MakeHudLayout(int width, int height) {
  HudLayout l;
  l.text = {8, 8, 300, 215};  // up to 11 lines of 1.5x stb_easy_font (18 px each)
  const int cw = width * 3 / 10 > 160 ? width * 3 / 10 : 160;
  const int ch = height / 5 > 70 ? height / 5 : 70;
  l.chart = {width - cw - 10, height - ch - 10, cw, ch};
  l.legend = {10, height - 74 - 10, 290, 74};  // four lines of stb_easy_font and a bar
  return l;
}

}  // namespace snapthread::viewer
