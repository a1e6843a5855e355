#pragma once
// One command sample delivered: wait until a reader matches, write, wait for its acknowledgement
// (reliable topics: the command has reached every matched reader when this returns).

#include <algorithm>
#include <chrono>
#include <string>

#include "core/error.h"
#include "wire/endpoint.h"

namespace studio::ctl {

template <class T>
Expected<void> send_acked(const wire::Writer<T>& writer, const T& sample,
                          std::chrono::steady_clock::time_point deadline, const char* listeners) {
  using namespace std::chrono;
  if (!writer.wait_for_readers(1, duration_cast<milliseconds>(deadline - steady_clock::now())))
    return fail(std::string("no ") + listeners + " is listening on " +
                wire::TopicTraits<T>::name());
  if (auto w = writer.write(sample); !w) return w;
  const auto left =
      std::max<int64_t>(0, duration_cast<nanoseconds>(deadline - steady_clock::now()).count());
  if (auto rc = dds_wait_for_acks(writer.handle(), left); rc < 0)
    return fail(wire::dds_error("waiting for acknowledgements", rc));
  return {};
}

}  // namespace studio::ctl
