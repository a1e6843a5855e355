#include "preview/frame_images.h"

#include <algorithm>

namespace studio::preview {

template <class Map>
void FrameImageStore::trim(Map& m, std::size_t keep) {
  while (m.size() > keep)
    m.erase(std::min_element(m.begin(), m.end(), [](const auto& a, const auto& b) {
      return a.first.second < b.first.second;
    }));
}

std::vector<std::string> FrameImageStore::to_request(uint64_t frame,
                                                     const std::vector<std::string>& cameras) {
  std::vector<std::string> out;
  for (const auto& c : cameras)
    if (!images_.count({c, frame}) && asked_.emplace(Key{c, frame}, true).second) out.push_back(c);
  trim(asked_, 4 * kept_);
  return out;
}

void FrameImageStore::add(const std::string& camera, FrameImage image) {
  const uint64_t frame = image.frame;
  images_[{camera, frame}] = std::move(image);
  trim(images_, kept_);
}

void FrameImageStore::refuse(const std::string& camera, uint64_t frame) {
  refused_[{camera, frame}] = true;
  trim(refused_, kept_);
}

std::expected<std::vector<FrameImage>, FrameImageStore::Missing> FrameImageStore::find(
    uint64_t frame, const std::vector<std::string>& cameras) const {
  std::vector<FrameImage> out;
  for (const auto& c : cameras) {
    const auto it = images_.find({c, frame});
    if (it == images_.end()) {
      const bool refused = std::any_of(cameras.begin(), cameras.end(), [&](const auto& r) {
        return refused_.count({r, frame}) > 0;
      });
      return std::unexpected(refused ? Missing::refused : Missing::late);
    }
    out.push_back(it->second);
  }
  return out;
}

bool FrameImageStore::settled(uint64_t frame, const std::vector<std::string>& cameras) const {
  bool all = true;
  for (const auto& c : cameras) {
    if (refused_.count({c, frame})) return true;
    all = all && images_.count({c, frame}) > 0;
  }
  return all;
}

bool FrameImageStore::answered(uint64_t frame, const std::vector<std::string>& cameras) const {
  return std::all_of(cameras.begin(), cameras.end(), [&](const std::string& c) {
    return images_.count({c, frame}) > 0 || refused_.count({c, frame}) > 0;
  });
}

std::vector<std::pair<std::string, FrameImage>> FrameImageStore::here(
    uint64_t frame, const std::vector<std::string>& cameras) const {
  std::vector<std::pair<std::string, FrameImage>> out;
  for (const auto& c : cameras)
    if (const auto it = images_.find({c, frame}); it != images_.end())
      out.emplace_back(c, it->second);
  return out;
}

}  // namespace studio::preview
