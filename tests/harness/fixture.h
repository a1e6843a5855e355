#pragma once
// gtest fixture for process-level tests: a scratch directory, a DDS domain of its own (applied to
// this process too, so in-test participants join it), a watchdog, spawned processes stopped at
// the end, and their logs printed when the test failed.

#include <gtest/gtest.h>

#include <deque>

#include "harness/process.h"

namespace studio::testing {

class ProcessTest : public ::testing::Test {
 protected:
  static constexpr std::chrono::seconds kWatchdog{50};  // below the ctest timeout of 60 s

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = make_test_dir(std::string(info->test_suite_name()) + "." + info->name());
    dds_ = DdsDomain::unique();
    dds_.apply_to_this_process();
  }

  void TearDown() override {
    for (auto& p : processes_) p.stop();
    if (HasFailure()) {
      std::fprintf(stderr, "test dir: %s (DDS domain %d, tag %s)\n", dir_.c_str(), dds_.domain_id,
                   dds_.tag.c_str());
      for (auto& p : processes_)
        std::fprintf(stderr, "---- %s log (%s) ----\n%s\n", p.name().c_str(), p.log_path().c_str(),
                     p.log().c_str());
    } else {
      std::error_code ec;
      std::filesystem::remove_all(dir_, ec);
    }
  }

  // Starts a binary of this build tree (path relative to the build dir) in the test's domain.
  Process& spawn(const std::string& name, const std::string& binary,
                 std::vector<std::string> args) {
    auto p = Process::start({.name = name,
                             .binary = built_binary(binary),
                             .args = std::move(args),
                             .env = dds_.env(),
                             .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  }

  Watchdog watchdog_{kWatchdog};
  std::filesystem::path dir_;
  DdsDomain dds_;
  std::deque<Process> processes_;
};

}  // namespace studio::testing
