#pragma once
// Non-owning, stride-aware image views and a small owning image.
//
// ImageView<T> looks at width x height pixels of type T; rows are stride_bytes apart (stride may
// exceed width*sizeof(T): padding, or a sub-rectangle of a larger image). Pixel types:
// uint8_t (mono / mask: 0 background, 255 actor), Rgb8, Bgr8, float. A view never owns memory;
// the caller keeps the buffer alive.

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace studio {

struct Rgb8 {
  uint8_t r, g, b;
  friend bool operator==(const Rgb8&, const Rgb8&) = default;
};
struct Bgr8 {
  uint8_t b, g, r;
  friend bool operator==(const Bgr8&, const Bgr8&) = default;
};
static_assert(sizeof(Rgb8) == 3 && sizeof(Bgr8) == 3);

template <class T>
class ImageView {
 public:
  ImageView() = default;
  ImageView(T* data, int width, int height, std::ptrdiff_t stride_bytes)
      : data_(data), width_(width), height_(height), stride_(stride_bytes) {
    assert(width >= 0 && height >= 0 && stride_bytes >= std::ptrdiff_t(width * sizeof(T)));
  }
  ImageView(T* data, int width, int height)
      : ImageView(data, width, height, std::ptrdiff_t(width) * std::ptrdiff_t(sizeof(T))) {}
  // A view of T converts to a view of const T.
  template <class U, class = std::enable_if_t<std::is_same_v<const U, T>>>
  ImageView(const ImageView<U>& other)  // NOLINT(google-explicit-constructor)
      : ImageView(other.data(), other.width(), other.height(), other.stride_bytes()) {}

  T* data() const { return data_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::ptrdiff_t stride_bytes() const { return stride_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  bool contiguous() const { return stride_ == std::ptrdiff_t(width_ * sizeof(T)); }

  T* row(int y) const {
    assert(y >= 0 && y < height_);
    using Byte = std::conditional_t<std::is_const_v<T>, const std::byte, std::byte>;
    return reinterpret_cast<T*>(reinterpret_cast<Byte*>(data_) + std::ptrdiff_t(y) * stride_);
  }
  T& operator()(int x, int y) const {
    assert(x >= 0 && x < width_);
    return row(y)[x];
  }
  // Sub-rectangle [x, x+w) x [y, y+h), sharing memory.
  ImageView sub(int x, int y, int w, int h) const {
    assert(x >= 0 && y >= 0 && x + w <= width_ && y + h <= height_);
    return ImageView(row(y) + x, w, h, stride_);
  }

 private:
  T* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
  std::ptrdiff_t stride_ = 0;
};

// Owning, contiguous image.
template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, T fill = T{})
      : width_(width), height_(height), pixels_(std::size_t(width) * std::size_t(height), fill) {}
  // A moved-from image is empty (0x0), never a size without pixels.
  Image(Image&& other) noexcept
      : width_(std::exchange(other.width_, 0)),
        height_(std::exchange(other.height_, 0)),
        pixels_(std::move(other.pixels_)) {
    other.pixels_.clear();
  }
  Image& operator=(Image&& other) noexcept {
    if (this == &other) return *this;
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    pixels_ = std::move(other.pixels_);
    other.pixels_.clear();
    return *this;
  }
  Image(const Image&) = default;
  Image& operator=(const Image&) = default;

  int width() const { return width_; }
  int height() const { return height_; }
  T* data() { return pixels_.data(); }
  const T* data() const { return pixels_.data(); }
  T& operator()(int x, int y) { return pixels_[std::size_t(y) * width_ + x]; }
  const T& operator()(int x, int y) const { return pixels_[std::size_t(y) * width_ + x]; }
  ImageView<T> view() { return ImageView<T>(pixels_.data(), width_, height_); }
  ImageView<const T> view() const { return ImageView<const T>(pixels_.data(), width_, height_); }
  std::vector<T>& pixels() { return pixels_; }
  const std::vector<T>& pixels() const { return pixels_; }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T> pixels_;
};

using MaskView = ImageView<const uint8_t>;  // 0 background, non-zero actor
using Mask = Image<uint8_t>;

}  // namespace studio
