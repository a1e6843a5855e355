#include "scene_render/render_target.h"

#include <cstring>
#include <utility>

#include "gl.h"

namespace studio::scene_render {

Expected<RenderTarget> RenderTarget::create(int width, int height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    return fail("render target: size " + std::to_string(width) + "x" + std::to_string(height) +
                " out of range (1..16384)");
  RenderTarget t;
  t.width_ = width;
  t.height_ = height;
  glGenTextures(1, &t.colour_);
  glBindTexture(GL_TEXTURE_2D, t.colour_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glGenRenderbuffers(1, &t.depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, t.depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glGenFramebuffers(1, &t.fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, t.fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t.colour_, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t.depth_);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return fail("render target: framebuffer incomplete (status 0x" + std::to_string(status) + ")");
  t.row_.resize(static_cast<std::size_t>(width) * 4);
  return t;
}

RenderTarget::RenderTarget(RenderTarget&& o) noexcept { *this = std::move(o); }

RenderTarget& RenderTarget::operator=(RenderTarget&& o) noexcept {
  if (this != &o) {
    release();
    width_ = std::exchange(o.width_, 0);
    height_ = std::exchange(o.height_, 0);
    fbo_ = std::exchange(o.fbo_, 0);
    colour_ = std::exchange(o.colour_, 0);
    depth_ = std::exchange(o.depth_, 0);
    row_ = std::move(o.row_);
  }
  return *this;
}

RenderTarget::~RenderTarget() { release(); }

void RenderTarget::release() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (colour_) glDeleteTextures(1, &colour_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
  fbo_ = colour_ = depth_ = 0;
}

void RenderTarget::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::bind_default(int width, int height) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
}

void RenderTarget::read_rgba(std::vector<std::uint8_t>& out) const {
  const std::size_t stride = static_cast<std::size_t>(width_) * 4;
  if (out.size() != stride * height_) out.resize(stride * height_);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
  // OpenGL's rows are bottom first: swap into image order.
  for (int y = 0; y < height_ / 2; ++y) {
    std::uint8_t* a = out.data() + stride * y;
    std::uint8_t* b = out.data() + stride * (height_ - 1 - y);
    std::memcpy(row_.data(), a, stride);
    std::memcpy(a, b, stride);
    std::memcpy(b, row_.data(), stride);
  }
}

}  // namespace studio::scene_render
