#pragma once
// What a service node holds per topic: the topic together with its writer (Publication) or its
// reader (Subscription), created in one call with the table's QoS; and gather(), which builds a
// node's bundle of endpoints from several Expected results or returns the first error.
//
//   struct Io {
//     wire::Subscription<studio_AlphaMask> masks;
//     wire::Publication<studio_ActorMesh> meshes;
//     wire::WaitSet waitset;
//   };
//   auto io = wire::gather([](auto&&... e) { return Io{std::move(e)...}; },
//                          wire::Subscription<studio_AlphaMask>::create(participant),
//                          wire::Publication<studio_ActorMesh>::create(participant),
//                          wire::WaitSet::create(participant));
//   if (!io) return std::unexpected(io.error());
//   io->masks->visit(...);  io->meshes->write(mesh);

#include <string>
#include <utility>

#include "wire/endpoint.h"

namespace studio::wire {

// A topic and its writer. The topic is declared first, so it outlives the writer.
template <WireType T>
struct Publication {
  Topic<T> topic;
  Writer<T> writer;

  static Expected<Publication> create(const Participant& p, const std::string& name = {}) {
    auto t = Topic<T>::create(p, name);
    if (!t) return std::unexpected(t.error());
    auto w = Writer<T>::create(p, *t);
    if (!w) return std::unexpected(w.error());
    return Publication{std::move(*t), std::move(*w)};
  }
  const Writer<T>* operator->() const { return &writer; }
  const Writer<T>& operator*() const { return writer; }
};

// A topic and its reader. The topic is declared first, so it outlives the reader.
template <WireType T>
struct Subscription {
  Topic<T> topic;
  Reader<T> reader;

  // history_depth: see Reader::create (0: the topic's depth).
  static Expected<Subscription> create(const Participant& p, const std::string& name = {},
                                       int32_t history_depth = 0) {
    auto t = Topic<T>::create(p, name);
    if (!t) return std::unexpected(t.error());
    auto r = Reader<T>::create(p, *t, history_depth);
    if (!r) return std::unexpected(r.error());
    return Subscription{std::move(*t), std::move(*r)};
  }
  Reader<T>* operator->() { return &reader; }
  const Reader<T>* operator->() const { return &reader; }
  Reader<T>& operator*() { return reader; }
  const Reader<T>& operator*() const { return reader; }
};

// make(std::move(*parts)...) if every part holds a value, else the first part's error.
template <class Make, class... Parts>
auto gather(Make&& make, Expected<Parts>&&... parts)
    -> Expected<decltype(make(std::move(*parts)...))> {
  Error first;
  const bool ok = ((parts ? true : (first = parts.error(), false)) && ...);
  if (!ok) return std::unexpected(std::move(first));
  return make(std::move(*parts)...);
}

}  // namespace studio::wire
