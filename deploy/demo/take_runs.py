#!/usr/bin/env python3
"""Frames of a recorded take that every camera holds, as contiguous runs (for
`studio-hull offline --take DIR --frames A:B`, which needs every camera's frame).

usage: take_runs.py TAKE_DIR   → JSON on stdout:
  {"cameras": {id: frames recorded}, "common": N, "runs": [[A, B], ...]}   (A..B inclusive)
Reads each camera's index (capture/take.h: "STIX", u32 version, then u64 frame, u64 offset per
frame). A camera without an index holds nothing."""
import json
import os
import struct
import sys


def frames_of(cam_dir):
    try:
        data = open(os.path.join(cam_dir, "index"), "rb").read()
    except OSError:
        return set()
    if data[:4] != b"STIX":
        return set()
    body = data[8:]
    return {struct.unpack_from("<Q", body, i)[0] for i in range(0, len(body) - len(body) % 16, 16)}


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    take = sys.argv[1]
    cams = sorted(d for d in os.listdir(take) if os.path.isdir(os.path.join(take, d)))
    per = {c: frames_of(os.path.join(take, c)) for c in cams}
    common = sorted(set.intersection(*per.values())) if per else []
    runs = []
    for f in common:
        if runs and f == runs[-1][1] + 1:
            runs[-1][1] = f
        else:
            runs.append([f, f])
    print(json.dumps({"cameras": {c: len(v) for c, v in per.items()}, "common": len(common),
                      "runs": runs}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
