#pragma once
// Move-only RAII handles over Cyclone DDS entities: Entity (any handle), Participant, Qos,
// GuardCondition, WaitSet. Creation returns studio::Expected with a one-line error naming the
// DDS return code; destruction deletes the entity (and thereby its children).

#include <dds/dds.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "wire/types.h"

namespace studio::wire {

// "what: DDS_RETCODE_..." for a negative DDS return code.
std::string dds_error(std::string_view what, dds_return_t rc);

class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity() { reset(); }
  Entity(Entity&& other) noexcept : handle_(other.handle_) { other.handle_ = 0; }
  Entity& operator=(Entity&& other) noexcept;
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;

  dds_entity_t handle() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }
  void reset();

 private:
  dds_entity_t handle_ = 0;
};

// A dds_qos_t owned by value.
class Qos {
 public:
  Qos() : qos_(dds_create_qos()) {}
  ~Qos() { dds_delete_qos(qos_); }
  Qos(Qos&& other) noexcept : qos_(other.qos_) { other.qos_ = dds_create_qos(); }
  Qos& operator=(Qos&& other) noexcept;
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

// QoS of a topic (applied to its topic, writers and readers alike), built from its row of the
// DESIGN §3 table (kTopicTable in idl/src/types.cc).
Qos qos_for(TopicId id);

// The domain id services and tests use when none is given: $STUDIO_DDS_DOMAIN if set (the test
// harness sets it per test), else DDS_DOMAIN_DEFAULT (the Id of the CYCLONEDDS_URI config).
dds_domainid_t default_domain();

class Participant {
 public:
  // config: empty = use CYCLONEDDS_URI; otherwise Cyclone XML or a file:// URI, used to create
  // the domain explicitly (ignored if this process already created that domain).
  static Expected<Participant> create(dds_domainid_t domain = default_domain(),
                                      const std::string& config = {});
  dds_entity_t handle() const { return participant_.handle(); }

 private:
  Entity domain_;  // explicit domain (when config given); deleted after the participant
  Entity participant_;
};

// Wakes a WaitSet from another thread (shutdown, new work).
class GuardCondition {
 public:
  static Expected<GuardCondition> create(const Participant& participant);
  void trigger() const;
  // Resets the condition; returns whether it was triggered.
  bool take() const;
  dds_entity_t handle() const { return entity_.handle(); }

 private:
  Entity entity_;
};

class ReaderBase;

class WaitSet {
 public:
  static Expected<WaitSet> create(const Participant& participant);
  // Triggers while the reader holds samples not yet read or taken (incl. dispose notices).
  Expected<void> attach(const ReaderBase& reader, dds_attach_t token);
  Expected<void> attach(const GuardCondition& guard, dds_attach_t token);
  // Tokens of the triggered attachments; empty on timeout.
  std::vector<dds_attach_t> wait(std::chrono::nanoseconds timeout) const;

 private:
  std::vector<Entity> conditions_;  // read conditions made by attach(reader); deleted first
  Entity waitset_;
};

}  // namespace studio::wire
