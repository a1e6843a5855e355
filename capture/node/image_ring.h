#pragma once
// Frame-exact images on request (issue 16, the paper's way): each camera keeps its last few
// frames in an ImageRing; the preview asks for (camera, frame) on studio/camera/image_request and
// the capture node answers on studio/camera/image_reply from the ring: the image of exactly that
// frame (IMAGE_REPLY_OK, raw RGB8), or EVICTED (older than the ring) or NOT_YET (not captured
// yet). A reply never carries another frame's image.
//
// Threads: push() runs on the camera's grab thread, find() on the loop thread; the ring's mutex
// guards the slots (find copies one frame under the lock, ~1 ms for 704x576; push by move only
// swaps buffers).

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/image.h"
#include "runtime/service_loop.h"

namespace studio::capture::node {

class ImageRing {
 public:
  explicit ImageRing(std::size_t capacity);

  // Keeps a copy of the frame, replacing the oldest slot.
  void push(uint64_t frame, int64_t capture_ns, const Image<Rgb8>& image);
  // Keeps the frame's image itself (no copy); `image` gets the oldest slot's buffer (stale).
  void push(uint64_t frame, int64_t capture_ns, Image<Rgb8>&& image);

  enum class Found { ok, evicted, not_yet };
  struct Image3 {
    int width = 0, height = 0;
    int64_t capture_ns = 0;
    std::vector<uint8_t> rgb;  // width * height * 3
  };
  // ok: `out` holds exactly `frame` (its buffer reused between calls).
  Found find(uint64_t frame, Image3& out) const;
  std::size_t capacity() const { return slots_.size(); }

 private:
  struct Slot {
    bool used = false;
    uint64_t frame = 0;
    int64_t capture_ns = 0;
    Image<Rgb8> image;
  };
  Slot& next_slot(uint64_t frame, int64_t capture_ns);  // mutex_ held
  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::size_t next_ = 0;
  uint64_t newest_ = 0;
  bool any_ = false;
};

// The request side: one input (ImageRequest) and one output (ImageReply) on the node's loop.
// Requests for cameras of other capture nodes are ignored; counters: image_requests_in,
// image_replies_ok, image_replies_evicted, image_replies_not_yet.
class ImageRequests {
 public:
  struct Camera {
    std::string id;
    const ImageRing* ring;
  };
  ImageRequests(runtime::ServiceLoop& loop, std::vector<Camera> cameras);

 private:
  runtime::Outcome on_request(const studio_ImageRequest& request);

  std::vector<Camera> cameras_;
  runtime::Output<studio_ImageReply>& replies_;
  runtime::Counter& ok_;
  runtime::Counter& evicted_;
  runtime::Counter& not_yet_;
  ImageRing::Image3 scratch_;
};

}  // namespace studio::capture::node
