#include "offline_take.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>

#include "capture/take.h"
#include "keyer/keyer.h"

namespace fs = std::filesystem;

namespace studio::hull::cli {

struct ColourTake::Impl {
  const std::vector<Camera>* cameras = nullptr;
  std::vector<std::string> dirs;
  std::vector<std::map<uint64_t, uint64_t>> offsets;  // per camera: frame -> byte offset
  std::vector<uint64_t> frames;
  std::vector<std::vector<keyer::Keyer>> keyers;  // per slot, per camera
  std::vector<std::vector<uint8_t>> pixels;       // per slot
};

ColourTake::ColourTake(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ColourTake::~ColourTake() = default;
const std::vector<uint64_t>& ColourTake::all_frames() const { return impl_->frames; }

Expected<std::unique_ptr<ColourTake>> ColourTake::open(const std::string& dir,
                                                       const std::vector<Camera>& cameras,
                                                       const keyer::KeyerOptions& key, int slots) {
  if (!fs::is_directory(dir)) return fail(dir + ": not a folder");
  if (auto ok = key.validate(); !ok) return fail("keyer: " + ok.error().message);
  if (key.mode == keyer::KeyMode::kDifference) {
    return fail("keyer: the difference key needs a clean plate; a take is keyed blue or green");
  }
  auto impl = std::make_unique<Impl>();
  impl->cameras = &cameras;
  impl->offsets.resize(cameras.size());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const std::string cam_dir = (fs::path(dir) / cameras[c].id).string();
    if (!fs::exists(fs::path(cam_dir) / capture::kFramesFile)) {
      return fail("take " + dir + ": no recording of camera " + cameras[c].id);
    }
    auto index = capture::read_index(cam_dir);
    std::vector<capture::IndexEntry> entries;
    if (index && !index->empty()) {
      entries = std::move(*index);
    } else {
      auto scan = capture::scan_frames(cam_dir);
      if (!scan) return fail("take " + dir + ": " + scan.error().message);
      entries = std::move(scan->intact);
    }
    for (const auto& e : entries) impl->offsets[c].emplace(e.frame, e.offset);
    impl->dirs.push_back(cam_dir);
  }
  // The take's frames: those every camera recorded (a frame one camera dropped is not part of
  // the sequence; the plain hull mode names it, see --frames there).
  for (const auto& [f, offset] : impl->offsets.front()) {
    bool everywhere = true;
    for (const auto& per_camera : impl->offsets) everywhere &= per_camera.contains(f);
    if (everywhere) impl->frames.push_back(f);
  }
  if (impl->frames.empty()) return fail("take " + dir + ": no frame recorded by every camera");
  impl->keyers.resize(std::size_t(std::max(slots, 1)));
  impl->pixels.resize(impl->keyers.size());
  for (auto& per_slot : impl->keyers) {
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      auto k = keyer::Keyer::create(key);
      if (!k) return fail("keyer: " + k.error().message);
      per_slot.push_back(std::move(*k));
    }
  }
  return std::unique_ptr<ColourTake>(new ColourTake(std::move(impl)));
}

Expected<void> ColourTake::load(uint64_t f, int slot, ColourFrame& out, double& read_ms,
                                double& key_ms) {
  const std::vector<Camera>& cameras = *impl_->cameras;
  out.images.resize(cameras.size());
  out.masks.resize(cameras.size());
  std::vector<uint8_t>& pixels = impl_->pixels[std::size_t(slot)];
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const Camera& cam = cameras[c];
    const std::string where = impl_->dirs[c] + ": frame " + std::to_string(f);
    auto t0 = std::chrono::steady_clock::now();
    auto header = capture::read_frame(impl_->dirs[c], {f, impl_->offsets[c].at(f)}, pixels);
    if (!header) return fail(where + ": " + header.error().message);
    if (header->frame != f) return fail(where + ": the index points at another frame");
    if (long(header->width) != cam.width || long(header->height) != cam.height) {
      return fail(where + ": size differs from camera " + cam.id);
    }
    if (header->format != capture::PixelFormat::kRgb8) {
      return fail(where + ": " + capture::pixel_format_name(header->format) +
                  " frames have no colour for --refine/--texture (need RGB8)");
    }
    out.images[c] = Image<Rgb8>(cam.width, cam.height);
    std::memcpy(out.images[c].data(), pixels.data(), std::size_t(cam.width) * cam.height * 3);
    read_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    t0 = std::chrono::steady_clock::now();
    if (auto ok = impl_->keyers[std::size_t(slot)][c].key(out.images[c].view(), out.masks[c]);
        !ok) {
      return fail(where + ": " + ok.error().message);
    }
    key_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  return {};
}

}  // namespace studio::hull::cli
