#!/usr/bin/env python3
"""deploy.demo_cli: the demo's command lines refuse bad input with one clear line and a non-zero
status (never a hang or crash), beside positive controls (--help, a rig subset and a score that
work).

usage: cli_test.py --source DIR --build DIR"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def run(cmd, timeout=60):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--build", required=True)
    a = ap.parse_args()
    probe = os.path.join(a.build, "deploy/demo/studio-demo-probe")
    demo = os.path.join(a.source, "deploy/demo.sh")
    ex = os.path.join(a.source, "deploy/examples/studio")
    tmp = tempfile.mkdtemp(prefix="studio-demo-cli-")
    failures = []

    def expect(cmd, rc_ok, needle=None, one_line=False):
        rc, out, err = run(cmd)
        ok = rc_ok(rc) and (needle is None or needle in (out + err))
        if one_line:
            ok = ok and len(err.strip().splitlines()) == 1
        if not ok:
            failures.append(f"{' '.join(cmd)}: exit {rc}\nstdout: {out[-500:]}\nstderr: {err[-500:]}")
        return rc, out, err

    zero = lambda rc: rc == 0
    two = lambda rc: rc == 2
    # Positive controls.
    expect([probe, "--help"], zero, "studio-demo-probe watch")
    expect([demo, "--help"], zero, "--seconds S")
    expect([os.path.join(a.source, "studio"), "demo", "--help"], zero, "--cameras N")
    subset = os.path.join(tmp, "rig3.yaml")
    expect([probe, "rig", "--from", os.path.join(ex, "rig.yaml"), "--cameras", "cam0,cam2,cam5",
            "--out", subset], zero)
    text = open(subset).read() if os.path.exists(subset) else ""
    if not (text.count("- id:") == 3 and "cam2" in text and "cam1" not in text):
        failures.append(f"rig subset wrong:\n{text}")
    # Refusals: one line, exit 2.
    expect([probe, "frobnicate"], two, "unknown command", one_line=True)
    expect([probe, "watch"], two, "no capture config", one_line=True)
    expect([probe, "watch", "--capture", os.path.join(tmp, "missing.yaml")], two, "missing.yaml",
           one_line=True)
    expect([probe, "watch", "--capture", os.path.join(ex, "capture-cam0.yaml"), "--seconds", "x"],
           two, "not a number", one_line=True)
    expect([probe, "watch", "--capture", os.path.join(ex, "capture-cam0.yaml"), "--seconds", "0"],
           two, "--seconds", one_line=True)
    expect([probe, "rig", "--from", os.path.join(ex, "rig.yaml"), "--cameras", "cam9",
            "--out", os.path.join(tmp, "x.yaml")], two, "cam9", one_line=True)
    expect([probe, "score", "--rig", os.path.join(ex, "rig.yaml"), "--meshes", tmp], two,
           "no <frame>.ply", one_line=True)
    bad_clock = os.path.join(tmp, "capture-bad.yaml")
    with open(bad_clock, "w") as f:
        f.write(open(os.path.join(ex, "capture-cam1.yaml")).read().replace("fps: 25", "fps: 30"))
    expect([probe, "watch", "--capture", os.path.join(ex, "capture-cam0.yaml"), bad_clock], two,
           "clock differs", one_line=True)
    for args, needle in ((["--cameras", "9"], "--cameras"), (["--seconds", "abc"], "--seconds"),
                         (["--keyer", "gpu"], "--keyer"), (["--bogus"], "unknown option"),
                         (["--projector-priority", "60"], "--projector-priority"),
                         (["--projector-priority", "nice:x"], "--projector-priority"),
                         (["--projector-priority", "30,nice:x"], "--projector-priority"),
                         (["--projector-priority", "60,nice:5"], "--projector-priority"),
                         (["--scheduling", "normal", "--projector-priority", "30"],
                          "needs --scheduling realtime"),
                         (["--scheduling", "normal", "--projector-priority", "30,nice:5"],
                          "needs --scheduling realtime")):
        expect([demo, "--build", a.build, "--out", os.path.join(tmp, "o")] + args, two, needle,
               one_line=True)
    expect([demo, "--build", os.path.join(tmp, "nobuild"), "--out", os.path.join(tmp, "o")], two,
           "is not built", one_line=True)

    subprocess.run(["rm", "-rf", tmp])
    for f in failures:
        print("FAIL:", f)
    print("PASS" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
