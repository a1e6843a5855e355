#pragma once
// Procedural textures of the demo scene, drawn with OpenCV from fixed seeds (the same bytes on
// every build): PNG-encoded for embedding in the GLB.

#include <cstdint>
#include <vector>

namespace studio::scene_tools {

std::vector<std::uint8_t> marble_png(int size);      // white-grey veined floor marble
std::vector<std::uint8_t> wall_panel_png(int size);  // beige wall with framed panels
std::vector<std::uint8_t> stone_png(int size);       // speckled granite (pedestals, columns)
std::vector<std::uint8_t> landscape_png(int w, int h);  // a muted landscape painting
std::vector<std::uint8_t> abstract_png(int w, int h);   // a muted abstract painting

}  // namespace studio::scene_tools
