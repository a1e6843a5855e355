#!/usr/bin/env python3
"""deploy.demo_end_to_end: runs `deploy/demo.sh` for a short window (the services as separate
processes from deploy/examples/studio/, a private DDS domain on loopback) and asserts on its
report.json.

Configuration (honest, as the demo runs by default): 6 simulated cameras at 704x576, 25 fps, keyed
in the capture servers; hull 160x160 columns; tracker; the services SCHED_FIFO at their systemd units' priorities (as
installed; demo.sh's default where permitted); 15 s measured after a 3 s warm-up (375 frames, so
that p99 is not decided by the two or three worst frames of a short run); a take of 25 frames
(1 s, to bound the test's time; the demo's default is 50) reconstructed offline at 256x256.
The machine is shared: the test runs alone (RUN_SERIAL), the other engineers' builds do not.

Bounds (issue 20's test, looser than its targets only in rate and latency, for a loaded CI
machine): fps >= 20, latency p99 <= 60 ms on the last stage that exists (capture -> mesh and head
delivered, or capture -> projector frame rendered once the projector runs), hull_iou >= 0.95,
head_error_m <= 0.03, masks_lost == 0, and, when the projector ran (built, with the example
studio's projector-proj1.yaml), lit_actor_px == 0: no projector pixel of any frame rendered in the
window lands on the simulator's true actor at display time outside the blackout mask (the probe
scores every frame; unscored frames are reported). lit_actor_px must be null with a reason while
the projector is not built. On failure the report's held_back_by names the stage that holds the
figure back.
"""
import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time



# The projector runs in this test (since session 18): with the scene on a thread and an llvmpipe
# screen of its own, and the projector real-time at its unit's FIFO 55 (the scene thread
# time-sharing), the studio keeps the rate and the latency bound with it. 60 s runs of session 19
# (BENCHMARKS.md, demo, 2026-11-29): 25.0 meshes/s reach the projector, motion to photon
# p50 / p99 22-25 / 29-36 ms, lit_actor_px 0; this test's 15 s run: 25.0, p50 / p99 24.1 / 33.3 ms.
# STUDIO_DEMO_TEST_PROJECTORS=0 (or --projectors 0) runs it without, the headline latency then
# capture -> mesh and head delivered.
PROJECTORS = 1

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--build", required=True)
    ap.add_argument("--seconds", default="15")
    ap.add_argument("--projectors", type=int,
                    default=int(os.environ.get("STUDIO_DEMO_TEST_PROJECTORS", PROJECTORS)),
                    help=f"projectors to run (default {PROJECTORS}, or $STUDIO_DEMO_TEST_PROJECTORS)")
    a = ap.parse_args()
    projectors = a.projectors

    out = tempfile.mkdtemp(prefix="studio-demo-test-")
    env = dict(os.environ)
    env["STUDIO_DDS_DOMAIN"] = str(random.randint(1, 230))
    env["STUDIO_DDS_TAG"] = f"studio-demo-test-{os.getpid()}-{random.getrandbits(32):08x}"
    cmd = [os.path.join(a.source, "deploy/demo.sh"), "--seconds", a.seconds, "--out", out,
           "--build", a.build, "--take-frames", "25", "--projectors", str(projectors),
           # The margin sweep has its own test (deploy.margin_sweep); here it would only add time.
           "--sweep-frames", "0"]
    print("running:", " ".join(cmd), flush=True)
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, env=env, timeout=150, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True)
        log, rc = p.stdout, p.returncode
    except subprocess.TimeoutExpired as e:
        log, rc = (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or ""), -1
    print(log)
    print(f"demo.sh exit {rc} after {time.monotonic() - t0:.0f} s; output in {out}")

    failures = []

    def check(cond, what):
        if not cond:
            failures.append(what)

    report_path = os.path.join(out, "report.json")
    if not os.path.exists(report_path):
        print("FAIL: no report.json")
        return 1
    r = json.load(open(report_path))
    check(rc == 0, f"demo.sh exit status {rc} (problems: {r.get('problems')})")
    for f in ("report.md", "latency.png"):
        check(os.path.getsize(os.path.join(out, f)) > 0 if os.path.exists(os.path.join(out, f))
              else False, f"{f} missing")
    with open(os.path.join(out, "latency.png"), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "latency.png is not a PNG")
    check(r["offline"]["meshes"] == 25, f"offline meshes: {r['offline']['meshes']} of 25")
    check(r["clean_stop"], f"services did not stop cleanly: {r['services_exit_status']}")
    check((r.get("take") or {}).get("complete"), "take incomplete")
    check((r.get("rig_check") or {}).get("matches"), f"rig.yaml differs from the published "
          f"calibrations: {r.get('rig_check')}")

    # Honesty of `missing`: a stage is listed iff its binary is not built.
    built = {14: "scene/studio-scene", 15: "projector/studio-projector", 16: "preview/studio-preview"}
    listed = {m["issue"] for m in r["missing"]}
    for issue, binary in built.items():
        if not os.access(os.path.join(a.build, binary), os.X_OK):
            check(issue in listed, f"issue {issue} ({binary}) not built but not listed as missing")
    if 15 in listed or projectors == 0:
        check(r["lit_actor_px"] is None and r["lit_actor_px_reason"], "lit_actor_px without reason")
    else:
        # The projector ran: its light must not fall on the actor.
        d = r.get("lit_actor_detail") or {}
        check(r.get("lit_actor_px") is not None and (d.get("frames_scored") or 0) > 0,
              f"projector ran but lit_actor_px not measured: {r.get('lit_actor_px_reason')}")
        check(r.get("lit_actor_px") == 0,
              f"lit_actor_px {r.get('lit_actor_px')} != 0 (max {d.get('max_per_frame')} per frame at "
              f"{d.get('worst_at')}, {d.get('frames_with_lit')} of {d.get('frames_scored')} frames; "
              f"margin {(r.get('projector') or {}).get('margin_m')}, motion to photon "
              f"{(r.get('projector') or {}).get('motion_to_photon_ms')})")

    fps = r.get("fps") or 0
    p99 = (r.get("latency_ms") or {}).get("p99")
    check(fps >= 20, f"fps {fps:.1f} < 20 ({r.get('fps_stage')})")
    check(p99 is not None and p99 <= 60, f"latency p99 {p99} ms > 60")
    check(r.get("hull_iou") is not None and r["hull_iou"] >= 0.95, f"hull_iou {r.get('hull_iou')} < 0.95")
    check(r.get("head_error_m") is not None and r["head_error_m"] <= 0.03,
          f"head_error_m {r.get('head_error_m')} > 0.03")
    check(r.get("masks_lost") == 0, f"masks_lost {r.get('masks_lost')} != 0")

    # The CPU budget (report.json cpu_budget): every local service's CPU ms per frame period,
    # summed per stage, against the cores' budget; held_back_by.cpu names it in one line.
    b = r.get("cpu_budget") or {}
    stages = b.get("stages_ms_per_frame") or {}
    per = b.get("per_service") or {}
    for stage in ("capture", "hull", "tracker"):
        check((stages.get(stage) or 0) > 0, f"cpu_budget: no CPU measured for stage {stage}: {stages}")
    check(sum(1 for k in per if k.startswith("capture:")) == 6,
          f"cpu_budget: expected the 6 capture servers, got {sorted(per)}")
    check(abs(sum(stages.values()) + (b.get("probe_ms_per_frame") or 0) - (b.get("used_ms_per_frame") or -1)) < 1e-3,
          f"cpu_budget: stages {stages} + probe do not add up to used {b.get('used_ms_per_frame')}")
    check(b.get("cores") == os.cpu_count() and abs((b.get("available_ms_per_frame") or 0) - os.cpu_count() * 1000 / 25) < 1e-6,
          f"cpu_budget: available {b.get('available_ms_per_frame')} ms for {b.get('cores')} cores at 25 fps")
    check(str((r.get("held_back_by") or {}).get("cpu", "")).startswith(f"{b.get('used_ms_per_frame', 0):.1f} of "),
          f"held_back_by.cpu does not state the budget: {(r.get('held_back_by') or {}).get('cpu')}")

    print("cpu per frame:", (r.get("held_back_by") or {}).get("cpu"))
    print("load average start/end:", (r.get("machine") or {}).get("load_average"))
    print("held back by:", json.dumps(r.get("held_back_by")))
    print("lit actor:", r.get("lit_actor_px"), json.dumps(r.get("lit_actor_detail")))
    print("slowest frame:", json.dumps((r.get("latency_ms") or {}).get("slowest_frame")))
    if failures:
        print(open(os.path.join(out, "report.md")).read())
        for f in failures:
            print("FAIL:", f)
        return 1
    subprocess.run(["rm", "-rf", out])
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
