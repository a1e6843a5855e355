#pragma once
// The camera images of exact frames that the preview textures the live actor from (issue 16,
// frame-exact texturing, the paper's way): for a mesh built from the masks of frame F the
// preview asks the capture servers for the images of (camera, F); they answer from their rings
// with the image or a refusal (evicted, not yet). FrameImageStore is the bookkeeping: which
// (camera, frame) to ask for (each once), the replies, and whether every image of a frame is
// here. The newest `kept` images and refusals are kept (by frame), 4 x `kept` asked pairs.
// Not thread-safe: the caller serialises (PreviewNode holds its lock).

#include <cstddef>
#include <cstdint>
#include <expected>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace studio::preview {

struct FrameImage {
  int width = 0, height = 0;
  uint64_t frame = 0;
  std::vector<uint8_t> rgb;  // width * height * 3, top row first
};

class FrameImageStore {
 public:
  explicit FrameImageStore(std::size_t kept = 24) : kept_(kept) {}

  // The cameras of `frame` to ask for now: neither here nor asked before; marks them asked.
  std::vector<std::string> to_request(uint64_t frame, const std::vector<std::string>& cameras);
  // A reply: the image of (camera, image.frame), or a refusal of (camera, frame).
  void add(const std::string& camera, FrameImage image);
  void refuse(const std::string& camera, uint64_t frame);

  // Why a frame's images are not all here: a camera refused one, or some are still late.
  enum class Missing { late, refused };
  // The images of exactly `frame`, one per camera in order, once every one is here.
  std::expected<std::vector<FrameImage>, Missing> find(
      uint64_t frame, const std::vector<std::string>& cameras) const;
  // Nothing more to wait for: every image is here or one was refused.
  bool settled(uint64_t frame, const std::vector<std::string>& cameras) const;
  // Every camera has answered: its image is here or it refused (a rig-wide request that takes
  // whichever images came).
  bool answered(uint64_t frame, const std::vector<std::string>& cameras) const;
  // The images of exactly `frame` of those cameras whose image is here, with their ids, in order.
  std::vector<std::pair<std::string, FrameImage>> here(
      uint64_t frame, const std::vector<std::string>& cameras) const;

  std::size_t images() const { return images_.size(); }

 private:
  using Key = std::pair<std::string, uint64_t>;
  template <class Map>
  void trim(Map& m, std::size_t keep);

  std::size_t kept_;
  std::map<Key, FrameImage> images_;
  std::map<Key, bool> refused_, asked_;
};

}  // namespace studio::preview
