#include "studioctl/topic_reader.h"

#include <algorithm>

namespace studio::ctl {

const wire::TopicRow* find_topic(std::string_view name) {
  for (const auto& row : wire::topic_table())
    if (name == row.name) return &row;
  return nullptr;
}

const IdlType* find_type(const dds_topic_descriptor_t* descriptor) {
  for (const auto& t : idl_types())
    if (t.descriptor == descriptor) return &t;
  return nullptr;
}

std::string_view idl_name(const dds_topic_descriptor_t* descriptor) {
  std::string_view n = descriptor->m_typename;
  if (auto pos = n.rfind("::"); pos != std::string_view::npos) n.remove_prefix(pos + 2);
  return n;
}

std::string qos_text(const wire::TopicRow& row) {
  std::string s = row.reliable ? "reliable" : "best-effort";
  s += row.transient_local ? ", transient-local" : ", volatile";
  s += ", keep-last " + std::to_string(row.depth);
  if (row.liveliness_lease_s > 0)
    s += ", liveliness lease " + std::to_string(row.liveliness_lease_s) + " s";
  return s;
}

Expected<TopicReader> TopicReader::open(const wire::Participant& p, const wire::TopicRow& row) {
  TopicReader r;
  r.row_ = &row;
  r.type_ = find_type(row.descriptor);
  if (r.type_ == nullptr)  // the generator emits every IDL struct: only a build mix-up gets here
    return fail(std::string("no printer for type ") + row.descriptor->m_typename);
  const wire::Qos qos = wire::qos_for(row.id);
  r.topic_ =
      wire::Entity(dds_create_topic(p.handle(), row.descriptor, row.name, qos.get(), nullptr));
  if (r.topic_.handle() < 0)
    return fail(wire::dds_error(std::string("topic ") + row.name, r.topic_.handle()));
  r.reader_ = wire::Entity(dds_create_reader(p.handle(), r.topic_.handle(), qos.get(), nullptr));
  if (r.reader_.handle() < 0) return fail(wire::dds_error("reader", r.reader_.handle()));
  r.waitset_ = wire::Entity(dds_create_waitset(p.handle()));
  if (r.waitset_.handle() < 0) return fail(wire::dds_error("waitset", r.waitset_.handle()));
  const dds_entity_t cond = dds_create_readcondition(r.reader_.handle(), DDS_ANY_STATE);
  if (cond < 0) return fail(wire::dds_error("read condition", cond));
  if (auto rc = dds_waitset_attach(r.waitset_.handle(), cond, 0); rc < 0)
    return fail(wire::dds_error("waitset attach", rc));
  return r;
}

Expected<std::size_t> TopicReader::next(std::chrono::nanoseconds timeout,
                                        const std::function<void(const RawSample&)>& f) {
  const dds_return_t w = dds_waitset_wait(waitset_.handle(), nullptr, 0, timeout.count());
  if (w < 0) return fail(wire::dds_error("waitset wait", w));
  std::size_t visited = 0;
  constexpr int kBatch = 32;
  while (true) {
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = dds_take(reader_.handle(), samples, infos, kBatch, kBatch);
    if (n < 0) return fail(wire::dds_error("take", n));
    struct Loan {  // returned on every path, including exceptions thrown by f
      dds_entity_t reader;
      void** samples;
      dds_return_t n;
      ~Loan() {
        if (n > 0) dds_return_loan(reader, samples, n);
      }
    } loan{reader_.handle(), samples, n};
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      f(RawSample{samples[i], &infos[i], row_->validate(samples[i])});
      ++visited;
    }
    if (n < kBatch) break;
  }
  return visited;
}

std::string print_sample(const IdlType& type, const void* sample, bool json) {
  Printer p(json ? Printer::Mode::json : Printer::Mode::text);
  p.begin_object();
  type.print(p, sample);
  p.end_object();
  return p.take();
}

}  // namespace studio::ctl
