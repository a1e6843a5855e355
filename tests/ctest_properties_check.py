#!/usr/bin/env python3
"""Every ctest test has a TIMEOUT and labels from the known set (cmake/StudioHelpers.cmake).

A test without TIMEOUT can hang CI for as long as the job lives; a test without a label is
outside every `-L` run (CI's `./studio test --asan -L unit`, the GL runs). The check reads
`ctest --show-only=json-v1` of a build tree (or a saved JSON file, for the self-test) and names
each offending test. Placeholders `<binary>_NOT_BUILT` (a gtest binary not built in this tree:
the ASan tree builds only the unit label's binaries) are counted, not checked: ctest fails them
if they are run.

With --sanitizer-exclude FILE (tests/sanitizer-exclude.txt: the release-only tests that
`./studio test --asan` leaves out), every name in it must be a test of the list, so that a
renamed test cannot silently run under ASan again, nor a stale line hide nothing.

usage: ctest_properties_check.py (--build-dir DIR | --tests-json FILE) [--sanitizer-exclude FILE]
       ctest_properties_check.py --self-test
exit 0 when every test passes the check, 1 otherwise, 2 on bad usage or unreadable input.
"""
import argparse
import json
import subprocess
import sys
import tempfile

KNOWN_LABELS = {"unit", "integration", "gl", "dataset"}


def problems(doc):
    """[(test name, what is wrong)] and the number of NOT_BUILT placeholders."""
    out, placeholders = [], 0
    for test in doc.get("tests", []):
        name = test.get("name", "?")
        if name.endswith("_NOT_BUILT"):
            placeholders += 1
            continue
        props = {p["name"]: p["value"] for p in test.get("properties", [])}
        timeout = props.get("TIMEOUT")
        if not isinstance(timeout, (int, float)) or timeout <= 0:
            out.append((name, "no TIMEOUT"))
        labels = props.get("LABELS") or []
        if not labels:
            out.append((name, "no LABELS"))
        unknown = sorted(set(labels) - KNOWN_LABELS)
        if unknown:
            out.append((name, "unknown label(s) " + ",".join(unknown)))
    return out, placeholders


def excluded_names(path):
    """The test names of a sanitizer-exclude file: the first word of each line, # comments out."""
    with open(path) as f:
        return [line.split()[0] for line in f if line.strip() and not line.lstrip().startswith("#")]


def check(doc, exclude=()):
    found, placeholders = problems(doc)
    known = {t.get("name") for t in doc.get("tests", [])}
    found += [(name, "in the sanitizer-exclude list but not a test") for name in exclude
              if name not in known]
    n = len(doc.get("tests", []))
    for name, what in found:
        print(f"ctest_properties: {name}: {what}")
    print(f"ctest_properties: {n - placeholders} tests checked, {len(found)} problem(s), "
          f"{placeholders} not-built placeholder(s) ignored")
    return 1 if found else 0


def self_test():
    """The check on fixture documents: each bad case fails and names the test; the good one passes."""
    def t(name, **props):
        return {"name": name, "properties": [{"name": k, "value": v} for k, v in props.items()]}
    cases = [
        ("clean, two labels", [t("A.ok", TIMEOUT=60.0, LABELS=["integration", "gl"])], 0, None),
        ("missing TIMEOUT", [t("A.ok", TIMEOUT=60.0, LABELS=["unit"]),
                             t("B.lost", LABELS=["integration"])], 1, "B.lost: no TIMEOUT"),
        ("missing LABELS", [t("C.none", TIMEOUT=10.0)], 1, "C.none: no LABELS"),
        ("unknown label", [t("D.odd", TIMEOUT=10.0, LABELS=["unit", "TIMEOUT"])], 1,
         "D.odd: unknown label"),
        ("placeholder ignored", [t("x_test_NOT_BUILT"), t("A.ok", TIMEOUT=1.0, LABELS=["gl"])], 0,
         "1 not-built placeholder"),
        ("excluded test exists", [t("A.ok", TIMEOUT=1.0, LABELS=["unit"])], 0, None, "A.ok  heavy"),
        ("excluded test unknown", [t("A.ok", TIMEOUT=1.0, LABELS=["unit"])], 1,
         "A.gone: in the sanitizer-exclude list", "# comment\nA.ok  heavy\nA.gone  renamed"),
    ]
    failures = 0
    for what, tests, want, text, *exclude in cases:
        with tempfile.NamedTemporaryFile("w", suffix=".json") as f, \
                tempfile.NamedTemporaryFile("w", suffix=".txt") as x:
            json.dump({"kind": "ctestInfo", "tests": tests}, f)
            f.flush()
            args = [sys.executable, __file__, "--tests-json", f.name]
            if exclude:
                x.write(exclude[0] + "\n")
                x.flush()
                args += ["--sanitizer-exclude", x.name]
            r = subprocess.run(args, capture_output=True, text=True)
        ok = r.returncode == want and (text is None or text in r.stdout)
        print(("ok   " if ok else "FAIL ") + what + ("" if ok else f": exit {r.returncode}\n{r.stdout}"))
        failures += not ok
    return 1 if failures else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--build-dir", help="a configured build tree (runs ctest --show-only=json-v1)")
    g.add_argument("--tests-json", help="a saved `ctest --show-only=json-v1` document")
    g.add_argument("--self-test", action="store_true", help="run the check on fixture documents")
    ap.add_argument("--sanitizer-exclude", metavar="FILE",
                    help="tests/sanitizer-exclude.txt: each name in it must be a test of the list")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    try:
        if a.build_dir:
            text = subprocess.run(["ctest", "--test-dir", a.build_dir, "--show-only=json-v1"],
                                  capture_output=True, text=True, check=True).stdout
        else:
            with open(a.tests_json) as f:
                text = f.read()
        doc = json.loads(text)
        exclude = excluded_names(a.sanitizer_exclude) if a.sanitizer_exclude else []
    except (OSError, subprocess.CalledProcessError, json.JSONDecodeError) as e:
        print(f"ctest_properties: cannot read the test list: {e}", file=sys.stderr)
        return 2
    return check(doc, exclude)


if __name__ == "__main__":
    sys.exit(main())
