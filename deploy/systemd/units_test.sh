#!/usr/bin/env bash
# The studio's systemd units, as an operator installs them (issue 19 item 1):
#  1. `cmake --install` of this build into a staging root (DESTDIR) puts the services, studioctl,
#     the units, the sysusers entry, the DDS profiles and the example configs in their FHS places;
#  2. `systemd-analyze verify` accepts every unit (template units as an instance), with the
#     host's own units beside them so dependencies resolve; negative control: with a service
#     binary missing, verify fails;
#  3. `systemd-analyze security --offline=true` rates every headless service at <= 4.9 ("OK");
#     negative control: the same unit without its hardening is rated above 4.9;
#  4. the installed services run with the installed example configs (state paths moved into the
#     staging root, the loopback DDS profile in a domain of this test) and the installed
#     `studioctl status --require` sees each of them; negative control: it fails for a service
#     that was not started.
# usage: units_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
source_dir=$(cd "$2" && pwd)
command -v systemd-analyze >/dev/null || { echo "systemd-analyze missing (Debian package systemd, deploy/debian-packages.txt)"; exit 1; }
stage=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$stage" "$stage.install.log"
}
trap cleanup EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }

DESTDIR="$stage" cmake --install "$build" >"$stage.install.log" 2>&1 || { cat "$stage.install.log"; exit 1; }
prefix=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$build/CMakeCache.txt")
unitdir=$(sed -n 's/^STUDIO_UNITDIR:PATH=//p' "$build/CMakeCache.txt")
[ "$prefix" = /usr ] && etc=/etc || etc=$prefix/etc
echo "installed under $stage (prefix $prefix, units $unitdir, config $etc/studio)"

# 1. FHS places.
for f in "$prefix/bin/studioctl" "$prefix/bin/studio-capture" "$prefix/bin/studio-keyer" \
         "$prefix/bin/studio-hull" "$prefix/bin/studio-tracker" "$prefix/bin/studio-scene" \
         "$unitdir/studio-capture@.service" "$unitdir/studio-scene.service" "$unitdir/studio-keyer@.service" \
         "$unitdir/studio-hull.service" "$unitdir/studio-tracker.service" "$unitdir/studio.target" \
         "$unitdir/studio-projector@.service" "$prefix/bin/studio-projector" \
         "$prefix/lib/sysusers.d/studio.conf" "$etc/studio/dds.xml" \
         "$prefix/share/studio/dds/studio.xml" "$prefix/share/studio/dds/loopback.xml" \
         "$prefix/share/studio/dds/unicast.xml" "$prefix/share/doc/studio/README.md" \
         "$prefix/share/doc/studio/examples/studio/capture-cam0.yaml" \
         "$prefix/share/doc/studio/examples/studio/hull.yaml" "$prefix/share/doc/studio/examples/studio/rig.yaml" \
         "$prefix/share/doc/studio/examples/studio/tracker.yaml" \
         "$prefix/share/doc/studio/examples/studio/scene.yaml" \
         "$prefix/share/studio/scene/scene.yaml" "$prefix/share/studio/scene/museum.glb" \
         "$prefix/share/doc/studio/examples/studio/projector-proj1.yaml" \
         "$prefix/share/doc/studio/examples/studio/separate-keyer/keyer-keyer0.yaml"; do
  [ -e "$stage$f" ] || bad "not installed: $f"
done
for b in studioctl studio-capture studio-keyer studio-hull studio-tracker studio-scene studio-projector; do
  [ -x "$stage$prefix/bin/$b" ] || bad "$prefix/bin/$b is not executable"
done
"$stage$prefix/bin/studioctl" --help >/dev/null || bad "installed studioctl --help failed"
grep -q "ExecStart=$prefix/bin/studio-capture --config $etc/studio/capture-%i.yaml" \
  "$stage$unitdir/studio-capture@.service" || bad "capture unit does not start the installed binary with its per-instance config"

# The host's units beside ours (targets, slices), so that dependencies resolve under --root.
mkdir -p "$stage/usr/lib/systemd/system"
cp -rn /usr/lib/systemd/system/. "$stage/usr/lib/systemd/system/" 2>/dev/null || true
find "$stage/usr/lib/systemd/system" -type l -delete
if [ "$unitdir" != /usr/lib/systemd/system ]; then
  for u in "$stage$unitdir"/studio*; do cp "$u" "$stage/usr/lib/systemd/system/"; done
fi

units="studio-capture@cam0.service studio-keyer@keyer0.service studio-hull.service studio-tracker.service studio-scene.service studio-projector@proj1.service studio.target"
headless="studio-capture@cam0.service studio-keyer@keyer0.service studio-hull.service studio-tracker.service studio-scene.service studio-projector@proj1.service"

# 2. verify.
for u in $units; do
  if out=$(systemd-analyze verify --root="$stage" "$u" 2>&1); then
    echo "ok   verify $u"
  else
    bad "systemd-analyze verify $u: $out"
  fi
done
# Negative control: the same verification refuses a unit whose binary is missing.
mv "$stage$prefix/bin/studio-hull" "$stage/studio-hull.moved"
if systemd-analyze verify --root="$stage" studio-hull.service >/dev/null 2>&1; then
  bad "verify accepted studio-hull.service without its binary (the check cannot fail)"
else
  echo "ok   verify refuses a unit whose binary is missing"
fi
mv "$stage/studio-hull.moved" "$stage$prefix/bin/studio-hull"

# 3. security rating.
rating() {  # prints the overall exposure of unit $1
  systemd-analyze security --offline=true --root="$stage" "$1" 2>/dev/null |
    sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p'
}
for u in $headless; do
  r=$(rating "$u")
  if [ -z "$r" ]; then
    bad "systemd-analyze security gave no rating for $u"
  elif awk -v r="$r" 'BEGIN { exit !(r <= 4.9) }'; then
    echo "ok   security $u: $r"
  else
    bad "security $u: $r > 4.9"
  fi
done
# Negative control: the hull unit without its hardening is rated above 4.9.
sed -e '/^# Hardening/,/^KeyringMode=/d' -e '/^PrivateDevices=/d' -e '/^DevicePolicy=/d' \
  "$stage/usr/lib/systemd/system/studio-hull.service" >"$stage/usr/lib/systemd/system/studio-bare.service"
r=$(rating studio-bare.service)
if [ -n "$r" ] && awk -v r="$r" 'BEGIN { exit !(r > 4.9) }'; then
  echo "ok   the same unit without hardening rates $r (> 4.9)"
else
  bad "the unhardened unit rated '$r': the rating check cannot fail"
fi

# 4. The installed services with the installed example configs.
examples="$stage$prefix/share/doc/studio/examples"
run="$stage/run"
mkdir -p "$run/var/lib/studio"
# The complete studio's configs (deploy/examples/studio/), as an operator copies them to
# /etc/studio/ (capture's keyer.yaml and the keyer's ../keyer.yaml are relative to each file).
mkdir -p "$run/separate-keyer"
for f in capture-cam0.yaml keyer.yaml tracker.yaml scene.yaml separate-keyer/keyer-keyer0.yaml \
         projector-proj1.yaml projectors.yaml; do
  sed -e "s|/var/lib/studio|$run/var/lib/studio|g" -e "s|/usr/share/studio|$stage$prefix/share/studio|g" \
    "$examples/studio/$f" >"$run/$f"
done
export CYCLONEDDS_URI="file://$source_dir/deploy/dds/loopback.xml"
export STUDIO_DDS_DOMAIN=$((200 + RANDOM % 30))
export STUDIO_DDS_TAG="units-test-$$-$RANDOM"
"$stage$prefix/bin/studio-capture" --config "$run/capture-cam0.yaml" >"$run/capture.log" 2>&1 & pids+=($!)
"$stage$prefix/bin/studio-tracker" --config "$run/tracker.yaml" >"$run/tracker.log" 2>&1 & pids+=($!)
"$stage$prefix/bin/studio-keyer" --config "$run/separate-keyer/keyer-keyer0.yaml" >"$run/keyer.log" 2>&1 & pids+=($!)
"$stage$prefix/bin/studio-scene" --config "$run/scene.yaml" >"$run/scene.log" 2>&1 & pids+=($!)
"$stage$prefix/bin/studio-projector" --config "$run/projector-proj1.yaml" >"$run/projector.log" 2>&1 & pids+=($!)
ctl="$stage$prefix/bin/studioctl"
ok=0
for _ in $(seq 1 15); do
  if "$ctl" status --require capture:cam0,tracker:tracker,keyer:keyer0,scene:scene,projector:proj1 --wait 2 >"$run/status.txt" 2>"$run/status.err"; then
    ok=1
    break
  fi
done
if [ $ok = 1 ]; then
  echo "ok   the installed services run with the example configs:"
  sed 's/^/       /' "$run/status.txt"
else
  bad "the example services did not all report: $(cat "$run/status.err")"
  for l in capture tracker keyer scene projector; do echo "---- $l"; cat "$run/$l.log"; done
fi
if "$ctl" status --require hull --wait 1 >/dev/null 2>&1; then
  bad "studioctl status --require hull passed without a hull running"
else
  echo "ok   studioctl status --require hull fails: no hull was started"
fi
exit $fail
