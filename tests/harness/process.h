#pragma once
// The integration-test harness: real service processes on loopback, one DDS domain per test.
//
//   auto dds = DdsDomain::unique();          // domain id + discovery tag nobody else uses
//   dds.apply_to_this_process();            // so the test's own participants join it
//   Process peer = Process::start({.name = "peer", .binary = ..., .args = {...},
//                                  .env = dds.env(), .dir = test_dir}).value();
//   ASSERT_TRUE(peer.wait_ready(10s)) << peer.log();
//
// A Process runs in its own process group with stdout+stderr captured to <dir>/<name>.log and
// NOTIFY_SOCKET pointing at an AF_UNIX datagram socket this Process owns (the systemd protocol;
// READY=1 marks the service ready). stop() sends SIGTERM to the group, waits, then SIGKILLs.
// A Watchdog kills every live Process group and ends the test process when a test overruns.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace studio::testing {

using Env = std::vector<std::pair<std::string, std::string>>;

// A fresh directory under $TMPDIR (or /tmp) for one test: logs, sockets, outputs.
std::filesystem::path make_test_dir(const std::string& name);

// The loopback DDS profile (deploy/dds/loopback.xml) with a domain id and discovery tag unique to
// this test, so parallel ctest runs never see each other.
struct DdsDomain {
  int domain_id = 0;
  std::string tag;
  std::string config_uri;  // file://.../deploy/dds/loopback.xml

  static DdsDomain unique();
  // CYCLONEDDS_URI, STUDIO_DDS_DOMAIN, STUDIO_DDS_TAG for child processes.
  Env env() const;
  void apply_to_this_process() const;
};

class Process {
 public:
  struct Options {
    std::string name;  // for logs ("peer", "hull", ...)
    std::filesystem::path binary;
    std::vector<std::string> args;
    Env env;                    // added to (and overriding) this process's environment
    std::filesystem::path dir;  // where <name>.log and the notify socket live
  };

  static Expected<Process> start(Options options);
  Process(Process&& other) noexcept;
  Process& operator=(Process&& other) noexcept;
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process();

  // True once the process sent READY=1 on its NOTIFY_SOCKET; false on timeout or exit.
  bool wait_ready(std::chrono::milliseconds timeout);
  // Next notification datagram (e.g. "STATUS=..."), or nullopt on timeout.
  std::optional<std::string> next_notification(std::chrono::milliseconds timeout);
  // Exit status if the process has ended within timeout (>= 0 exit code, < 0 -signal).
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);
  // SIGTERM to the whole group, then SIGKILL after `grace`. Returns the exit status as above.
  int stop(std::chrono::milliseconds grace = std::chrono::seconds(3));
  bool running();

  pid_t pid() const { return pid_; }
  const std::string& name() const { return name_; }
  const std::filesystem::path& log_path() const { return log_path_; }
  std::string log() const;  // the captured stdout+stderr so far

 private:
  Process() = default;
  void reap(int status);
  pid_t pid_ = -1;
  int notify_fd_ = -1;
  std::optional<int> exit_status_;
  std::string name_;
  std::filesystem::path log_path_;
  std::filesystem::path socket_path_;
};

// Kills every live Process group and exits the test process (status 124, logs to stderr) when
// `limit` passes before destruction. One per test.
class Watchdog {
 public:
  explicit Watchdog(std::chrono::seconds limit);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

 private:
  struct State;
  State* state_;
};

// Path of a binary built in this tree (STUDIO_BINARY_DIR/<relative>).
std::filesystem::path built_binary(const std::string& relative);

// The arguments that run `command` on a private Xvfb display of `screen` (e.g. "960x540x24"):
// tests/harness/xvfb-exec, which lets Xvfb choose a free display itself (`xvfb-run -a` races
// when tests start at once) and writes "DISPLAY=:N" to `env_file`. Spawn its first element
// with the rest as arguments, followed by the command and its arguments.
std::vector<std::string> xvfb_exec(const std::string& screen, const std::filesystem::path& env_file);

}  // namespace studio::testing
