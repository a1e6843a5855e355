#include "core/clock.h"
#include "capture/freed_listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <ctime>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

namespace studio::capture {
namespace {


std::string errno_text() { return std::strerror(errno); }

// The SO_TIMESTAMPNS receive time of a datagram read with recvmsg, or now when the kernel gave
// none (it always does once the option is set; the fallback keeps a packet rather than drop it).
int64_t kernel_receive_ns(msghdr& msg) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts;
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
    }
  return realtime_ns();
}

}  // namespace

Expected<void> FreeDListenerOptions::validate() const {
  in_addr addr{};
  if (inet_pton(AF_INET, bind_address.c_str(), &addr) != 1) {
    return fail("free-d listener: bind_address '" + bind_address + "' is not an IPv4 address");
  }
  if (!group.empty()) {
    in_addr g{};
    if (inet_pton(AF_INET, group.c_str(), &g) != 1 || !IN_MULTICAST(ntohl(g.s_addr)))
      return fail("free-d listener: group '" + group + "' is not an IPv4 multicast address");
  }
  if (!clock.valid()) return fail("free-d listener: clock period must be > 0");
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
  struct Tracked {
    int delay_frames = 0;
    std::optional<uint64_t> delivered;  // newest frame delivered
  };
  std::map<uint8_t, Tracked> tracked;

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
  // SO_REUSEADDR only when sharing is asked for: on Linux it lets UDP sockets share a port, each
  // getting a copy of broadcast/multicast datagrams but unicast ones going to one socket only; a
  // second unshared listener on the same port must fail instead (UDP has no TIME_WAIT).
  if (options.shared || !options.group.empty()) {
    const int one = 1;
    if (setsockopt(state->socket_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0)
      return fail("free-d listener: SO_REUSEADDR: " + errno_text());
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(options.port);
  inet_pton(AF_INET, options.bind_address.c_str(), &addr.sin_addr);
  if (bind(state->socket_fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    return fail("free-d listener: bind " + options.bind_address + ":" +
                std::to_string(options.port) + ": " + errno_text());
  }
  if (!options.group.empty()) {
    ip_mreq mreq{};
    inet_pton(AF_INET, options.group.c_str(), &mreq.imr_multiaddr);
    mreq.imr_interface.s_addr = htonl(INADDR_ANY);
    if (setsockopt(state->socket_fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0)
      return fail("free-d listener: join " + options.group + ": " + errno_text());
  }
  // The kernel's receive time (CLOCK_REALTIME, as realtime_ns()) decides a packet's frame, not the
  // time this thread got round to reading it: a listener delayed by a loaded machine must not move
  // a pose into the next frame's window (handle_datagram maps arrival time to frame).
  {
    const int one = 1;
    if (setsockopt(state->socket_fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) != 0)
      return fail("free-d listener: SO_TIMESTAMPNS: " + errno_text());
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
      iovec iov{buffer, sizeof buffer};
      alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
      msghdr msg{};
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control;
      msg.msg_controllen = sizeof control;
      const ssize_t n = recvmsg(s.socket_fd, &msg, MSG_TRUNC | MSG_DONTWAIT);
      if (n < 0) continue;
      // MSG_TRUNC makes recvmsg report a longer datagram's true size; the decoder then sees the
      // 2 KiB that fit, which it rejects as wrong_length like any other size but 29.
      const std::size_t size = std::min(std::size_t(n), sizeof buffer);
      self->handle_datagram(std::span<const uint8_t>(buffer, size), kernel_receive_ns(msg));
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
const FreeDListenerOptions& FreeDListener::options() const { return state_->options; }

void FreeDListener::track(uint8_t freed_id, int delay_frames) {
  std::lock_guard lock(state_->mutex);
  state_->tracked[freed_id].delay_frames = std::max(delay_frames, 0);
}

void FreeDListener::handle_datagram(std::span<const uint8_t> bytes, int64_t arrival_ns) {
  FreeDReject reason{};
  auto packet = decode_freed(bytes, &reason);
  {
    std::lock_guard lock(state_->mutex);
    State& s = *state_;
    ++s.stats.datagrams;
    std::optional<FreeDReject> rejected;
    uint64_t frame = 0;
    if (!packet) {
      rejected = reason;
    } else {
      const auto t = s.tracked.find(packet->camera_id);
      const int delay = t == s.tracked.end() ? 0 : t->second.delay_frames;
      const uint64_t arrival_frame = s.options.clock.frame_at(arrival_ns);
      auto& history = s.kept[packet->camera_id];
      if (!s.tracked.empty() && t == s.tracked.end()) {
        rejected = FreeDReject::unknown_id;
      } else if (arrival_frame < uint64_t(delay) ||
                 (t != s.tracked.end() && t->second.delivered &&
                  arrival_frame - uint64_t(delay) <= *t->second.delivered)) {
        rejected = FreeDReject::too_late;
      } else if (frame = arrival_frame - uint64_t(delay);
                 !s.tracked.empty() &&
                 std::any_of(history.begin(), history.end(),
                             [&](const FreeDSample& k) { return k.frame == frame; })) {
        rejected = FreeDReject::duplicate;  // the first packet of a frame counts
      } else {
        history.push_back(FreeDSample{*packet, arrival_ns, frame});
        while (history.size() > s.options.history) history.pop_front();
      }
      if (history.empty()) s.kept.erase(packet->camera_id);
    }
    if (rejected)
      ++s.stats.rejected[std::size_t(*rejected)];
    else
      ++s.stats.accepted;
  }
  state_->changed.notify_all();
}

bool FreeDListener::tracks(uint8_t freed_id) const {
  std::lock_guard lock(state_->mutex);
  return state_->tracked.count(freed_id) > 0;
}

std::optional<FreeDSample> FreeDListener::latest(uint8_t freed_id) const {
  std::lock_guard lock(state_->mutex);
  auto it = state_->kept.find(freed_id);
  if (it == state_->kept.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::optional<FreeDSample> FreeDListener::wait_frame(uint8_t freed_id, uint64_t frame,
                                                     int64_t until_ns) const {
  std::unique_lock lock(state_->mutex);
  for (;;) {
    if (auto it = state_->kept.find(freed_id); it != state_->kept.end()) {
      for (const FreeDSample& s : it->second)
        if (s.frame == frame) return s;
    }
    const int64_t now = realtime_ns();
    if (now >= until_ns) return std::nullopt;
    state_->changed.wait_for(lock, std::chrono::nanoseconds(until_ns - now));
  }
}

void FreeDListener::delivered(uint8_t freed_id, uint64_t frame) {
  std::lock_guard lock(state_->mutex);
  auto& t = state_->tracked[freed_id];
  if (!t.delivered || frame > *t.delivered) t.delivered = frame;
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
  if (!clock.valid()) return fail("tracked source: clock period must be > 0");
  if (delay_frames < 0 || delay_frames > 50)
    return fail("tracked source: delay_frames must be in 0..50");
  if (silent_ns <= 0) return fail("tracked source: silent_ns must be > 0");
  return {};
}

TrackedSource::TrackedSource(std::unique_ptr<FrameSource> inner,
                             std::shared_ptr<FreeDListener> listener, TrackedSourceOptions options)
    : inner_(std::move(inner)), listener_(std::move(listener)), options_(std::move(options)) {
  if (options_.grace_ns < 0) options_.grace_ns = options_.clock.period_ns / 4;
  listener_->track(options_.camera.freed_id, options_.delay_frames);
  following_ = inner_->follow_pose([this](uint64_t frame) { return resolve(frame); });
}

std::optional<Camera> TrackedSource::resolve(uint64_t frame) {
  if (resolved_ && resolved_->first == frame) return resolved_->second;
  const int64_t until = options_.clock.time_of(frame + uint64_t(options_.delay_frames) + 1) +
                        options_.grace_ns;
  std::optional<Camera> camera;
  if (auto sample = listener_->wait_frame(options_.camera.freed_id, frame, until))
    camera = freed_to_camera(sample->packet, options_.camera);
  listener_->delivered(options_.camera.freed_id, frame);
  resolved_.emplace(frame, camera);
  return camera;
}

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
  f.calibration = resolve(f.frame);
  if (!f.calibration) ++untracked_;
  return frame;
}

TrackingStatus TrackedSource::status(int64_t now_ns) const {
  TrackingStatus s;
  s.untracked = untracked_.load();
  if (auto last = listener_->latest(options_.camera.freed_id)) {
    s.since_s = double(now_ns - last->arrival_ns) * 1e-9;
    s.silent = now_ns - last->arrival_ns > options_.silent_ns;
  }
  return s;
}

}  // namespace studio::capture
