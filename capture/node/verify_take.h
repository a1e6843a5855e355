#pragma once
// `studio-capture verify-take DIR`: checks a recorded take after a crash or copy and rebuilds its
// index from frames.raw (DESIGN §4). DIR is one camera's take folder (holding frames.raw) or a
// take folder with one sub-folder per camera. Prints one JSON object on stdout:
//   {"cameras": [{"dir": ..., "frames": N, "corrupt": C, "first_frame": F, "last_frame": L,
//                 "bytes": B, "valid_bytes": V, "tail": "...", "index_rebuilt": true,
//                 "status": "complete|recording|error|missing"}]}
// ("tail" says why the scan stopped before the end: a torn last frame after kill -9 or power
// loss; it is expected, not an error). Exit 0 when every complete frame is intact, 1 when some
// frame fails its CRC or DIR holds no take, 2 for bad usage.

namespace studio::capture::node {

int verify_take_main(int argc, char** argv);

}  // namespace studio::capture::node
