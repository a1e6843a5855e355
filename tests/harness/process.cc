#include "harness/process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>

extern char** environ;

namespace studio::testing {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Live process groups, for the watchdog.
struct Live {
  pid_t pgid;
  std::string name;
  fs::path log;
};
std::mutex g_live_mutex;
std::vector<Live> g_live;

void register_live(pid_t pgid, const std::string& name, const fs::path& log) {
  std::lock_guard lock(g_live_mutex);
  g_live.push_back({pgid, name, log});
}
void unregister_live(pid_t pgid) {
  std::lock_guard lock(g_live_mutex);
  std::erase_if(g_live, [&](const Live& l) { return l.pgid == pgid; });
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

int decode_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return -WTERMSIG(status);
  return -1000;
}

std::atomic<unsigned> g_counter{0};

}  // namespace

fs::path make_test_dir(const std::string& name) {
  const char* tmp = std::getenv("TMPDIR");
  std::string clean;
  for (char c : name) clean += (std::isalnum(static_cast<unsigned char>(c)) ? c : '_');
  std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/studio-" + clean + "-XXXXXX";
  if (!mkdtemp(templ.data())) throw std::runtime_error("make_test_dir: mkdtemp failed: " + templ);
  return templ;
}

DdsDomain DdsDomain::unique() {
  std::random_device rd;
  const unsigned n = g_counter++;
  const unsigned salt = rd();
  DdsDomain d;
  // Valid DDSI domain ids with the default port mapping are 0..232; 0 is the default domain of
  // anything else on this machine, so tests use 1..230.
  d.domain_id = 1 + int((unsigned(getpid()) * 7919u + n * 104729u + salt) % 230u);
  char tag[64];
  std::snprintf(tag, sizeof tag, "studio-test-%d-%u-%08x", int(getpid()), n, salt);
  d.tag = tag;
  d.config_uri = "file://" STUDIO_SOURCE_DIR "/deploy/dds/loopback.xml";
  return d;
}

Env DdsDomain::env() const {
  return {{"CYCLONEDDS_URI", config_uri},
          {"STUDIO_DDS_DOMAIN", std::to_string(domain_id)},
          {"STUDIO_DDS_TAG", tag}};
}

void DdsDomain::apply_to_this_process() const {
  for (const auto& [k, v] : env()) setenv(k.c_str(), v.c_str(), 1);
}

fs::path built_binary(const std::string& relative) {
  return fs::path(STUDIO_BINARY_DIR) / relative;
}

std::vector<std::string> xvfb_exec(const std::string& screen, const fs::path& env_file) {
  return {(fs::path(STUDIO_SOURCE_DIR) / "tests/harness/xvfb-exec").string(), screen,
          env_file.string()};
}

Expected<Process> Process::start(Options o) {
  if (!fs::exists(o.binary)) return fail("harness: no such binary: " + o.binary.string());
  Process p;
  p.name_ = o.name;
  p.log_path_ = o.dir / (o.name + ".log");

  // The notify socket: abstract namespace (no path length limit, nothing to clean up).
  const std::string abstract_name = "studio-notify-" + std::to_string(getpid()) + "-" +
                                    std::to_string(g_counter++) + "-" + o.name;
  p.notify_fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (p.notify_fd_ < 0) return fail("harness: socket: " + std::string(std::strerror(errno)));
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (abstract_name.size() + 1 > sizeof addr.sun_path)
    return fail("harness: process name too long");
  std::memcpy(addr.sun_path + 1, abstract_name.data(), abstract_name.size());
  const socklen_t len = socklen_t(offsetof(sockaddr_un, sun_path) + 1 + abstract_name.size());
  if (bind(p.notify_fd_, reinterpret_cast<sockaddr*>(&addr), len) != 0)
    return fail("harness: bind notify socket: " + std::string(std::strerror(errno)));

  const int log_fd = open(p.log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) return fail("harness: cannot create " + p.log_path_.string());
  const int null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);

  // Everything the child needs is built before fork (no allocation after it).
  std::map<std::string, std::string> env;
  for (char** e = environ; *e; ++e) {
    const char* eq = std::strchr(*e, '=');
    if (eq) env[std::string(*e, size_t(eq - *e))] = eq + 1;
  }
  for (const auto& [k, v] : o.env) env[k] = v;
  env["NOTIFY_SOCKET"] = "@" + abstract_name;
  std::vector<std::string> env_strings;
  for (const auto& [k, v] : env) env_strings.push_back(k + "=" + v);
  std::vector<char*> envp;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> args{o.binary.string()};
  args.insert(args.end(), o.args.begin(), o.args.end());
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();

  const pid_t pid = fork();
  if (pid < 0) {
    close(log_fd);
    if (null_fd >= 0) close(null_fd);
    return fail("harness: fork: " + std::string(std::strerror(errno)));
  }
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the test
    if (getppid() != parent) _exit(126);
    if (null_fd >= 0) dup2(null_fd, 0);
    dup2(log_fd, 1);
    dup2(log_fd, 2);
    execve(argv[0], argv.data(), envp.data());
    const char msg[] = "harness: execve failed\n";
    (void)!write(2, msg, sizeof msg - 1);
    _exit(127);
  }
  setpgid(pid, pid);  // also here: no race with kill(-pid) below
  close(log_fd);
  if (null_fd >= 0) close(null_fd);
  p.pid_ = pid;
  register_live(pid, p.name_, p.log_path_);
  return p;
}

Process::Process(Process&& o) noexcept
    : pid_(std::exchange(o.pid_, -1)),
      notify_fd_(std::exchange(o.notify_fd_, -1)),
      exit_status_(o.exit_status_),
      name_(std::move(o.name_)),
      log_path_(std::move(o.log_path_)),
      socket_path_(std::move(o.socket_path_)) {}

Process& Process::operator=(Process&& o) noexcept {
  if (this != &o) {
    this->~Process();
    new (this) Process(std::move(o));
  }
  return *this;
}

Process::~Process() {
  if (pid_ > 0 && !exit_status_) stop(std::chrono::seconds(2));
  if (notify_fd_ >= 0) close(notify_fd_);
}

void Process::reap(int status) {
  exit_status_ = decode_status(status);
  kill(-pid_, SIGKILL);  // anything the service left behind in its group
  unregister_live(pid_);
}

bool Process::running() {
  if (pid_ <= 0 || exit_status_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    reap(status);
    return false;
  }
  return true;
}

std::optional<std::string> Process::next_notification(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    pollfd pfd{notify_fd_, POLLIN, 0};
    const int r = poll(&pfd, 1, int(std::clamp<int64_t>(left.count(), 0, 50)));
    if (r > 0) {
      char buf[4096];
      const ssize_t n = recv(notify_fd_, buf, sizeof buf, 0);
      if (n > 0) return std::string(buf, size_t(n));
    }
    if (!running()) {
      // Drain what the process sent before it ended.
      char buf[4096];
      const ssize_t n = recv(notify_fd_, buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) return std::string(buf, size_t(n));
      return std::nullopt;
    }
    if (Clock::now() >= deadline) return std::nullopt;
  }
}

bool Process::wait_ready(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    auto msg = next_notification(
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()));
    if (!msg) return false;
    std::istringstream lines(*msg);
    for (std::string line; std::getline(lines, line);)
      if (line == "READY=1") return true;
  }
  return false;
}

std::optional<int> Process::wait_exit(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (running()) {
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return exit_status_;
}

int Process::stop(std::chrono::milliseconds grace) {
  if (pid_ <= 0) return -1000;
  if (running()) {
    kill(-pid_, SIGTERM);
    if (!wait_exit(grace)) {
      std::fprintf(stderr, "harness: %s (pid %d) ignored SIGTERM for %lld ms; SIGKILL\n",
                   name_.c_str(), int(pid_), static_cast<long long>(grace.count()));
      kill(-pid_, SIGKILL);
      int status = 0;
      if (waitpid(pid_, &status, 0) == pid_) reap(status);
    }
  }
  return exit_status_.value_or(-1000);
}

std::string Process::log() const { return read_file(log_path_); }

struct Watchdog::State {
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  std::thread thread;
};

Watchdog::Watchdog(std::chrono::seconds limit) : state_(new State) {
  state_->thread = std::thread([s = state_, limit] {
    std::unique_lock lock(s->mutex);
    if (s->cv.wait_for(lock, limit, [s] { return s->done; })) return;
    std::fprintf(stderr, "watchdog: test exceeded %lld s; killing its processes\n",
                 static_cast<long long>(limit.count()));
    std::lock_guard live_lock(g_live_mutex);
    for (const Live& l : g_live) {
      kill(-l.pgid, SIGKILL);
      std::fprintf(stderr, "---- %s (pid %d) log %s ----\n%s\n", l.name.c_str(), int(l.pgid),
                   l.log.c_str(), read_file(l.log).c_str());
    }
    std::fflush(stderr);
    _exit(124);
  });
}

Watchdog::~Watchdog() {
  {
    std::lock_guard lock(state_->mutex);
    state_->done = true;
  }
  state_->cv.notify_all();
  state_->thread.join();
  delete state_;
}

}  // namespace studio::testing
