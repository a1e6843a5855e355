#!/usr/bin/env python3
"""Runs a build tree's ctest tests as ctest would and reports the CPU time (user + sys) of each.

ctest records wall time only, and wall time on a shared machine measures the load as much as the
test. This runs each selected test's command (from `ctest --show-only=json-v1`, with its working
directory, ENVIRONMENT and TIMEOUT) in its own process, N at a time, and takes the CPU time of the
test and every process it waited for from wait4(2). Totals per gtest binary (or script) go to
stdout as a table, sorted by CPU; --json writes every test's figures. Used for BENCHMARKS.md,
"CI's cost" (the ASan unit run), e.g.

  tests/ctest_cpu_time.py --build-dir build/asan -j 2 -L unit --json /tmp/asan-unit.json

exit 0 when every test passed, 1 when any failed or timed out (each named), 2 on bad usage.
"""
import argparse
import collections
import concurrent.futures
import json
import os
import signal
import subprocess
import sys
import threading
import time

ASAN_DEFAULTS = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=1",
                 "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1"}  # as ./studio test sets


def selected_tests(build_dir, ctest_args):
    out = subprocess.run(["ctest", "--test-dir", build_dir, "--show-only=json-v1", *ctest_args],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out)["tests"]


def binary_of(cmd):
    exe = os.path.basename(cmd[0])
    if exe.startswith("python") and len(cmd) > 1:
        return os.path.basename(cmd[1])
    return exe


def run_one(test, env_base):
    props = {p["name"]: p["value"] for p in test.get("properties", [])}
    env = dict(env_base)
    for kv in props.get("ENVIRONMENT", []):
        k, _, v = kv.partition("=")
        env[k] = v
    timeout = float(props.get("TIMEOUT", 1500))
    t0 = time.monotonic()
    proc = subprocess.Popen(test["command"], cwd=props.get("WORKING_DIRECTORY"), env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True)
    timed_out = threading.Event()

    def kill():
        timed_out.set()
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    timer = threading.Timer(timeout, kill)
    timer.start()
    output = proc.stdout.read()
    _, status, ru = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    timer.cancel()
    text = output.decode(errors="replace")
    skipped = "[  SKIPPED ]" in text
    return {"name": test["name"], "binary": binary_of(test["command"]),
            "cpu_s": ru.ru_utime + ru.ru_stime, "wall_s": time.monotonic() - t0,
            "max_rss_mb": ru.ru_maxrss / 1024.0, "rc": proc.returncode,
            "timed_out": timed_out.is_set(), "skipped": skipped,
            "output_tail": "" if proc.returncode == 0 else text[-6000:]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build-dir", required=True)
    ap.add_argument("-j", type=int, default=2, help="tests run at once (default 2)")
    ap.add_argument("--json", help="write every test's figures here")
    ap.add_argument("--skip-passed", action="append", default=[], metavar="JSON",
                    help="skip the tests that passed in this earlier --json result (repeatable)")
    # Everything else is ctest's selection (-L unit, -R regex, -E regex).
    a, a.ctest_args = ap.parse_known_args()
    env = dict(os.environ)
    for k, v in ASAN_DEFAULTS.items():
        env.setdefault(k, v)
    every = selected_tests(a.build_dir, a.ctest_args)
    # <binary>_NOT_BUILT: a gtest binary this tree has not built (named, not run).
    not_built = [t["name"] for t in every if t["name"].endswith("_NOT_BUILT")]
    tests = [t for t in every if t.get("command") and not t["name"].endswith("_NOT_BUILT")]
    passed = set()
    for path in a.skip_passed:
        with open(path) as f:
            passed |= {r["name"] for r in json.load(f)["tests"] if r["rc"] == 0 and not r["timed_out"]}
    tests = [t for t in tests if t["name"] not in passed]
    if not_built:
        print(f"ctest_cpu_time: not built, not run: {' '.join(not_built)}", flush=True)
    if not tests:
        print("ctest_cpu_time: no test selected", file=sys.stderr)
        return 2
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.j) as pool:
        for r in pool.map(lambda t: run_one(t, env), tests):
            results.append(r)
            print(f"{len(results)}/{len(tests)} {r['name']} ({r['binary']}): CPU {r['cpu_s']:.1f} s, "
                  f"wall {r['wall_s']:.1f} s, exit {r['rc']}", file=sys.stderr, flush=True)
            bad = r["rc"] != 0 or r["timed_out"]
            if bad:
                print(f"FAILED {r['name']} (exit {r['rc']}{', timed out' if r['timed_out'] else ''})"
                      f"\n{r['output_tail']}", flush=True)
    per = collections.defaultdict(lambda: {"tests": 0, "cpu_s": 0.0, "wall_s": 0.0, "failed": 0})
    for r in results:
        b = per[r["binary"]]
        b["tests"] += 1
        b["cpu_s"] += r["cpu_s"]
        b["wall_s"] += r["wall_s"]
        b["failed"] += r["rc"] != 0 or r["timed_out"]
    print(f"{'binary':40s} {'tests':>5s} {'CPU s':>8s} {'wall s':>8s} failed")
    for name, b in sorted(per.items(), key=lambda kv: -kv[1]["cpu_s"]):
        print(f"{name:40s} {b['tests']:5d} {b['cpu_s']:8.1f} {b['wall_s']:8.1f} {b['failed']}")
    failed = [r["name"] for r in results if r["rc"] != 0 or r["timed_out"]]
    print(f"total: {len(results)} tests, CPU {sum(r['cpu_s'] for r in results):.0f} s, "
          f"{len(failed)} failed, {sum(r['skipped'] for r in results)} skipped; load {os.getloadavg()}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"tests": results, "binaries": per}, f, indent=1)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
