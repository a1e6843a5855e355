#include "testing/x_screen.h"

#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <cstdlib>

namespace studio::projector::testing {

XScreen read_x_screen(const std::string& display, const std::string& xauthority) {
  XScreen out;
  if (!xauthority.empty()) setenv("XAUTHORITY", xauthority.c_str(), 1);
  Display* d = XOpenDisplay(display.c_str());
  if (!d) return out;
  const Window root = DefaultRootWindow(d);
  XWindowAttributes a;
  XGetWindowAttributes(d, root, &a);
  XImage* img = XGetImage(d, root, 0, 0, unsigned(a.width), unsigned(a.height), AllPlanes, ZPixmap);
  if (img) {
    auto shift = [](unsigned long mask) {
      int s = 0;
      while (mask && !(mask & 1)) {
        mask >>= 1;
        ++s;
      }
      return s;
    };
    const int rs = shift(img->red_mask), gs = shift(img->green_mask), bs = shift(img->blue_mask);
    out.width = a.width;
    out.height = a.height;
    out.rgb.resize(std::size_t(a.width) * a.height * 3);
    std::uint8_t* p = out.rgb.data();
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) {
        const unsigned long px = XGetPixel(img, x, y);
        *p++ = std::uint8_t((px & img->red_mask) >> rs);
        *p++ = std::uint8_t((px & img->green_mask) >> gs);
        *p++ = std::uint8_t((px & img->blue_mask) >> bs);
      }
    XDestroyImage(img);
  }
  XCloseDisplay(d);
  return out;
}

}  // namespace studio::projector::testing
