#!/usr/bin/env python3
"""A skipped test counts as failing unless the allow-list names it with its reason (DESIGN §7).

Reads the JUnit report of a ctest run (ctest --output-junit), prints how many tests there were and
how many were skipped (disabled tests count as skipped), and exits 1 when a skipped test is not in the allow-list, printing each one with the
reason it gave. A skip of a test labelled `dataset` while the shared data directory is missing says
so plainly. Also exits 1 on a malformed allow-list (an entry without a reason).

usage: skip_check.py --junit FILE --allow-list FILE [--tests-json FILE] [--shared-data DIR]
  --tests-json   output of `ctest --show-only=json-v1` (test labels)
  --shared-data  the STUDIO_SHARED_DATA directory the build was configured with

Allow-list lines: `<ctest name or fnmatch pattern> <reason>`; '#' starts a comment.
"""
import argparse
import fnmatch
import json
import os
import sys
import xml.etree.ElementTree as ET


def load_allow_list(path):
    entries = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            text = line.split("#", 1)[0].strip()
            if not text:
                continue
            parts = text.split(None, 1)
            if len(parts) < 2 or len(parts[1].strip()) < 10:
                raise ValueError(f"{path}:{number}: '{parts[0]}' needs a reason (a sentence, after the name)")
            entries.append((parts[0], parts[1].strip()))
    return entries


def skip_reason(case):
    """The message the test gave for skipping: gtest's text after 'Skipped', else its last line."""
    if case.get("status") == "disabled":
        return "disabled (DISABLED_ prefix or DISABLED property)"
    out = (case.findtext("system-out") or "").splitlines()
    for i, line in enumerate(out):
        if line.rstrip().endswith(": Skipped"):
            reason = []
            for follow in out[i + 1:]:
                if follow.startswith("[  SKIPPED ]"):
                    break
                reason.append(follow.strip())
            text = " ".join(r for r in reason if r)
            if text:
                return text
    lines = [l.strip() for l in out if l.strip() and not l.startswith("[")]
    if lines:
        return lines[-1]
    skipped = case.find("skipped")
    return skipped.get("message", "no reason given") if skipped is not None else "no reason given"


def main():
    ap = argparse.ArgumentParser(description="fail on skipped tests not in the allow-list")
    ap.add_argument("--junit", required=True)
    ap.add_argument("--allow-list", required=True)
    ap.add_argument("--tests-json")
    ap.add_argument("--shared-data")
    args = ap.parse_args()
    try:
        allow = load_allow_list(args.allow_list)
    except (OSError, ValueError) as e:
        print(f"skip check: {e}", file=sys.stderr)
        return 1
    try:
        root = ET.parse(args.junit).getroot()
    except (OSError, ET.ParseError) as e:
        print(f"skip check: cannot read the ctest report {args.junit}: {e}", file=sys.stderr)
        return 1
    labels = {}
    if args.tests_json:
        try:
            with open(args.tests_json, encoding="utf-8") as f:
                for t in json.load(f).get("tests", []):
                    for p in t.get("properties", []):
                        if p.get("name") == "LABELS":
                            labels[t["name"]] = p.get("value") or []
        except (OSError, ValueError) as e:
            print(f"skip check: cannot read {args.tests_json}: {e}", file=sys.stderr)
            return 1
    data_missing = args.shared_data is not None and not os.path.isdir(args.shared_data)

    cases = root.iter("testcase")
    total = skipped = allowed = 0
    unlisted = []
    for case in cases:
        total += 1
        # notrun: skipped at run time (gtest's SKIPPED, SKIP_RETURN_CODE); disabled: a DISABLED_
        # gtest or the DISABLED property. Both are tests that did not run.
        if case.find("skipped") is None and case.get("status") not in ("notrun", "disabled"):
            continue
        skipped += 1
        name = case.get("name")
        match = next((reason for pattern, reason in allow if fnmatch.fnmatchcase(name, pattern)), None)
        if match is not None:
            allowed += 1
            print(f"  skipped (allowed): {name}: {match}")
            continue
        unlisted.append((name, skip_reason(case)))

    print(f"{total} tests, {skipped} skipped: {allowed} allowed by {args.allow_list}, "
          f"{len(unlisted)} not allowed")
    for name, reason in unlisted:
        extra = ""
        if data_missing and "dataset" in labels.get(name, []):
            extra = (f" [the shared test data is missing: {args.shared_data} does not exist; "
                     "provide ../shared/data or configure -DSTUDIO_SHARED_DATA=DIR]")
        print(f"FAILED (skipped, not in the allow-list): {name}: {reason}{extra}", file=sys.stderr)
    if unlisted:
        print(f"skip check: {len(unlisted)} skipped test(s) not in {args.allow_list}: a skipped test "
              "counts as failing (DESIGN §7); fix the cause or list it with its reason", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
