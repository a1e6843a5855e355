#include "frame_input.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "capture/take.h"
#include "capture/take_calibration.h"
#include "keyer/keyer.h"
#include "yaml_io/node.h"
#include "yaml_io/rig_yaml.h"

namespace fs = std::filesystem;

namespace studio::hull::cli {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string size_text(long w, long h) { return std::to_string(w) + "x" + std::to_string(h); }

bool in_range(long f, const std::optional<FrameRange>& r) {
  return !r || (f >= r->first && f <= r->last);
}

// ---- mask folder ------------------------------------------------------------------------------

class MaskFolder final : public FrameInput {
 public:
  MaskFolder(const std::vector<Camera>& cameras, std::vector<fs::path> dirs,
             std::vector<std::string> names)
      : cameras_(cameras), dirs_(std::move(dirs)) {
    frames_ = std::move(names);
  }

  Expected<void> load(std::size_t k, int, std::vector<RunMask>& masks, LoadTimes& times) override {
    const auto t0 = std::chrono::steady_clock::now();
    masks.resize(cameras_.size());
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      const Camera& cam = cameras_[c];
      const fs::path path = dirs_[k] / (cam.id + ".png");
      if (!fs::exists(path)) return fail(path.string() + ": missing mask for camera " + cam.id);
      const cv::Mat m = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
      if (m.empty()) return fail(path.string() + ": not a readable image");
      if (m.cols != cam.width || m.rows != cam.height) {
        return fail(path.string() + ": mask is " + size_text(m.cols, m.rows) + ", camera " +
                    cam.id + " is " + size_text(cam.width, cam.height));
      }
      masks[c] =
          RunMask::from_mask(MaskView(m.ptr<uint8_t>(), m.cols, m.rows, std::ptrdiff_t(m.step)));
    }
    times.read += ms_since(t0);
    return {};
  }

 private:
  const std::vector<Camera>& cameras_;
  std::vector<fs::path> dirs_;
};

// ---- recorded take ----------------------------------------------------------------------------

class Take final : public FrameInput {
 public:
  Take(const std::vector<Camera>& cameras, std::vector<std::string> camera_dirs,
       std::vector<uint64_t> numbers, std::vector<std::map<uint64_t, uint64_t>> offsets,
       std::vector<std::vector<keyer::Keyer>> keyers,
       std::vector<std::map<uint64_t, Camera>> tracked)
      : cameras_(cameras),
        tracked_(std::move(tracked)),
        camera_dirs_(std::move(camera_dirs)),
        numbers_(std::move(numbers)),
        offsets_(std::move(offsets)),
        keyers_(std::move(keyers)),
        pixels_(keyers_.size()) {
    for (const uint64_t f : numbers_) frames_.push_back(std::to_string(f));
    keyed_ = true;
  }

  Expected<void> load(std::size_t k, int slot, std::vector<RunMask>& masks,
                      LoadTimes& times) override {
    masks.resize(cameras_.size());
    const uint64_t f = numbers_[k];
    std::vector<uint8_t>& pixels = pixels_[std::size_t(slot)];
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      const Camera& cam = cameras_[c];
      const std::string& dir = camera_dirs_[c];
      auto t0 = std::chrono::steady_clock::now();
      auto header = capture::read_frame(dir, {f, offsets_[c].at(f)}, pixels);
      if (!header)
        return fail(dir + ": frame " + std::to_string(f) + ": " + header.error().message);
      const std::string where = dir + ": frame " + std::to_string(f);
      if (header->frame != f) {
        return fail(where + ": the index points at frame " + std::to_string(header->frame) +
                    " (rebuild it with studio-capture verify-take)");
      }
      if (long(header->width) != cam.width || long(header->height) != cam.height) {
        return fail(where + " is " + size_text(header->width, header->height) + ", camera " +
                    cam.id + " is " + size_text(cam.width, cam.height));
      }
      if (header->format != capture::PixelFormat::kRgb8) {
        return fail(where + ": " + capture::pixel_format_name(header->format) +
                    " frames cannot be chroma keyed (need RGB8)");
      }
      times.read += ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      const ImageView<const Rgb8> image(reinterpret_cast<const Rgb8*>(pixels.data()), cam.width,
                                        cam.height);
      if (auto ok = keyers_[std::size_t(slot)][c].key(image, masks[c]); !ok) {
        return fail(where + ": " + ok.error().message);
      }
      times.key += ms_since(t0);
    }
    return {};
  }

  const Camera* camera(std::size_t k, std::size_t c) const override {
    const auto it = tracked_[c].find(numbers_[k]);
    return it == tracked_[c].end() ? nullptr : &it->second;
  }

 private:
  const std::vector<Camera>& cameras_;
  std::vector<std::map<uint64_t, Camera>> tracked_;  // per camera: frame -> its calibration
  std::vector<std::string> camera_dirs_;
  std::vector<uint64_t> numbers_;
  std::vector<std::map<uint64_t, uint64_t>> offsets_;  // per camera: frame -> byte offset
  std::vector<std::vector<keyer::Keyer>> keyers_;      // per slot, per camera
  std::vector<std::vector<uint8_t>> pixels_;           // per slot
};

}  // namespace

Expected<std::unique_ptr<FrameInput>> open_mask_folder(const std::string& dir,
                                                       const std::vector<Camera>& cameras,
                                                       std::optional<FrameRange> range) {
  if (!fs::is_directory(dir)) return fail(dir + ": not a folder");
  std::vector<fs::path> dirs;
  std::vector<std::string> names;
  bool single = false;
  for (const Camera& c : cameras) single |= fs::exists(fs::path(dir) / (c.id + ".png"));
  if (single) {
    dirs.push_back(dir);
    names.push_back("");
  } else {
    std::vector<std::pair<long, fs::path>> found;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      if (!e.is_directory()) continue;
      const std::string n = e.path().filename().string();
      if (n.empty() || n.size() > 18 || !std::all_of(n.begin(), n.end(), ::isdigit)) continue;
      const long f = std::stol(n);
      if (in_range(f, range)) found.emplace_back(f, e.path());
    }
    if (ec) return fail(dir + ": " + ec.message());
    std::sort(found.begin(), found.end());
    for (const auto& [f, p] : found) {
      dirs.push_back(p);
      names.push_back(p.filename().string());
    }
    if (dirs.empty()) {
      return fail(dir + ": no masks (" + cameras.front().id + ".png) and no frame folders" +
                  (range ? " in --frames" : ""));
    }
  }
  return std::unique_ptr<FrameInput>(new MaskFolder(cameras, std::move(dirs), std::move(names)));
}

Expected<std::vector<Camera>> cameras_of_take(const std::string& dir) {
  if (!fs::is_directory(dir)) return fail(dir + ": not a folder");
  std::vector<fs::path> folders;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.is_directory() && fs::exists(e.path() / capture::kTakeFile)) folders.push_back(e.path());
  }
  if (ec) return fail(dir + ": " + ec.message());
  if (folders.empty()) return fail("take " + dir + ": no camera folder with a " + capture::kTakeFile);
  std::sort(folders.begin(), folders.end());
  std::vector<Camera> cameras;
  for (const fs::path& folder : folders) {
    const std::string file = (folder / capture::kTakeFile).string();
    auto root = yaml::load_file(file);
    if (!root) return std::unexpected(root.error());
    auto entries = root->entries();
    if (!entries) return std::unexpected(entries.error());
    const yaml::Node* calibration = nullptr;
    for (const auto& [key, node] : *entries) {
      if (key == "calibration") calibration = &node;
    }
    if (!calibration) {
      return fail(file + ": camera recorded without calibration; give --rig");
    }
    auto camera = yaml::read_camera(*calibration);
    if (!camera) return std::unexpected(camera.error());
    if (camera->id != folder.filename().string()) {
      return fail(file + ": calibration of camera '" + camera->id + "' in folder " +
                  folder.filename().string());
    }
    cameras.push_back(std::move(*camera));
  }
  return cameras;
}

Expected<std::unique_ptr<FrameInput>> open_take(const std::string& dir,
                                                const std::vector<Camera>& cameras,
                                                std::optional<FrameRange> range,
                                                const keyer::KeyerOptions& key, int slots) {
  if (!fs::is_directory(dir)) return fail(dir + ": not a folder");
  if (auto ok = key.validate(); !ok) return fail("keyer: " + ok.error().message);
  if (key.mode == keyer::KeyMode::kDifference) {
    return fail("keyer: the difference key needs a clean plate; a take is keyed blue or green");
  }
  std::vector<std::string> camera_dirs;
  std::vector<std::map<uint64_t, uint64_t>> offsets(cameras.size());
  std::vector<std::map<uint64_t, Camera>> tracked(cameras.size());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const std::string cam_dir = (fs::path(dir) / cameras[c].id).string();
    auto per_frame = capture::read_take_calibration(cam_dir, cameras[c]);
    if (!per_frame) return fail("take " + dir + ": " + per_frame.error().message);
    tracked[c] = std::move(*per_frame);
    if (!fs::exists(fs::path(cam_dir) / capture::kFramesFile)) {
      return fail("take " + dir + ": no recording of camera " + cameras[c].id + " (" + cam_dir +
                  "/" + capture::kFramesFile + " is missing)");
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
    for (const auto& e : entries) {
      if (in_range(long(e.frame), range)) offsets[c].emplace(e.frame, e.offset);
    }
    camera_dirs.push_back(cam_dir);
  }
  // Every camera must hold every frame of the selection: the hull of a frame without one of
  // its cameras would be silently too large.
  std::vector<uint64_t> numbers;
  for (const auto& per_camera : offsets)
    for (const auto& [f, offset] : per_camera) numbers.push_back(f);
  std::sort(numbers.begin(), numbers.end());
  numbers.erase(std::unique(numbers.begin(), numbers.end()), numbers.end());
  if (numbers.empty()) {
    return fail("take " + dir + ": no recorded frames" + (range ? " in --frames" : ""));
  }
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    for (const uint64_t f : numbers) {
      if (!offsets[c].contains(f)) {
        return fail("take " + dir + ": camera " + cameras[c].id + " has no frame " +
                    std::to_string(f) + " (dropped while recording?); use --frames to skip it");
      }
      if (!tracked[c].empty() && !tracked[c].contains(f)) {
        return fail("take " + dir + ": tracked camera " + cameras[c].id +
                    " has no calibration for frame " + std::to_string(f) +
                    "; use --frames to skip it");
      }
    }
  }
  std::vector<std::vector<keyer::Keyer>> keyers(std::size_t(std::max(slots, 1)));
  for (auto& per_slot : keyers) {
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      auto k = keyer::Keyer::create(key);
      if (!k) return fail("keyer: " + k.error().message);
      per_slot.push_back(std::move(*k));
    }
  }
  return std::unique_ptr<FrameInput>(new Take(cameras, std::move(camera_dirs), std::move(numbers),
                                              std::move(offsets), std::move(keyers),
                                              std::move(tracked)));
}

}  // namespace studio::hull::cli
