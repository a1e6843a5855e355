// RAII handles, QoS from the table, participant/domain creation, guard conditions, waitsets.

#include "wire/entity.h"

#include <cstdlib>
#include <string>

#include "core/log.h"
#include "wire/endpoint.h"

namespace studio::wire {

std::string dds_error(std::string_view what, dds_return_t rc) {
  return std::string(what) + ": " + dds_strretcode(rc);
}

Entity& Entity::operator=(Entity&& other) noexcept {
  if (this != &other) {
    reset();
    handle_ = other.handle_;
    other.handle_ = 0;
  }
  return *this;
}

void Entity::reset() {
  if (handle_ > 0) {
    // Deleting a child of an already deleted entity reports BAD_PARAMETER/ALREADY_DELETED: fine.
    dds_delete(handle_);
  }
  handle_ = 0;
}

Qos& Qos::operator=(Qos&& other) noexcept {
  std::swap(qos_, other.qos_);
  return *this;
}

Qos qos_for(TopicId id) {
  const TopicRow& row = topic_row(id);
  Qos q;
  dds_qset_reliability(q.get(),
                       row.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_durability(
      q.get(), row.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(q.get(), DDS_HISTORY_KEEP_LAST, row.depth);
  if (row.liveliness_lease_s > 0)
    dds_qset_liveliness(q.get(), DDS_LIVELINESS_AUTOMATIC, DDS_SECS(row.liveliness_lease_s));
  return q;
}

dds_domainid_t default_domain() {
  if (const char* env = std::getenv("STUDIO_DDS_DOMAIN"); env && *env) {
    char* end = nullptr;
    const unsigned long v = std::strtoul(env, &end, 10);
    if (end && *end == '\0' && v <= 232) return static_cast<dds_domainid_t>(v);
    STUDIO_LOG(warn, "dds") << "ignoring STUDIO_DDS_DOMAIN='" << env << "' (expected 0..232)";
  }
  return DDS_DOMAIN_DEFAULT;
}

Expected<Participant> Participant::create(dds_domainid_t domain, const std::string& config) {
  Participant p;
  if (!config.empty()) {
    if (domain == DDS_DOMAIN_DEFAULT)
      return fail("dds: an explicit config needs an explicit domain id");
    const dds_entity_t d = dds_create_domain(domain, config.c_str());
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET)
      return fail(dds_error("dds: create domain " + std::to_string(domain), d));
    if (d > 0) p.domain_ = Entity(d);
  }
  const dds_entity_t e = dds_create_participant(domain, nullptr, nullptr);
  if (e < 0) return fail(dds_error("dds: create participant", e));
  p.participant_ = Entity(e);
  return p;
}

Expected<GuardCondition> GuardCondition::create(const Participant& participant) {
  const dds_entity_t e = dds_create_guardcondition(participant.handle());
  if (e < 0) return fail(dds_error("dds: create guard condition", e));
  GuardCondition g;
  g.entity_ = Entity(e);
  return g;
}

void GuardCondition::trigger() const { dds_set_guardcondition(entity_.handle(), true); }

bool GuardCondition::take() const {
  bool triggered = false;
  dds_take_guardcondition(entity_.handle(), &triggered);
  return triggered;
}

Expected<WaitSet> WaitSet::create(const Participant& participant) {
  const dds_entity_t e = dds_create_waitset(participant.handle());
  if (e < 0) return fail(dds_error("dds: create waitset", e));
  WaitSet w;
  w.waitset_ = Entity(e);
  return w;
}

Expected<void> WaitSet::attach(const ReaderBase& reader, dds_attach_t token) {
  const dds_entity_t cond = dds_create_readcondition(reader.handle(), ReaderBase::kNotRead);
  if (cond < 0) return fail(dds_error("dds: create read condition", cond));
  Entity owned(cond);
  if (dds_return_t rc = dds_waitset_attach(waitset_.handle(), cond, token); rc < 0)
    return fail(dds_error("dds: attach reader", rc));
  conditions_.push_back(std::move(owned));
  return {};
}

Expected<void> WaitSet::attach(const GuardCondition& guard, dds_attach_t token) {
  if (dds_return_t rc = dds_waitset_attach(waitset_.handle(), guard.handle(), token); rc < 0)
    return fail(dds_error("dds: attach guard condition", rc));
  return {};
}

std::vector<dds_attach_t> WaitSet::wait(std::chrono::nanoseconds timeout) const {
  std::vector<dds_attach_t> tokens(conditions_.size() + 8);
  const dds_return_t n =
      dds_waitset_wait(waitset_.handle(), tokens.data(), tokens.size(), timeout.count());
  if (n < 0) {
    STUDIO_LOG(warn, "dds") << dds_error("waitset wait", n);
    return {};
  }
  tokens.resize(std::min<std::size_t>(std::size_t(n), tokens.size()));
  return tokens;
}

}  // namespace studio::wire
