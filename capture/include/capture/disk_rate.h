#pragma once
// What the takes disk sustains versus what the cameras need (issue 17 item 5): the capture
// service compares the two at start and warns when recording every camera at full rate would
// overrun the disk (the recorder would then drop frames at its queue, counted, never block).

#include <cstddef>
#include <string>

#include "core/error.h"

namespace studio::capture {

// Sustained sequential write rate of the file system holding `dir`, in MB/s (1e6 bytes): writes
// `bytes` in 4 MiB chunks to a temporary file, fdatasync()s it (so the figure is the disk's,
// not the page cache's), removes it. Error with one line when `dir` is not writable.
Expected<double> measure_write_rate(const std::string& dir, std::size_t bytes = 32u << 20);

// Bytes per second one camera's take writes: (48-byte header + width*height*3) per frame.
double take_bytes_per_second(int width, int height, double fps);

}  // namespace studio::capture
