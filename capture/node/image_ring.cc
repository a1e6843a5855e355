#include "image_ring.h"

#include <algorithm>
#include <cstring>

#include "wire/sample.h"

namespace studio::capture::node {

ImageRing::ImageRing(std::size_t capacity) : slots_(std::max<std::size_t>(capacity, 1)) {}

ImageRing::Slot& ImageRing::next_slot(uint64_t frame, int64_t capture_ns) {
  Slot& s = slots_[next_];
  next_ = (next_ + 1) % slots_.size();
  s.used = true;
  s.frame = frame;
  s.capture_ns = capture_ns;
  newest_ = any_ ? std::max(newest_, frame) : frame;
  any_ = true;
  return s;
}

void ImageRing::push(uint64_t frame, int64_t capture_ns, const Image<Rgb8>& image) {
  std::lock_guard lock(mutex_);
  Slot& s = next_slot(frame, capture_ns);
  if (s.image.width() == image.width() && s.image.height() == image.height()) {
    std::copy(image.pixels().begin(), image.pixels().end(), s.image.pixels().begin());
  } else {
    s.image = image;
  }
}

void ImageRing::push(uint64_t frame, int64_t capture_ns, Image<Rgb8>&& image) {
  std::lock_guard lock(mutex_);
  std::swap(next_slot(frame, capture_ns).image, image);
}

ImageRing::Found ImageRing::find(uint64_t frame, Image3& out) const {
  std::lock_guard lock(mutex_);
  for (const Slot& s : slots_)
    if (s.used && s.frame == frame) {
      out.width = s.image.width();
      out.height = s.image.height();
      out.capture_ns = s.capture_ns;
      const auto* p = reinterpret_cast<const uint8_t*>(s.image.data());
      out.rgb.assign(p, p + std::size_t(out.width) * out.height * 3);
      return Found::ok;
    }
  return !any_ || frame > newest_ ? Found::not_yet : Found::evicted;
}

ImageRequests::ImageRequests(runtime::ServiceLoop& loop, std::vector<Camera> cameras)
    : cameras_(std::move(cameras)),
      replies_(loop.output<studio_ImageReply>({.counter = "image_replies", .rate = false})),
      ok_(loop.counter("image_replies_ok")),
      evicted_(loop.counter("image_replies_evicted")),
      not_yet_(loop.counter("image_replies_not_yet")) {
  loop.input<studio_ImageRequest>(
      {.received = "image_requests_in",
       .rejected = "image_requests_rejected",
       .reason_prefix = "image_requests_rejected_",
       .rate = false},
      [this](const studio_ImageRequest& r, const wire::SampleMeta&) { return on_request(r); });
}

runtime::Outcome ImageRequests::on_request(const studio_ImageRequest& request) {
  const std::string camera(wire::str(request.camera_id));
  const auto it = std::find_if(cameras_.begin(), cameras_.end(),
                               [&](const Camera& c) { return c.id == camera; });
  if (it == cameras_.end()) return {};  // another capture server's camera
  wire::Owned<studio_ImageReply> reply;
  std::memcpy(reply->requester, request.requester, sizeof reply->requester);
  wire::set(reply->camera_id, camera);
  reply->frame = request.frame;
  reply->request_id = request.request_id;
  reply->format = studio_IMAGE_RGB8;
  switch (it->ring->find(request.frame, scratch_)) {
    case ImageRing::Found::ok:
      reply->status = studio_IMAGE_REPLY_OK;
      reply->capture_ns = scratch_.capture_ns;
      reply->width = uint32_t(scratch_.width);
      reply->height = uint32_t(scratch_.height);
      wire::assign(reply->data, scratch_.rgb);
      ok_.add();
      break;
    case ImageRing::Found::evicted:
      reply->status = studio_IMAGE_REPLY_EVICTED;
      evicted_.add();
      break;
    case ImageRing::Found::not_yet:
      reply->status = studio_IMAGE_REPLY_NOT_YET;
      not_yet_.add();
      break;
  }
  (void)replies_.write(*reply);
  return {};
}

}  // namespace studio::capture::node
