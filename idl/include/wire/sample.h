#pragma once
// Owned samples and sequence/string helpers, so library and node code never calls dds_alloc or
// dds_free directly.
//
//   wire::Owned<studio_AlphaMask> m;              // zeroed sample, contents freed on destruction
//   wire::set(m->camera_id, "cam0");              // bounded string; throws std::length_error if
//   too long wire::assign(m->data, std::span(bytes));      // sequence from a span / vector
//   (copies) for (uint8_t b : wire::view(m->data)) ...     // sequence as a span
//
// Sequences filled by these helpers own their buffer (_release = true) and are freed by the
// Owned<T> destructor through the type's descriptor (dds_sample_free(..., DDS_FREE_CONTENTS)).

#include <cstring>
#include <span>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <vector>

#include "wire/types.h"

namespace studio::wire {

namespace detail {
void* seq_alloc(std::size_t bytes);  // zeroed; throws std::bad_alloc
void seq_free(void* p);
void free_contents(void* sample, const dds_topic_descriptor_t* descriptor);
}  // namespace detail

template <class Seq>
using SeqElement = std::remove_pointer_t<decltype(Seq::_buffer)>;

// Resizes a sequence to n elements, keeping the first min(old, n) and zeroing the rest.
template <class Seq>
void resize(Seq& seq, uint32_t n) {
  using E = SeqElement<Seq>;
  static_assert(std::is_trivially_copyable_v<E>, "sequences of flat elements only");
  E* buffer = n ? static_cast<E*>(detail::seq_alloc(sizeof(E) * n)) : nullptr;
  const uint32_t keep = seq._length < n ? seq._length : n;
  if (keep) std::memcpy(buffer, seq._buffer, sizeof(E) * keep);
  if (seq._release) detail::seq_free(seq._buffer);
  seq._buffer = buffer;
  seq._length = n;
  seq._maximum = n;
  seq._release = true;
}

template <class Seq, class E>
void assign(Seq& seq, std::span<const E> src) {
  static_assert(std::is_same_v<std::remove_cv_t<E>, SeqElement<Seq>>, "element type mismatch");
  if (src.size() > UINT32_MAX) throw std::length_error("wire::assign: sequence too long");
  resize(seq, 0);
  resize(seq, static_cast<uint32_t>(src.size()));
  if (!src.empty()) std::memcpy(seq._buffer, src.data(), sizeof(E) * src.size());
}
template <class Seq, class E>
void assign(Seq& seq, const std::vector<E>& src) {
  assign(seq, std::span<const E>(src));
}

template <class Seq>
std::span<const SeqElement<Seq>> view(const Seq& seq) {
  return {seq._buffer, seq._buffer ? seq._length : 0u};
}
template <class Seq>
std::span<SeqElement<Seq>> view(Seq& seq) {
  return {seq._buffer, seq._buffer ? seq._length : 0u};
}
template <class Seq>
std::vector<SeqElement<Seq>> to_vector(const Seq& seq) {
  auto v = view(seq);
  return {v.begin(), v.end()};
}

// Bounded strings are char[N] (string<N-1> in IDL).
template <std::size_t N>
void set(char (&dst)[N], std::string_view value) {
  if (value.size() >= N) throw std::length_error("wire::set: string longer than its IDL bound");
  std::memcpy(dst, value.data(), value.size());
  std::memset(dst + value.size(), 0, N - value.size());
}
template <std::size_t N>
std::string_view str(const char (&src)[N]) {
  const void* nul = std::memchr(src, 0, N);
  return {src, nul ? static_cast<std::size_t>(static_cast<const char*>(nul) - src) : N};
}

// A zero-initialised sample of a topic type that frees its sequences on destruction. Move-only.
template <WireType T>
class Owned {
 public:
  Owned() { std::memset(&value_, 0, sizeof value_); }
  ~Owned() { release(); }
  Owned(Owned&& other) noexcept {
    std::memcpy(&value_, &other.value_, sizeof value_);
    std::memset(&other.value_, 0, sizeof value_);
  }
  Owned& operator=(Owned&& other) noexcept {
    if (this != &other) {
      release();
      std::memcpy(&value_, &other.value_, sizeof value_);
      std::memset(&other.value_, 0, sizeof value_);
    }
    return *this;
  }
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;

  T* get() { return &value_; }
  const T* get() const { return &value_; }
  T* operator->() { return &value_; }
  const T* operator->() const { return &value_; }
  T& operator*() { return value_; }
  const T& operator*() const { return value_; }

 private:
  void release() {
    detail::free_contents(&value_, TopicTraits<T>::descriptor());
    std::memset(&value_, 0, sizeof value_);
  }
  T value_;
};

}  // namespace studio::wire
