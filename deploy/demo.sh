#!/usr/bin/env bash
# deploy/demo.sh — `./studio demo` (which builds first): the studio end to end on this machine.
# Starts every service that exists today as its own process, from the example configs
# (deploy/examples/studio/, the ones the systemd units use), on loopback in a private DDS domain;
# measures it live with studio-demo-probe (one line per second); records a take and reconstructs
# it offline at high resolution; stops everything (SIGTERM, exit codes checked); and writes
# OUT/report.json, report.md, latency.png, projector.png (a scored projector frame: its thumbnail,
# blackout mask and the true actor), actor_view.png (that frame on the cloth seen from the true
# eye: what the actor sees), preview.png (the headless preview's picture) and the offline
# meshes. Builds nothing itself.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

usage() {
  cat <<'TXT'
usage: deploy/demo.sh [--seconds S] [--cameras N] [--projectors N] [--gui] [--out DIR]
                      [--keyer inprocess|separate] [--offline-grid N] [--take-frames N]
                      [--keep-take] [--scheduling realtime|normal] [--sweep-frames N]
                      [--projector-priority P] [--build DIR]

Runs the studio end to end from deploy/examples/studio/ (usually through ./studio demo).
  --seconds S        measurement window (default 20), after the pipeline is up and 3 s warm-up
  --cameras N        simulated cameras 1..6 (default 6: cam0..cam5 at 704x576, 25 fps)
  --projectors N     projectors to run, 0..N (default 1): projector-proj1.yaml .. projN.yaml of
                     deploy/examples/studio/ (the example studio has proj1; a projector without
                     an example config is listed as missing in the report)
  --gui              open the preview window (default: the preview runs headless and takes
                     its pictures at a low rate, one every 2 s, each replacing OUT/preview.png:
                     the last shows the studio as the run ends, projector screens included)
  --out DIR          where the report goes (default out/demo)
  --keyer K          inprocess (default: capture servers key) or separate (studio-keyer services,
                     deploy/examples/studio/separate-keyer/)
  --offline-grid N   columns of the offline reconstruction of the take (default 256)
  --take-frames N    frames of the recorded take (default 50 = 2 s)
  --keep-take        keep the take's raw frames (6 x 1.2 MB per frame) in OUT/takes
  --scheduling S     realtime (default when permitted): the services run SCHED_FIFO at the
                     priorities of their systemd units, in pipeline order (capture 52, keyer
                     54, hull 56, tracker 58, scene 50; the projector 55 (its scene thread
                     time-sharing, see --projector-priority); the probe's receive path 45,
                     its scoring SCHED_IDLE), as installed; the preview time-sharing, as its
                     unit runs it (the headless preview, the report's picture taker, at nice
                     10: below the projector's scene, which the actor sees);
                     normal: time-sharing (the projector at nice 5)
  --projector-priority P
                     with realtime scheduling a SCHED_FIFO priority 1..59, optionally
                     ",nice:N" for its time-sharing threads (default 55,nice:5, the
                     projector's systemd unit: above capture 52 and keyer 54, which then
                     work for the next frame, below hull 56 and tracker 58, whose mesh and
                     head its frame waits for); the real-time part is the masks' path only
                     (render thread, its rasteriser: ~5 ms a mesh): the scene thread, its
                     rasteriser and the motion fit run time-sharing at nice N + 3 (scene_nice,
                     fit_nice; BENCHMARKS.md, demo, session 18); or nice:N, time-sharing (the
                     default under normal scheduling: nice:5)
  --sweep-frames N   frames of the projector mask's margin sweep (default 100; 0: none), run
                     after the services stopped, offline (studio-demo-probe sweep: the fast
                     arm swing through the hull library and the projector's MaskPlanner, at
                     the live motion-to-photon p99): OUT/sweep.json, OUT/sweep.png
  --build DIR        build tree with the binaries (default build/release)
Environment: STUDIO_DDS_DOMAIN / STUDIO_DDS_TAG choose the DDS domain (default: a random private
domain 1..230 and a unique discovery tag, so the demo never meets another studio on this host).
Exit status: 0 the report was written, the pipeline delivered meshes and every service stopped
cleanly; 1 otherwise (the report says what failed); 2 bad arguments or missing binaries.
TXT
}

seconds=20 cameras=6 projectors=1 gui=0 out=out/demo keyer=inprocess offline_grid=256
take_frames=50 keep_take=0 build=build/release scheduling=auto sweep_frames=100
projector_priority=
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=${2:?}; shift 2 ;;
    --cameras) cameras=${2:?}; shift 2 ;;
    --projectors) projectors=${2:?}; shift 2 ;;
    --gui) gui=1; shift ;;
    --out) out=${2:?}; shift 2 ;;
    --keyer) keyer=${2:?}; shift 2 ;;
    --offline-grid) offline_grid=${2:?}; shift 2 ;;
    --take-frames) take_frames=${2:?}; shift 2 ;;
    --keep-take) keep_take=1; shift ;;
    --scheduling) scheduling=${2:?}; shift 2 ;;
    --sweep-frames) sweep_frames=${2:?}; shift 2 ;;
    --build) build=${2:?}; shift 2 ;;
    --projector-priority) projector_priority=${2:?}; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "demo: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
is_int() { [[ "$1" =~ ^[0-9]+$ ]]; }
is_int "$cameras" && [ "$cameras" -ge 1 ] && [ "$cameras" -le 6 ] || { echo "demo: --cameras: expected 1..6" >&2; exit 2; }
is_int "$projectors" || { echo "demo: --projectors: expected a number" >&2; exit 2; }
[[ "$seconds" =~ ^[0-9]+(\.[0-9]+)?$ ]] && [ "${seconds%.*}" -ge 1 ] || { echo "demo: --seconds: expected >= 1" >&2; exit 2; }
is_int "$offline_grid" && [ "$offline_grid" -ge 8 ] || { echo "demo: --offline-grid: expected >= 8" >&2; exit 2; }
is_int "$take_frames" && [ "$take_frames" -ge 1 ] || { echo "demo: --take-frames: expected >= 1" >&2; exit 2; }
is_int "$sweep_frames" && { [ "$sweep_frames" -eq 0 ] || [ "$sweep_frames" -ge 3 ]; } || { echo "demo: --sweep-frames: expected 0 or >= 3" >&2; exit 2; }
case "$keyer" in inprocess|separate) ;; *) echo "demo: --keyer: expected inprocess or separate" >&2; exit 2 ;; esac
case "$scheduling" in
  auto) if chrt -f 1 true 2>/dev/null; then scheduling=realtime; else scheduling=normal; fi ;;
  realtime) chrt -f 1 true 2>/dev/null || { echo "demo: --scheduling realtime: not permitted here (needs CAP_SYS_NICE)" >&2; exit 2; } ;;
  normal) ;;
  *) echo "demo: --scheduling: expected realtime or normal" >&2; exit 2 ;;
esac
[ -n "$projector_priority" ] || { [ "$scheduling" = realtime ] && projector_priority=55,nice:5 || projector_priority=nice:5; }
if [[ "$projector_priority" =~ ^nice:-?[0-9]+$ ]]; then :
elif [[ "$projector_priority" =~ ^([0-9]+)(,nice:-?[0-9]+)?$ ]] && [ "${BASH_REMATCH[1]}" -ge 1 ] && [ "${BASH_REMATCH[1]}" -le 59 ]; then
  [ "$scheduling" = realtime ] || { echo "demo: --projector-priority $projector_priority: a SCHED_FIFO priority needs --scheduling realtime" >&2; exit 2; }
else
  echo "demo: --projector-priority: expected nice:N or a SCHED_FIFO priority 1..59 (optionally ,nice:N)" >&2; exit 2
fi
case "$build" in /*) ;; *) build="$root/$build" ;; esac
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac

say() { printf '[demo] %s\n' "$*" >&2; }

# ---- binaries: what exists today, what does not (and the issue it waits for) ----------------
need() { [ -x "$build/$1" ] || { echo "demo: $build/$1 is not built (run ./studio build, or ./studio demo)" >&2; exit 2; }; }
capture_bin=capture/studio-capture keyer_bin=keyer/studio-keyer hull_bin=hull/studio-hull
tracker_bin=tracker/studio-tracker probe_bin=deploy/demo/studio-demo-probe
for b in $capture_bin $hull_bin $tracker_bin $probe_bin; do need "$b"; done
[ "$keyer" = separate ] && need $keyer_bin
examples="$root/deploy/examples/studio"
# Stages being built by other issues: started here as soon as their binary and example config
# exist (hooks), listed in the report's `missing` otherwise.
scene_bin=scene/studio-scene projector_bin=projector/studio-projector preview_bin=preview/studio-preview
studioctl_bin=deploy/studioctl/studioctl
have() { [ -x "$build/$1" ] && [ -f "$examples/$2" ]; }

# ---- the private DDS domain -----------------------------------------------------------------
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
export STUDIO_DDS_DOMAIN=${STUDIO_DDS_DOMAIN:-$((1 + RANDOM % 230))}
export STUDIO_DDS_TAG=${STUDIO_DDS_TAG:-studio-demo-$$-$RANDOM}
export STUDIO_LOG=${STUDIO_LOG:-info}

# ---- configs: a copy of the examples with the demo's takes_dir --------------------------------
rm -rf "$out/config" "$out/logs" "$out/offline" "$out/takes"
mkdir -p "$out/config" "$out/logs" "$out/offline" "$out/takes"
cfg="$out/config"
cp "$examples"/*.yaml "$cfg/"
if [ "$keyer" = separate ]; then
  cp "$examples"/separate-keyer/*.yaml "$cfg/"
  sed -i 's|^keyer: \.\./keyer\.yaml|keyer: keyer.yaml|' "$cfg"/keyer-keyer*.yaml
fi
sed -i "s|^takes_dir: .*|takes_dir: $out/takes|" "$cfg"/capture-cam*.yaml
# The simulated cameras' clock starts with this run (its epoch a second ago, every camera and the
# probe reading the same configs): the simulated actor's motion (sim/'s sequence: a 16 s cycle
# while it walks round a circle) is then at the same phase in every run's window, so runs can be
# compared. With the examples' epoch 0 the phase followed the wall clock: runs a minute and a
# half apart saw the actor in different places (in the projector's view 8 000 px in one run and
# 27 000 in the next; BENCHMARKS.md, demo, session 14).
epoch_ns=$((($(date +%s) - 1) * 1000000000))
sed -i "s|^clock: {fps: \([0-9.]*\), epoch_ns: 0}|clock: {fps: \1, epoch_ns: $epoch_ns}|" "$cfg"/capture-cam*.yaml
# The scene server: the demo scene of this build tree (installed: /usr/share/studio/scene), its
# persisted state under $out/scene (fresh each run: the scene starts from the file).
if [ -f "$cfg/scene.yaml" ]; then
  rm -rf "$out/scene"
  sed -i -e "s|^scene: .*|scene: $build/scene/default/scene.yaml|" \
    -e "s|^state_dir: .*|state_dir: $out/scene|" "$cfg/scene.yaml"
fi
# The preview resolves the scene's relative asset paths in the same build-tree copy.
if [ -f "$cfg/preview.yaml" ]; then
  sed -i "s|^asset_root: .*|asset_root: $build/scene/default|" "$cfg/preview.yaml"
fi
rm -f "$out/preview.png" "$out/projector.png" "$out/actor_view.png" "$out/sweep.json" "$out/sweep.png"
cam_ids=() capture_cfgs=()
for ((i = 0; i < cameras; i++)); do cam_ids+=("cam$i"); capture_cfgs+=("$cfg/capture-cam$i.yaml"); done
if [ "$cameras" -lt 6 ]; then
  # Fewer cameras: the hull's rig keeps only those (it would wait for the others every frame).
  ids=$(IFS=,; echo "${cam_ids[*]}")
  "$build/$probe_bin" rig --from "$examples/rig.yaml" --cameras "$ids" --out "$cfg/rig.yaml"
  min=$((cameras < 4 ? cameras : 4))
  sed -i "s|^  min_cameras: .*|  min_cameras: $min|" "$cfg/hull.yaml"
fi
hull_box=$(sed -n 's/^  box: *\[\(.*\)\].*/\1/p' "$cfg/hull.yaml" | tr -d ' ')

# ---- processes --------------------------------------------------------------------------------
names=() pids=()
# As the systemd units run them: SCHED_FIFO at the unit's priority (deploy/systemd, issue 19).
# PRIORITY nice:N: time-sharing at nice N in both modes (the projector's unit: llvmpipe's
# rasteriser threads must not take whole cores from the real-time pipeline).
rt() {
  case "$1" in
    nice:*) echo nice -n "${1#nice:}" ;;
    *,nice:*) if [ "$scheduling" = realtime ]; then echo nice -n "${1#*,nice:}" chrt -f "${1%%,*}"; fi ;;
    *) if [ "$scheduling" = realtime ]; then echo chrt -f "$1"; fi ;;
  esac
}
start() {  # start NAME PRIORITY BINARY ARGS...
  local name=$1 prio=$2 bin=$3; shift 3
  $(rt "$prio") "$build/$bin" "$@" >"$out/logs/$name.log" 2>&1 &
  names+=("$name"); pids+=($!)
}
cleanup() {  # on any exit: nothing of ours stays running
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  sleep 1
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
}
trap cleanup EXIT
trap 'exit 130' INT TERM

missing_json="$out/missing.json"
python3 - "$missing_json" "$build" "$examples" "$projectors" "$gui" <<'PY'
import json, os, sys
out, build, ex, projectors, gui = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5] == "1"
def have(b, c): return os.access(os.path.join(build, b), os.X_OK) and (c is None or os.path.exists(os.path.join(ex, c)))
missing = []
if not have("scene/studio-scene", "scene.yaml"):
    missing.append({"stage": "scene server (studio-scene --config scene.yaml)", "issue": 14,
                    "effect": "the live actor mesh and head are not placed in a scene graph"})
if projectors > 0 and not have("projector/studio-projector", None):
    missing.append({"stage": "projector (studio-projector --config projector.yaml)", "issue": 15,
                    "effect": f"no projector image for the {projectors} projector(s) asked; lit_actor_px and projector.png are not measured"})
elif projectors > 0:
    # The example studio's projectors: projector-proj1.yaml, projector-proj2.yaml, ...
    absent = [f"projector-proj{p}.yaml" for p in range(1, projectors + 1)
              if not os.path.exists(os.path.join(ex, f"projector-proj{p}.yaml"))]
    if absent:
        missing.append({"stage": f"example projector config(s) {', '.join(absent)} (deploy/examples/studio/)",
                        "issue": 20, "effect": f"{len(absent)} of the {projectors} projector(s) asked not started (the example studio has {projectors - len(absent)})"})
if not have("preview/studio-preview", "preview.yaml"):
    missing.append({"stage": "director's preview (studio-preview, headless or --gui)", "issue": 16,
                    "effect": "no preview.png" + ("; --gui asked, no window opened" if gui else "")})
if not os.access(os.path.join(build, "deploy/studioctl/studioctl"), os.X_OK):
    missing.append({"stage": "studioctl (the operator's CLI)", "issue": 19,
                    "effect": "the take is commanded by studio-demo-probe take (same CaptureCommand)"})
json.dump(missing, open(out, "w"), indent=1)
for m in missing: print(f"[demo] not built yet: {m['stage']} (issue {m['issue']}): {m['effect']}", file=sys.stderr)
PY

say "scheduling: $scheduling$([ "$scheduling" = realtime ] && echo ' (SCHED_FIFO at the systemd units priorities)')"
say "DDS domain $STUDIO_DDS_DOMAIN (loopback profile, tag $STUDIO_DDS_TAG); logs in $out/logs"
say "starting tracker, hull$([ "$keyer" = separate ] && echo ', 2 keyers'), $cameras capture servers ($keyer keying)"
start tracker 58 "$tracker_bin" --config "$cfg/tracker.yaml"
start hull 56 "$hull_bin" --config "$cfg/hull.yaml"
if [ "$keyer" = separate ]; then
  start keyer0 54 "$keyer_bin" --config "$cfg/keyer-keyer0.yaml"
  start keyer1 54 "$keyer_bin" --config "$cfg/keyer-keyer1.yaml"
fi
for ((i = 0; i < cameras; i++)); do start "cam$i" 52 "$capture_bin" --config "$cfg/capture-cam$i.yaml"; done
if have $scene_bin scene.yaml; then
  say "starting the scene server"
  start scene 50 "$scene_bin" --config "$cfg/scene.yaml"
fi
# The projector: --projector-priority (default: FIFO 55 at nice 5, as its unit; time-sharing at
# nice 5 under normal scheduling).
for ((p = 1; p <= projectors; p++)); do  # the example studio's projectors are proj1, proj2, ...
  if have $projector_bin "projector-proj$p.yaml"; then
    say "starting projector proj$p (projector-proj$p.yaml)"
    start "proj$p" "$projector_priority" "$projector_bin" --config "$cfg/projector-proj$p.yaml"
  fi
done
if have $preview_bin preview.yaml; then
  say "starting the preview ($([ "$gui" = 1 ] && echo window || echo 'headless: a picture every 2 s, preview.png'))"
  if [ "$gui" = 1 ]; then start preview nice:0 "$preview_bin" --config "$cfg/preview.yaml"
  else
    # Low-rate pictures (the issue's "taking its pictures at a low rate"): one mesh drawn every
    # 2 s, textured from the capture servers' image rings with only its own frame's images
    # requested; each picture replaces preview.png; SIGTERM at the end like the others (exit 0
    # when it drew a mesh; exit status checked with the others). At nice 10, below the
    # projector's time-sharing scene thread (nice 5 + 3): on this one machine a picture (~130 ms
    # of llvmpipe every 2 s) at nice 0 took CPU from the projector's frames, i.e. from what the
    # actor sees; in a studio the preview has a PC of its own. BENCHMARKS.md, demo, session 17:
    # p99 115 -> 96 ms (the projector time-sharing then).
    start preview nice:10 "$preview_bin" --config "$cfg/preview.yaml" --headless --every 2 \
      --screenshot "$out/preview.png"
  fi
fi

# ---- live measurement -------------------------------------------------------------------------
say "measuring: ${seconds} s after the pipeline is up (3 s warm-up); one line per second"
probe_rc=0
$(rt 45) "$build/$probe_bin" watch --capture "${capture_cfgs[@]}" --rig "$cfg/rig.yaml" \
  --seconds "$seconds" --warmup 3 --histogram "$out/latency.png" \
  --projector-png "$out/projector.png" --actor-view "$out/actor_view.png" \
  --out "$out/live.json" || probe_rc=$?

# ---- a take, recorded frame-accurately on every camera ------------------------------------------
say "recording a take of $take_frames frames on every camera"
take_rc=0
# studio-demo-probe take publishes the same CaptureCommand (START at a future frame, STOP N frames
# later) as `studioctl capture start|stop --at-frame N` (issue 19), and waits for every camera's
# CameraState to confirm both.
$(rt 45) "$build/$probe_bin" take --capture "${capture_cfgs[@]}" --name demo --frames "$take_frames" \
  --lead 1 --out "$out/take.json" || take_rc=$?

# ---- stop everything: SIGTERM, wait, exit codes ------------------------------------------------
say "stopping ${#pids[@]} services (SIGTERM)"
exit_json="{"
for k in "${!pids[@]}"; do kill -TERM "${pids[$k]}" 2>/dev/null || true; done
deadline=$((SECONDS + 15))
for k in "${!pids[@]}"; do
  # A service that has not ended 15 s after SIGTERM is killed (its status is then 137).
  while kill -0 "${pids[$k]}" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.1; done
  kill -0 "${pids[$k]}" 2>/dev/null && kill -KILL "${pids[$k]}" 2>/dev/null
  rc=0
  wait "${pids[$k]}" || rc=$?
  exit_json+="\"${names[$k]}\": $rc, "
done
exit_json="${exit_json%, }}"
pids=()
echo "$exit_json" >"$out/exit_codes.json"

# ---- offline reconstruction of the take at high resolution --------------------------------------
offline_rc=0
if [ -d "$out/takes/demo" ]; then
  # Only frames every camera recorded can be cut (a loaded machine drops frames while
  # recording, counted in each take.yaml): each contiguous run of them is one offline call.
  python3 "$root/deploy/demo/take_runs.py" "$out/takes/demo" >"$out/take_frames.json"
  runs=$(python3 -c 'import json,sys; print(" ".join(f"{a}:{b}" for a, b in json.load(open(sys.argv[1]))["runs"]))' "$out/take_frames.json")
  say "reconstructing the take offline at ${offline_grid}x${offline_grid} columns: frames every camera recorded ($(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["common"])' "$out/take_frames.json") of $take_frames)"
  : >"$out/offline_timing.json"
  for run in $runs; do
    "$build/$hull_bin" offline --take "$out/takes/demo" --keyer "$cfg/keyer.yaml" --box "$hull_box" \
      --grid "$offline_grid" --frames "$run" --out "$out/offline" --timing --quiet \
      >>"$out/offline_timing.json" 2>>"$out/logs/offline.log" || offline_rc=$?
  done
  [ -n "$runs" ] || offline_rc=1
  if [ -n "$runs" ]; then
    "$build/$probe_bin" score --rig "$cfg/rig.yaml" --meshes "$out/offline" \
      --out "$out/offline_score.json" 2>>"$out/logs/offline.log" || offline_rc=$?
  fi
  if [ "$keep_take" = 0 ]; then find "$out/takes" -name frames.raw -delete; fi
else
  say "no take was recorded"; offline_rc=1
fi

# ---- the projector mask's margin sweep, offline, at the live motion-to-photon p99 ------------------
sweep_rc=0
if [ "$sweep_frames" -gt 0 ] && [ -f "$out/live.json" ]; then
  m2p=$(python3 -c 'import json,sys; p=(json.load(open(sys.argv[1])).get("projector") or {}); v=(p.get("motion_to_photon_ms") or {}).get("p99"); print("" if v is None or v != v else v)' "$out/live.json" 2>/dev/null || true)
  if [ -n "$m2p" ]; then
    say "margin sweep of the projector mask: $sweep_frames frames of the fast arm swing at the live motion-to-photon p99 ($m2p ms)"
    # The sweep's default projector (the simulated studio's, on the side wall): the example
    # proj1's beam does not reach the spot where the arm swing stands.
    "$build/$probe_bin" sweep --rig "$cfg/rig.yaml" --latency-ms "$m2p" --frames "$sweep_frames" --out "$out/sweep.json" --png "$out/sweep.png" \
      2>>"$out/logs/sweep.log" || sweep_rc=$?
  fi
fi

# ---- the report ----------------------------------------------------------------------------------
python3 "$root/deploy/demo/make_report.py" --out "$out" --cameras "$cameras" --keyer "$keyer" \
  --projector-priority "$projector_priority" \
  --scheduling "$scheduling" --projectors "$projectors" \
  --offline-grid "$offline_grid" --probe-rc "$probe_rc" --take-rc "$take_rc" --offline-rc "$offline_rc"
