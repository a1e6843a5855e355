#pragma once
// A reader of any topic of the wire table, untyped: the topic's descriptor and QoS come from its
// row (wire/types.h), and samples are printed by the printer generated from idl/studio.idl for
// its type (studioctl_types.h). Samples are loaned and returned on every path.

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"
#include "studioctl_types.h"
#include "wire/entity.h"
#include "wire/types.h"

namespace studio::ctl {

const wire::TopicRow* find_topic(std::string_view name);
const IdlType* find_type(const dds_topic_descriptor_t* descriptor);
// "studio::AlphaMask" -> "AlphaMask"
std::string_view idl_name(const dds_topic_descriptor_t* descriptor);
std::string qos_text(const wire::TopicRow& row);

struct RawSample {
  const void* data;
  const dds_sample_info_t* info;
  std::optional<wire::Reject> rejected;  // the wire validator's verdict
};

class TopicReader {
 public:
  static Expected<TopicReader> open(const wire::Participant& p, const wire::TopicRow& row);
  // Waits up to `timeout` for samples and calls f for each sample with data. Returns the number
  // visited (0 on timeout).
  Expected<std::size_t> next(std::chrono::nanoseconds timeout,
                             const std::function<void(const RawSample&)>& f);
  const wire::TopicRow& row() const { return *row_; }
  const IdlType& type() const { return *type_; }

 private:
  const wire::TopicRow* row_ = nullptr;
  const IdlType* type_ = nullptr;
  wire::Entity topic_, reader_, waitset_;
};

// The sample as one JSON line or as text, by the generated printer.
std::string print_sample(const IdlType& type, const void* sample, bool json);

}  // namespace studio::ctl
