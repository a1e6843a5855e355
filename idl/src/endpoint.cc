// Topic/writer/reader plumbing shared by all Writer<T>/Reader<T>: creation with the table's
// QoS, match and liveliness status, and the take/read paths that validate and count.

#include "wire/endpoint.h"

#include <thread>

#include "core/log.h"

namespace studio::wire {

namespace detail {

void* seq_alloc(std::size_t bytes) {
  void* p = dds_alloc(bytes);  // zeroed
  if (!p) throw std::bad_alloc();
  return p;
}
void seq_free(void* p) { dds_free(p); }
void free_contents(void* sample, const dds_topic_descriptor_t* descriptor) {
  dds_sample_free(sample, descriptor, DDS_FREE_CONTENTS);
}

Expected<Entity> make_topic(const Participant& p, TopicId id, const dds_topic_descriptor_t* desc,
                            const std::string& name) {
  const TopicRow& row = topic_row(id);
  const std::string& topic_name = name.empty() ? std::string(row.name) : name;
  Qos qos = qos_for(id);
  const dds_entity_t e = dds_create_topic(p.handle(), desc, topic_name.c_str(), qos.get(), nullptr);
  if (e < 0) return fail(dds_error("dds: create topic " + topic_name, e));
  return Entity(e);
}

}  // namespace detail

uint64_t RejectCounts::total() const {
  uint64_t n = 0;
  for (uint64_t c : by_reason) n += c;
  return n;
}

Expected<Entity> WriterBase::make(const Participant& p, dds_entity_t topic, TopicId id) {
  Qos qos = qos_for(id);
  const dds_entity_t e = dds_create_writer(p.handle(), topic, qos.get(), nullptr);
  if (e < 0) return fail(dds_error(std::string("dds: create writer for ") + topic_row(id).name, e));
  return Entity(e);
}

Expected<void> WriterBase::write_raw(const void* sample, const char* what) const {
  if (dds_return_t rc = dds_write(entity_.handle(), sample); rc < 0)
    return fail(dds_error(std::string("dds: ") + what, rc));
  return {};
}

Expected<void> WriterBase::dispose_raw(const void* sample) const {
  if (dds_return_t rc = dds_dispose(entity_.handle(), sample); rc < 0)
    return fail(dds_error("dds: dispose", rc));
  return {};
}

uint32_t WriterBase::matched_readers() const {
  dds_publication_matched_status_t st{};
  if (dds_get_publication_matched_status(entity_.handle(), &st) < 0) return 0;
  return st.current_count;
}

bool WriterBase::wait_for_readers(uint32_t count, std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (matched_readers() < count) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

void WriterBase::assert_liveliness() const { dds_assert_liveliness(entity_.handle()); }

Expected<Entity> ReaderBase::make(const Participant& p, dds_entity_t topic, TopicId id,
                                  int32_t history_depth) {
  Qos qos = qos_for(id);
  if (history_depth > 0) dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, history_depth);
  const dds_entity_t e = dds_create_reader(p.handle(), topic, qos.get(), nullptr);
  if (e < 0) return fail(dds_error(std::string("dds: create reader for ") + topic_row(id).name, e));
  return Entity(e);
}

ReaderBase& ReaderBase::operator=(ReaderBase&& other) noexcept {
  if (this != &other) {
    remove_listener();
    entity_ = std::move(other.entity_);
    on_data_ = std::move(other.on_data_);
    row_ = other.row_;
    rejected_ = other.rejected_;
    logged_ = other.logged_;
  }
  return *this;
}

ReaderBase::~ReaderBase() {
  remove_listener();
  entity_.reset();
}

// Without this, a callback can still run (and fail to take) while dds_delete tears the reader
// down; dds_set_listener waits for a callback in progress.
void ReaderBase::remove_listener() {
  if (on_data_ && entity_) dds_set_listener(entity_.handle(), nullptr);
  on_data_.reset();
}

Expected<void> ReaderBase::on_data_available(std::function<void()> f) {
  auto next = f ? std::make_unique<std::function<void()>>(std::move(f)) : nullptr;
  dds_listener_t* listener = dds_create_listener(next.get());
  if (next) {
    dds_lset_data_available(listener, [](dds_entity_t, void* arg) {
      try {
        (*static_cast<std::function<void()>*>(arg))();
      } catch (const std::exception& e) {
        STUDIO_LOG(error, "dds") << "data-available callback threw: " << e.what();
      }
    });
  }
  // Cyclone waits for a callback in progress before it swaps the listener, so the old
  // function object can be freed afterwards.
  const dds_return_t rc = dds_set_listener(entity_.handle(), next ? listener : nullptr);
  dds_delete_listener(listener);
  if (rc < 0) return fail(dds_error(std::string("dds: set listener on ") + row_->name, rc));
  on_data_ = std::move(next);
  return {};
}

uint32_t ReaderBase::matched_writers() const {
  dds_subscription_matched_status_t st{};
  if (dds_get_subscription_matched_status(entity_.handle(), &st) < 0) return 0;
  return st.current_count;
}

uint32_t ReaderBase::alive_writers() const {
  dds_liveliness_changed_status_t st{};
  if (dds_get_liveliness_changed_status(entity_.handle(), &st) < 0) return 0;
  return st.alive_count;
}

namespace {
SampleMeta meta_of(const dds_sample_info_t& info) {
  SampleMeta m;
  m.valid_data = info.valid_data;
  m.alive = info.instance_state == DDS_IST_ALIVE;
  m.disposed = info.instance_state == DDS_IST_NOT_ALIVE_DISPOSED;
  m.source_timestamp = info.source_timestamp;
  m.instance = info.instance_handle;
  return m;
}
}  // namespace

bool ReaderBase::accept(const void* sample, const dds_sample_info_t& info) {
  if (!info.valid_data) return true;  // instance state change: key fields only
  const Verdict v = row_->validate(sample);
  if (!v) return true;
  // A sample read (not taken) before was already counted.
  if (info.sample_state == DDS_SST_READ) return false;
  const auto r = static_cast<std::size_t>(*v);
  ++rejected_.by_reason[r];
  if (!logged_[r]) {
    logged_[r] = true;
    STUDIO_LOG(warn, "dds") << row_->name << ": rejected a sample (" << reject_name(*v)
                            << "); further rejections are counted, not logged";
  }
  return false;
}

std::size_t ReaderBase::fill(bool take, uint32_t mask, std::span<void*> buffers, void* ctx,
                             Sink sink) {
  if (buffers.empty()) return 0;
  std::vector<dds_sample_info_t> infos(buffers.size());
  const auto n = static_cast<uint32_t>(buffers.size());
  const dds_return_t got =
      take ? dds_take_mask(entity_.handle(), buffers.data(), infos.data(), n, n, mask)
           : dds_read_mask(entity_.handle(), buffers.data(), infos.data(), n, n, mask);
  if (got < 0) {
    STUDIO_LOG(warn, "dds") << dds_error(std::string(row_->name) + (take ? ": take" : ": read"),
                                         got);
    return 0;
  }
  std::size_t accepted = 0;
  for (dds_return_t i = 0; i < got; ++i) {
    if (!accept(buffers[i], infos[i])) continue;
    sink(ctx, std::size_t(i), buffers[i], meta_of(infos[i]));
    ++accepted;
  }
  return accepted;
}

namespace {
// Returns a loan on every path (including exceptions thrown by the visitor).
struct LoanGuard {
  dds_entity_t reader;
  std::vector<void*>& buffers;
  int32_t count;
  ~LoanGuard() {
    if (count > 0) dds_return_loan(reader, buffers.data(), count);
  }
};
}  // namespace

std::size_t ReaderBase::visit_loaned(bool take, uint32_t mask, std::size_t max, void* ctx,
                                     Sink sink) {
  if (max == 0) return 0;
  std::vector<void*> buffers(max, nullptr);  // buffers[0] == nullptr: Cyclone lends the samples
  std::vector<dds_sample_info_t> infos(max);
  const auto n = static_cast<uint32_t>(max);
  const dds_return_t got =
      take ? dds_take_mask(entity_.handle(), buffers.data(), infos.data(), n, n, mask)
           : dds_read_mask(entity_.handle(), buffers.data(), infos.data(), n, n, mask);
  if (got < 0) {
    STUDIO_LOG(warn, "dds") << dds_error(std::string(row_->name) + ": take (loan)", got);
    return 0;
  }
  LoanGuard guard{entity_.handle(), buffers, got};
  std::size_t accepted = 0;
  for (dds_return_t i = 0; i < got; ++i) {
    if (!accept(buffers[i], infos[i])) continue;
    sink(ctx, std::size_t(i), buffers[i], meta_of(infos[i]));
    ++accepted;
  }
  return accepted;
}

}  // namespace studio::wire
