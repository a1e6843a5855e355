#pragma once
// Typed topics, writers and readers over the idlc-generated C types.
//
//   auto p = wire::Participant::create().value();
//   auto topic = wire::Topic<studio_AlphaMask>::create(p).value();       // name + QoS from the
//   table auto writer = wire::Writer<studio_AlphaMask>::create(p, topic).value(); auto reader =
//   wire::Reader<studio_AlphaMask>::create(p, topic).value(); reader.visit([](const
//   studio_AlphaMask& m, const wire::SampleMeta&) { ... });  // loaned, zero-copy for (auto& s :
//   reader.take()) use(*s.data);                          // owned copies
//
// Every received sample with data is validated (wire/types.h validators) before it is handed
// out; a rejected sample is dropped and counted per reason (Reader::rejected()). Loans are
// returned on every path, including exceptions thrown by a visitor.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "wire/entity.h"
#include "wire/sample.h"

namespace studio::wire {

template <WireType T>
class Topic {
 public:
  // name: empty = the table's name for T. QoS always from T's table row.
  static Expected<Topic> create(const Participant& p, const std::string& name = {});
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  explicit Topic(Entity e) : entity_(std::move(e)) {}
  Entity entity_;
};

namespace detail {
Expected<Entity> make_topic(const Participant& p, TopicId id, const dds_topic_descriptor_t* desc,
                            const std::string& name);
}  // namespace detail

template <WireType T>
Expected<Topic<T>> Topic<T>::create(const Participant& p, const std::string& name) {
  auto e = detail::make_topic(p, TopicTraits<T>::id, TopicTraits<T>::descriptor(), name);
  if (!e) return std::unexpected(e.error());
  return Topic(std::move(*e));
}

struct SampleMeta {
  bool valid_data = false;  // false: an instance state change only (key fields are set)
  bool alive = false;       // instance alive (not disposed, has writers)
  bool disposed = false;    // instance disposed by a writer
  int64_t source_timestamp = 0;
  dds_instance_handle_t instance = 0;
};

template <WireType T>
struct Received {
  Owned<T> data;
  SampleMeta meta;
};

struct RejectCounts {
  std::array<uint64_t, kRejectReasons> by_reason{};
  uint64_t total() const;
  uint64_t operator[](Reject r) const { return by_reason[static_cast<std::size_t>(r)]; }
};

class WriterBase {
 public:
  dds_entity_t handle() const { return entity_.handle(); }
  // Readers currently matched.
  uint32_t matched_readers() const;
  // Waits until at least `count` readers matched (DESIGN §2: wait for match before publishing).
  bool wait_for_readers(uint32_t count, std::chrono::milliseconds timeout) const;
  // For manual liveliness; automatic liveliness needs nothing.
  void assert_liveliness() const;

 protected:
  WriterBase() = default;
  explicit WriterBase(Entity e) : entity_(std::move(e)) {}
  static Expected<Entity> make(const Participant& p, dds_entity_t topic, TopicId id);
  Expected<void> write_raw(const void* sample, const char* what) const;
  Expected<void> dispose_raw(const void* sample) const;
  Entity entity_;
};

template <WireType T>
class Writer : public WriterBase {
 public:
  static Expected<Writer> create(const Participant& p, const Topic<T>& topic) {
    auto e = make(p, topic.handle(), TopicTraits<T>::id);
    if (!e) return std::unexpected(e.error());
    return Writer(std::move(*e));
  }
  // Writers do not validate: the reader is the trust boundary (and tests send malformed samples).
  Expected<void> write(const T& sample) const { return write_raw(&sample, "write"); }
  // Disposes the instance named by the key fields of `key` (readers see it disappear).
  Expected<void> dispose(const T& key) const { return dispose_raw(&key); }

 private:
  explicit Writer(Entity e) : WriterBase(std::move(e)) {}
};

class ReaderBase {
 public:
  ReaderBase(ReaderBase&&) noexcept = default;
  ReaderBase& operator=(ReaderBase&& other) noexcept;
  ~ReaderBase();  // removes the listener (waiting for a running callback), then the reader

  dds_entity_t handle() const { return entity_.handle(); }

  // Runs `f` each time data arrives (DDS DATA_AVAILABLE listener), on the thread that delivers
  // it: Cyclone's receive thread for remote writers, the writing thread for a writer in this
  // process. Replaces any earlier callback; an empty `f` removes it. This saves the thread
  // hand-off of a waitset (one wake-up per sample instead of two), which matters most on small,
  // latency-bound topics. Contract: `f` typically calls visit()/take() on this reader; while a
  // callback is
  // installed the reader must not be moved, nor read from another thread. `f` must not block
  // (it holds up Cyclone's receive path); exceptions it throws are logged and swallowed.
  // Installing or removing waits for a running callback to finish.
  Expected<void> on_data_available(std::function<void()> f);

  const RejectCounts& rejected() const { return rejected_; }
  uint32_t matched_writers() const;
  // Writers whose liveliness is currently asserted.
  uint32_t alive_writers() const;
  const char* topic_name() const { return row_->name; }

  // Sample/instance selection masks (DDS_*_STATE bits).
  static constexpr uint32_t kAny = DDS_ANY_STATE;
  static constexpr uint32_t kAlive =
      DDS_ANY_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE;
  static constexpr uint32_t kNotRead =
      DDS_NOT_READ_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ANY_INSTANCE_STATE;

 protected:
  ReaderBase() = default;
  ReaderBase(Entity e, const TopicRow& row) : entity_(std::move(e)), row_(&row) {}
  static Expected<Entity> make(const Participant& p, dds_entity_t topic, TopicId id,
                               int32_t history_depth);

  using Sink = void (*)(void* ctx, std::size_t index, void* sample, const SampleMeta& meta);
  // Owned path: takes/reads up to `max` samples into `buffers` (zeroed samples the caller
  // owns), validates, and calls sink for the accepted ones. Returns the number accepted.
  std::size_t fill(bool take, uint32_t mask, std::span<void*> buffers, void* ctx, Sink sink);
  // Loaned path: visits accepted samples in place; the loan is returned on every path.
  std::size_t visit_loaned(bool take, uint32_t mask, std::size_t max, void* ctx, Sink sink);

 private:
  bool accept(const void* sample, const dds_sample_info_t& info);
  void remove_listener();
  Entity entity_;
  std::unique_ptr<std::function<void()>> on_data_;
  const TopicRow* row_ = nullptr;
  RejectCounts rejected_;
  std::array<bool, kRejectReasons> logged_{};
};

template <WireType T>
class Reader : public ReaderBase {
 public:
  // history_depth > 0 keeps that many samples per instance in this reader instead of the
  // topic's depth (types.h): a reader that must see every sample of a keep-last topic (e.g. the
  // per-frame pose of a tracked camera) even when it falls behind. History is local to the
  // reader; writers and other readers are unaffected.
  static Expected<Reader> create(const Participant& p, const Topic<T>& topic,
                                 int32_t history_depth = 0) {
    auto e = make(p, topic.handle(), TopicTraits<T>::id, history_depth);
    if (!e) return std::unexpected(e.error());
    return Reader(std::move(*e));
  }

  // Takes (removes) up to max valid samples as owned copies.
  std::vector<Received<T>> take(std::size_t max = 64, uint32_t mask = kAny) {
    return collect(true, max, mask);
  }
  // Reads (leaves in the reader cache) up to max samples; with kAlive the current alive
  // instances, e.g. the scene nodes that exist now.
  std::vector<Received<T>> read(std::size_t max = 64, uint32_t mask = kAny) {
    return collect(false, max, mask);
  }
  // Visits accepted loaned samples without copying: f(const T&, const SampleMeta&). Samples are
  // taken (removed). meta.valid_data is false for dispose/unregister notices (key fields only).
  // Returns the number visited.
  template <class F>
  std::size_t visit(F&& f, std::size_t max = 64, uint32_t mask = kAny) {
    auto sink = [](void* ctx, std::size_t, void* sample, const SampleMeta& meta) {
      (*static_cast<F*>(ctx))(*static_cast<const T*>(sample), meta);
    };
    return visit_loaned(true, mask, max, &f, sink);
  }

 private:
  explicit Reader(Entity e) : ReaderBase(std::move(e), TopicTraits<T>::row()) {}

  std::vector<Received<T>> collect(bool take, std::size_t max, uint32_t mask) {
    std::vector<Owned<T>> storage(max);
    std::vector<void*> buffers(max);
    for (std::size_t i = 0; i < max; ++i) buffers[i] = storage[i].get();
    std::vector<Received<T>> out;
    struct Ctx {
      std::vector<Owned<T>>* storage;
      std::vector<Received<T>>* out;
    } ctx{&storage, &out};
    auto sink = [](void* c, std::size_t i, void*, const SampleMeta& meta) {
      auto* x = static_cast<Ctx*>(c);
      x->out->push_back(Received<T>{std::move((*x->storage)[i]), meta});
    };
    fill(take, mask, buffers, &ctx, sink);
    return out;
  }
};

}  // namespace studio::wire
