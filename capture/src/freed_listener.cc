#include "core/clock.h"
#include "capture/freed_listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

namespace studio::capture {
namespace {


std::string errno_text() { return std::strerror(errno); }

}  // namespace

Expected<void> FreeDListenerOptions::validate() const {
  in_addr addr{};
  if (inet_pton(AF_INET, bind_address.c_str(), &addr) != 1) {
    return fail("free-d listener: bind_address '" + bind_address + "' is not an IPv4 address");
  }
  if (history == 0 || history > 100000) {
    return fail("free-d listener: history must be in 1..100000, got " + std::to_string(history));
  }
  return {};
}

struct FreeDListener::State {
  FreeDListenerOptions options;
  int socket_fd = -1;
  int wake_pipe[2] = {-1, -1};
  uint16_t port = 0;
  std::thread thread;

  mutable std::mutex mutex;
  mutable std::condition_variable changed;
  FreeDListenerStats stats;
  std::map<uint8_t, std::deque<FreeDSample>> kept;  // per camera id, oldest first

  ~State() {
    if (socket_fd >= 0) close(socket_fd);
    for (int fd : wake_pipe) {
      if (fd >= 0) close(fd);
    }
  }
};

FreeDListener::FreeDListener(std::unique_ptr<State> state) : state_(std::move(state)) {}

Expected<std::unique_ptr<FreeDListener>> FreeDListener::create(
    const FreeDListenerOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  auto state = std::make_unique<State>();
  state->options = options;
  state->socket_fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (state->socket_fd < 0) return fail("free-d listener: socket: " + errno_text());
  // No SO_REUSEADDR: on Linux it lets two UDP sockets share a port and split the datagrams
  // silently; a second listener on the same port must fail instead (UDP has no TIME_WAIT).
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(options.port);
  inet_pton(AF_INET, options.bind_address.c_str(), &addr.sin_addr);
  if (bind(state->socket_fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    return fail("free-d listener: bind " + options.bind_address + ":" +
                std::to_string(options.port) + ": " + errno_text());
  }
  socklen_t len = sizeof addr;
  getsockname(state->socket_fd, reinterpret_cast<sockaddr*>(&addr), &len);
  state->port = ntohs(addr.sin_port);
  if (pipe2(state->wake_pipe, O_CLOEXEC | O_NONBLOCK) != 0) {
    return fail("free-d listener: pipe: " + errno_text());
  }

  std::unique_ptr<FreeDListener> listener(new FreeDListener(std::move(state)));
  FreeDListener* self = listener.get();
  self->state_->thread = std::thread([self] {
    State& s = *self->state_;
    // 2 KiB is plenty: a D1 message is 29 bytes; longer datagrams are still counted with their
    // true length thanks to MSG_TRUNC.
    uint8_t buffer[2048];
    pollfd fds[2] = {{s.socket_fd, POLLIN, 0}, {s.wake_pipe[0], POLLIN, 0}};
    for (;;) {
      if (poll(fds, 2, -1) < 0) {
        if (errno == EINTR) continue;
        return;
      }
      if (fds[1].revents) return;  // stop requested
      if (!(fds[0].revents & POLLIN)) continue;
      const ssize_t n = recv(s.socket_fd, buffer, sizeof buffer, MSG_TRUNC | MSG_DONTWAIT);
      if (n < 0) continue;
      // MSG_TRUNC makes recv report a longer datagram's true size; the decoder then sees the
      // 2 KiB that fit, which it rejects as wrong_length like any other size but 29.
      const std::size_t size = std::min(std::size_t(n), sizeof buffer);
      self->handle_datagram(std::span<const uint8_t>(buffer, size), realtime_ns());
    }
  });
  return listener;
}

FreeDListener::~FreeDListener() {
  if (state_->thread.joinable()) {
    const char byte = 1;
    [[maybe_unused]] ssize_t w = write(state_->wake_pipe[1], &byte, 1);
    state_->thread.join();
  }
}

uint16_t FreeDListener::port() const { return state_->port; }

void FreeDListener::handle_datagram(std::span<const uint8_t> bytes, int64_t arrival_ns) {
  FreeDReject reason{};
  auto packet = decode_freed(bytes, &reason);
  {
    std::lock_guard lock(state_->mutex);
    ++state_->stats.datagrams;
    if (!packet) {
      ++state_->stats.rejected[std::size_t(reason)];
    } else {
      ++state_->stats.accepted;
      auto& history = state_->kept[packet->camera_id];
      history.push_back(FreeDSample{*packet, arrival_ns});
      while (history.size() > state_->options.history) history.pop_front();
    }
  }
  state_->changed.notify_all();
}

std::optional<FreeDSample> FreeDListener::latest(uint8_t freed_id) const {
  std::lock_guard lock(state_->mutex);
  auto it = state_->kept.find(freed_id);
  if (it == state_->kept.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::optional<FreeDSample> FreeDListener::nearest(uint8_t freed_id, int64_t time_ns,
                                                  int64_t max_skew_ns) const {
  std::lock_guard lock(state_->mutex);
  auto it = state_->kept.find(freed_id);
  if (it == state_->kept.end()) return std::nullopt;
  const FreeDSample* best = nullptr;
  int64_t best_skew = 0;
  for (const FreeDSample& s : it->second) {
    const int64_t skew = s.arrival_ns > time_ns ? s.arrival_ns - time_ns : time_ns - s.arrival_ns;
    if (!best || skew < best_skew) {
      best = &s;
      best_skew = skew;
    }
  }
  if (!best || best_skew > max_skew_ns) return std::nullopt;
  return *best;
}

FreeDListenerStats FreeDListener::stats() const {
  std::lock_guard lock(state_->mutex);
  return state_->stats;
}

bool FreeDListener::wait_for_datagrams(uint64_t count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(state_->mutex);
  return state_->changed.wait_for(lock, timeout, [&] {
    return state_->stats.accepted + state_->stats.rejected_total() >= count;
  });
}

Expected<void> TrackedSourceOptions::validate() const {
  if (auto ok = camera.validate(); !ok) return ok;
  if (max_skew_ns < 0) return fail("tracked source: max_skew_ns must not be negative");
  return {};
}

TrackedSource::TrackedSource(std::unique_ptr<FrameSource> inner,
                             std::shared_ptr<const FreeDListener> listener,
                             TrackedSourceOptions options)
    : inner_(std::move(inner)), listener_(std::move(listener)), options_(std::move(options)) {}

Expected<std::optional<Frame>> TrackedSource::next(std::chrono::milliseconds timeout) {
  auto frame = inner_->next(timeout);
  if (!frame || !*frame) return frame;
  Frame& f = **frame;
  if (f.image.width() != options_.camera.width || f.image.height() != options_.camera.height) {
    return fail("tracked camera " + inner_->id() + ": frame is " + std::to_string(f.image.width()) +
                "x" + std::to_string(f.image.height()) + " but its lens table describes " +
                std::to_string(options_.camera.width) + "x" +
                std::to_string(options_.camera.height));
  }
  auto sample = listener_->nearest(options_.camera.freed_id, f.capture_ns + options_.latency_ns,
                                   options_.max_skew_ns);
  if (sample) {
    f.calibration = freed_to_camera(sample->packet, options_.camera);
  } else {
    f.calibration.reset();
    ++untracked_;
  }
  return frame;
}

}  // namespace studio::capture
