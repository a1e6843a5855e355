#!/usr/bin/env python3
"""Run the project's Google Benchmark binaries and collect their results.

usage: bench/run.py --build build/release [FILTER] [--json]

Every executable named *_bench in the build tree whose name contains FILTER runs once with
JSON output. The merged results go to bench/results.json; a short table goes to stdout.
Benchmarks compare against a baseline in the same binary (DESIGN §7), so ratios are the figures
that survive this shared, noisy machine; counters carry them.
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time


def find_benches(build, name_filter):
    found = []
    for dirpath, _, files in os.walk(build):
        if "CMakeFiles" in dirpath:
            continue
        for f in files:
            p = os.path.join(dirpath, f)
            if f.endswith("_bench") and os.access(p, os.X_OK) and (not name_filter or name_filter in f):
                found.append(p)
    return sorted(found)


def machine():
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "kernel": platform.release(), "host": platform.node()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release", help="build directory (default build/release)")
    ap.add_argument("filter", nargs="?", default="", help="run only benchmark binaries whose name contains this")
    ap.add_argument("--json", action="store_true", help="print the merged JSON instead of a table")
    args = ap.parse_args()

    benches = find_benches(args.build, args.filter)
    if not benches:
        print(f"bench: no benchmark binary matches '{args.filter}' in {args.build}", file=sys.stderr)
        return 2
    results = {"machine": machine(), "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "runs": {}}
    status = 0
    for b in benches:
        name = os.path.basename(b)
        out = os.path.join(args.build, name + ".json")
        print(f"[bench] {name} ...", file=sys.stderr, flush=True)
        rc = subprocess.call([b, "--benchmark_format=console", f"--benchmark_out={out}",
                              "--benchmark_out_format=json"], stdout=sys.stderr)
        if rc != 0:
            print(f"bench: {name} exited with {rc}", file=sys.stderr)
            status = 1
            continue
        with open(out) as fh:
            results["runs"][name] = json.load(fh)

    os.makedirs("bench", exist_ok=True)
    with open("bench/results.json", "w") as fh:
        json.dump(results, fh, indent=1)
    if args.json:
        json.dump(results, sys.stdout, indent=1)
        print()
        return status
    print(f"machine: {results['machine']['cpu']}, {results['machine']['cores']} cores")
    print(f"{'benchmark':60s} {'time':>14s}  counters")
    skip = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations",
            "real_time", "cpu_time", "time_unit", "family_index", "per_family_instance_index",
            "aggregate_name", "aggregate_unit", "label", "error_occurred", "error_message"}
    for name, run in results["runs"].items():
        for bm in run.get("benchmarks", []):
            counters = ", ".join(f"{k}={v:.4g}" for k, v in bm.items()
                                 if k not in skip and isinstance(v, (int, float)))
            t = f"{bm.get('real_time', 0):.4g} {bm.get('time_unit', '')}"
            print(f"{bm['name']:60.60s} {t:>14s}  {counters}")
    print("results: bench/results.json")
    return status


if __name__ == "__main__":
    sys.exit(main())
