#pragma once
// Tests: runs the built studioctl as a process (in the calling test's DDS domain: the fixture
// exported it into this process's environment) and collects its exit code, stdout and stderr.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "harness/process.h"
#include "studioctl/testing/json.h"

namespace studio::ctl::testing {

struct Run {
  int code = -1;
  std::string out, err;
};

inline std::string slurp_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// prefix: prepended to the command line (environment overrides, a wrapper such as unshare).
// stderr goes to `err_file` (then read back).
inline Run run_studioctl(const std::vector<std::string>& args,
                         const std::filesystem::path& err_file, const std::string& prefix = "") {
  std::string cmd =
      prefix + " " + studio::testing::built_binary("deploy/studioctl/studioctl").string();
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " 2>'" + err_file.string() + "'";
  Run r;
  FILE* f = ::popen(cmd.c_str(), "r");
  if (!f) return r;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(f);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = slurp_file(err_file);
  return r;
}

// Every non-empty line of `text` parsed as JSON (lines that are not JSON are skipped).
inline std::vector<Json> json_lines_of(const std::string& text) {
  std::vector<Json> out;
  std::stringstream s(text);
  for (std::string l; std::getline(s, l);)
    if (auto j = JsonReader::parse(l); !l.empty() && j) out.push_back(std::move(*j));
  return out;
}

}  // namespace studio::ctl::testing
