#include "verify_take.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "capture/take.h"

namespace studio::capture::node {
namespace {

namespace fs = std::filesystem;

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string take_status(const fs::path& dir) {
  std::ifstream in(dir / kTakeFile);
  if (!in) return "missing";
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("status: ", 0) == 0) return line.substr(8);
  return "unknown";
}

// takes/<take>/<camera> itself, or the camera folders of takes/<take>, in name order.
std::vector<fs::path> camera_dirs(const fs::path& root) {
  std::vector<fs::path> dirs;
  std::error_code ec;
  if (fs::exists(root / kFramesFile, ec)) {
    dirs.push_back(root);
  } else if (fs::is_directory(root, ec)) {
    for (const auto& e : fs::directory_iterator(root, ec))
      if (e.is_directory() && fs::exists(e.path() / kFramesFile)) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
  }
  return dirs;
}

}  // namespace

int verify_take_main(int argc, char** argv) {
  // argv[1] == "verify-take"
  if (argc == 3 && (std::strcmp(argv[2], "--help") == 0 || std::strcmp(argv[2], "-h") == 0)) {
    std::printf(
        "usage: studio-capture verify-take DIR\n"
        "Checks every frame of a recorded take (header + CRC-32), rebuilds its index from\n"
        "frames.raw and prints a JSON report. DIR: takes/<take>/<camera> or takes/<take>.\n"
        "Exit 0 when every complete frame is intact, 1 on corrupt frames or no take, 2 on "
        "usage.\n");
    return 0;
  }
  if (argc != 3) {
    std::fprintf(stderr, "studio-capture verify-take: expected one DIR (see verify-take --help)\n");
    return 2;
  }
  const fs::path root = argv[2];
  const std::vector<fs::path> dirs = camera_dirs(root);
  if (dirs.empty()) {
    std::fprintf(stderr, "studio-capture verify-take: %s holds no take (no %s)\n", root.c_str(),
                 kFramesFile);
    return 1;
  }
  bool all_intact = true;
  std::ostringstream json;
  json << "{\"cameras\": [";
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const std::string dir = dirs[i].string();
    auto scan = scan_frames(dir);
    if (!scan) {
      std::fprintf(stderr, "studio-capture verify-take: %s\n", scan.error().message.c_str());
      return 1;
    }
    auto written = write_index(dir, scan->intact);
    if (!written) {
      std::fprintf(stderr, "studio-capture verify-take: %s\n", written.error().message.c_str());
      return 1;
    }
    if (scan->corrupt) all_intact = false;
    json << (i ? ", " : "") << "{\"dir\": " << json_string(dir)
         << ", \"frames\": " << scan->intact.size() << ", \"corrupt\": " << scan->corrupt;
    if (scan->first_frame)
      json << ", \"first_frame\": " << *scan->first_frame
           << ", \"last_frame\": " << *scan->last_frame;
    json << ", \"width\": " << scan->width << ", \"height\": " << scan->height
         << ", \"bytes\": " << scan->file_bytes << ", \"valid_bytes\": " << scan->valid_bytes
         << ", \"tail\": " << json_string(scan->tail) << ", \"index_rebuilt\": true"
         << ", \"status\": " << json_string(take_status(dirs[i])) << "}";
    std::fprintf(stderr, "%s: %zu frames intact, %llu corrupt%s%s\n", dir.c_str(),
                 scan->intact.size(), static_cast<unsigned long long>(scan->corrupt),
                 scan->tail.empty() ? "" : "; ", scan->tail.c_str());
  }
  json << "]}\n";
  std::fputs(json.str().c_str(), stdout);
  return all_intact ? 0 : 1;
}

}  // namespace studio::capture::node
