#pragma once
// Test helper: the root window of an X display as RGB8 (top row first), read with Xlib
// (XGetImage) — what a monitor of that display shows, independent of any GL code. Kept apart
// from the tests' sources because X11's headers define macros (Success, None, Status) that
// clash with Eigen and gtest.

#include <cstdint>
#include <string>
#include <vector>

namespace studio::projector::testing {

struct XScreen {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3
};

// display: e.g. ":99"; xauthority: the display's auth file ("" for none). Empty (width 0) when
// the display cannot be opened or read.
XScreen read_x_screen(const std::string& display, const std::string& xauthority);

}  // namespace studio::projector::testing
