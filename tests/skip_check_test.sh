#!/usr/bin/env bash
# Tests tests/skip_check.py (the mechanism behind `./studio test` failing on skips) on fake ctest
# JUnit reports: an unlisted skip fails and is named with its reason; the same skip listed passes
# (the positive control); an allow-list entry without a reason is refused; a dataset test skipped
# while the shared data is missing says so; a report without skips passes and counts 0.
set -euo pipefail
check=$(cd "$(dirname "$0")" && pwd)/skip_check.py
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failures=0
expect() {  # expect NAME WANT_RC GREP_PATTERN -- args...
  local name=$1 want=$2 pattern=$3
  shift 4
  local rc=0
  python3 "$check" "$@" >"$dir/out" 2>&1 || rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, expected $want"; cat "$dir/out"; failures=$((failures + 1)); return
  fi
  if ! grep -qE -- "$pattern" "$dir/out"; then
    echo "FAIL $name: output lacks /$pattern/"; cat "$dir/out"; failures=$((failures + 1)); return
  fi
  echo "ok   $name"
}

cat >"$dir/junit.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="(empty)" tests="3" failures="0" disabled="0" skipped="1" hostname="" time="0">
  <testcase name="Dino.Carves" classname="Dino.Carves" time="0.01" status="notrun">
    <skipped message="SKIP_REGULAR_EXPRESSION_MATCHED"/>
    <system-out>[ RUN      ] Dino.Carves
hull/dino_test.cc:23: Skipped
no middlebury_dino (shared test data)
[  SKIPPED ] Dino.Carves (0 ms)
</system-out>
  </testcase>
  <testcase name="Hull.Cuts" classname="Hull.Cuts" time="0.02" status="run"><system-out/></testcase>
  <testcase name="Wire.Echo" classname="Wire.Echo" time="0.02" status="run"><system-out/></testcase>
</testsuite>
XML
cat >"$dir/disabled.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="(empty)" tests="2" failures="0" disabled="1" skipped="0" hostname="" time="0">
  <testcase name="Keyer.Analysis" classname="Keyer.Analysis" time="0" status="disabled"><system-out>Disabled</system-out></testcase>
  <testcase name="Hull.Cuts" classname="Hull.Cuts" time="0.02" status="run"><system-out/></testcase>
</testsuite>
XML
cat >"$dir/clean.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="(empty)" tests="1" failures="0" disabled="0" skipped="0" hostname="" time="0">
  <testcase name="Hull.Cuts" classname="Hull.Cuts" time="0.02" status="run"><system-out/></testcase>
</testsuite>
XML
cat >"$dir/tests.json" <<'JSON'
{"kind": "ctestInfo", "tests": [{"name": "Dino.Carves", "properties": [{"name": "LABELS", "value": ["dataset"]}]}]}
JSON
printf '# nothing allowed\n' >"$dir/empty.txt"
printf 'Dino.*   the dino data set is not licensed for this machine\n' >"$dir/listed.txt"
printf 'Dino.Carves\n' >"$dir/noreason.txt"

expect "unlisted skip fails, named with its reason" 1 \
  'FAILED \(skipped, not in the allow-list\): Dino.Carves: no middlebury_dino \(shared test data\)' -- \
  --junit "$dir/junit.xml" --allow-list "$dir/empty.txt"
expect "the skip count is printed" 1 '3 tests, 1 skipped: 0 allowed' -- \
  --junit "$dir/junit.xml" --allow-list "$dir/empty.txt"
expect "listed skip passes (positive control)" 0 'skipped \(allowed\): Dino.Carves: the dino data set' -- \
  --junit "$dir/junit.xml" --allow-list "$dir/listed.txt"
expect "allow-list entry without a reason is refused" 1 'needs a reason' -- \
  --junit "$dir/junit.xml" --allow-list "$dir/noreason.txt"
expect "dataset skip with missing data says so" 1 'shared test data is missing: .*/nowhere does not exist' -- \
  --junit "$dir/junit.xml" --allow-list "$dir/empty.txt" --tests-json "$dir/tests.json" \
  --shared-data "$dir/nowhere"
expect "a disabled test counts as skipped" 1 'Keyer.Analysis: disabled' -- \
  --junit "$dir/disabled.xml" --allow-list "$dir/empty.txt"
printf 'Keyer.Analysis  an analysis aid that asserts nothing\n' >"$dir/disabled-listed.txt"
expect "a listed disabled test passes" 0 '2 tests, 1 skipped: 1 allowed' -- \
  --junit "$dir/disabled.xml" --allow-list "$dir/disabled-listed.txt"
expect "no skips passes" 0 '1 tests, 0 skipped' -- \
  --junit "$dir/clean.xml" --allow-list "$dir/empty.txt"
expect "missing report fails" 1 'cannot read the ctest report' -- \
  --junit "$dir/absent.xml" --allow-list "$dir/empty.txt"
# The checked-in allow-list itself is well formed (every entry has a reason).
expect "checked-in allow-list parses" 0 '0 skipped' -- \
  --junit "$dir/clean.xml" --allow-list "$(dirname "$check")/skip-allowlist.txt"

# The real ctest of this machine: its JUnit report of a gtest-style skip and of a SKIP_RETURN_CODE
# skip is what the checker reads.
mkdir -p "$dir/probe"
cat >"$dir/probe/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(probe NONE)
enable_testing()
add_test(NAME Probe.Skips COMMAND sh -c "echo 'probe.cc:3: Skipped'; echo 'no probe data'; echo '[  SKIPPED ] Probe.Skips (0 ms)'")
set_tests_properties(Probe.Skips PROPERTIES SKIP_REGULAR_EXPRESSION "\\[  SKIPPED \\]")
add_test(NAME Probe.Exit77 COMMAND sh -c "echo 'cannot unshare'; exit 77")
set_tests_properties(Probe.Exit77 PROPERTIES SKIP_RETURN_CODE 77)
add_test(NAME Probe.Runs COMMAND true)
CMAKE
cmake -S "$dir/probe" -B "$dir/probe/build" >/dev/null
ctest --test-dir "$dir/probe/build" --output-junit "$dir/probe.xml" >/dev/null 2>&1 || true
printf 'Probe.Skips  the probe has no data, by design of this test\n' >"$dir/probe-one.txt"
printf 'Probe.*  the probe skips by design of this test\n' >"$dir/probe-all.txt"
expect "real ctest: unlisted SKIP_RETURN_CODE skip fails" 1 'Probe.Exit77: cannot unshare' -- \
  --junit "$dir/probe.xml" --allow-list "$dir/probe-one.txt"
expect "real ctest: both listed pass" 0 '3 tests, 2 skipped: 2 allowed' -- \
  --junit "$dir/probe.xml" --allow-list "$dir/probe-all.txt"
[ "$failures" -eq 0 ] || { echo "$failures case(s) failed"; exit 1; }
