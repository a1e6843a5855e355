#!/usr/bin/env python3
"""Folder dependency check (DESIGN §2 "services side by side"; issue 13 item 5).

Derives the dependency graph of the repository's folders from two sources:
  - every `#include "..."` line of every .h / .cc file, resolved to the file it names;
  - every CMakeLists.txt: add_library / add_executable / studio_test / studio_bench /
    studio_fuzz (which folder a target belongs to, which sources it compiles),
    target_link_libraries and the LIBS of the studio_* helpers (target -> target),
    target_include_directories (which folders a target puts on its include path).

A vertex is a *unit*: a top-level folder's library part (`hull`), or one of its edge parts:
`hull/node`, `hull/cli`, `hull/tests` (tests, benchmarks, fuzzers and their helpers in
testing/). The folder `tests/` is a test unit as a whole. Library parts are what other
folders build on; node, cli and test parts are consumers at the edge of the graph (a node
adds idl/ and runtime/, tests add sim/ and tests/support).

It fails (exit 1, one line per problem) on
  (a) a cycle between units (so between the top-level folders' libraries);
  (b) a unit reaching into another folder's node/ or cli/ (an include, a compiled source,
      an include directory or a linked target there);
  (c) a service folder (capture, keyer, hull, tracker, scene, projector, preview, calibrate)
      depending, outside its tests, on another service's library, unless the edge is in
      ALLOWED below with its reason;
  (d) a production unit (library, node, cli) depending on sim/ or tests/, unless in ALLOWED;
  (e) docs/architecture.md's generated section differing from what --write-docs writes.

Usage: check-folder-graph.py [--root DIR] [--write-docs] [--no-docs] [--json] [--verbose]
Exit status: 0 clean, 1 violations, 2 usage or I/O error.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from collections import defaultdict
from pathlib import Path

SERVICES = {"capture", "keyer", "hull", "tracker", "scene", "projector", "preview", "calibrate"}

# Include roots that are not named after their folder.
INCLUDE_ROOTS = {
    "yaml_io": "core",   # core/yaml/include/yaml_io
    "wire": "idl",       # idl/include/wire
    "harness": "tests",  # tests/harness
    "support": "tests",  # tests/support
}
# Headers generated into the build tree, by the folder that generates them.
GENERATED = {"studio.h": "idl"}

# Edges that rules (b), (c) or (d) would refuse but that are deliberate. (from, to): reason.
# A unit is "folder" (its library) or "folder/node", "folder/cli", "folder/tests".
ALLOWED = {
    ("tracker", "hull"):
        "pure type: the tracker's input is hull::SegmentSet (hull/segment_set.h) and its grid",
    ("idl", "hull"):
        "the one IDL <-> core conversion of studio/actor/segments (wire/actor_convert.h) "
        "converts to hull::SegmentSet",
    ("idl", "tracker"):
        "the one IDL <-> core conversion of studio/actor/head (wire/actor_convert.h) converts "
        "to tracker::HeadPose",
    ("capture", "sim"):
        "capture offers a simulated camera source: studio_capture_sim_source is a thin "
        "FrameSource adapter over the simulated studio",
    ("capture/node", "sim"):
        "studio-capture offers the simulated camera source (source: {type: sim})",
    ("capture/node", "keyer"):
        "in-process keying: the capture node keys its frames with the keyer library",
    ("hull/cli", "capture"):
        "pure type: studio-hull offline reads recorded takes (capture/take.h, the take format)",
    ("hull/cli", "keyer"):
        "studio-hull offline --take keys the recorded frames with the keyer library",
    ("tracker/node", "hull"):
        "pure type: the tracker node reads studio/actor/segments as hull::SegmentSet",
    ("tracker/cli", "hull"):
        "pure type: studio-tracker locate cuts masks into a hull::SegmentSet",
    ("preview", "scene"):
        "pure type: the preview's textured actor draws scene::ActorMesh (scene/actor_mesh.h)",
    ("preview/node", "scene"):
        "the director's preview mirrors the scene graph (scene library) and draws it with the "
        "project's one renderer (scene_render), as DESIGN §2 places it in scene/",
    ("deploy/demo", "sim"):
        "the demo's probe (studio-demo-probe, a measuring tool, not a service) scores the live "
        "studio against the simulated studio's truth for the same frame",
    ("projector", "scene"):
        "the projector frame (projector/render) draws with the project's one OpenGL renderer "
        "(scene/render, studio_scene_render: DESIGN §1, shared by projector and preview)",
    ("projector/node", "scene"):
        "the projector node mirrors studio/scene/node into a scene::Scene (studio_scene_wire) "
        "and loads the assets its nodes name (scene_assets)",
    ("projector/cli", "scene"):
        "studio-projector render reads a scene file (scene_config) and draws it",
    ("deploy/demo", "tests"):
        "the demo's probe scores meshes with the test helpers' mask IoU and rasteriser",
}

DOC_BEGIN = "<!-- BEGIN folder-graph: generated by cmake/check-folder-graph.py --write-docs -->"
DOC_END = "<!-- END folder-graph -->"

SKIP_DIRS = {"build", ".git", "node_modules", "__pycache__"}
SOURCE_EXT = (".h", ".hh", ".hpp", ".cc", ".cpp", ".c", ".inc")


def unit_of(rel: str) -> str | None:
    """The unit of a repository-relative path, None for files outside any folder."""
    parts = rel.split("/")
    if len(parts) < 2:
        return None
    folder = parts[0]
    if folder == "tests":
        return "tests"
    if folder == "deploy" and len(parts) > 2 and parts[1] == "demo":
        return "deploy/demo"  # the demo and its probe: a measuring tool beside the services
    name = parts[-1]
    if "testing" in parts[1:-1] or re.search(r"_(test|bench|fuzz)\.(cc|cpp|h)$", name) \
            or name in ("test_frames.h",):
        return folder + "/tests"
    # node/ and cli/ at any depth below the folder (core/yaml is core's library).
    for p in parts[1:-1]:
        if p in ("node", "cli"):
            return folder + "/" + p
    return folder


def folder_of(unit: str) -> str:
    return unit.split("/")[0]


def part_of(unit: str) -> str:
    if unit == "tests":
        return "tests"
    return unit.split("/")[1] if "/" in unit else "lib"


class Graph:
    def __init__(self) -> None:
        # (from, to) -> list of evidence strings ("file:line: #include ...").
        self.edges: dict[tuple[str, str], list[str]] = defaultdict(list)
        self.units: set[str] = set()

    def add(self, a: str, b: str, why: str) -> None:
        self.units.update((a, b))
        if a != b:
            self.edges[(a, b)].append(why)


# ------------------------------------------------------------------------------- includes ----

INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def walk_sources(root: Path):
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and not d.startswith("."))
        for f in sorted(filenames):
            if f.endswith(SOURCE_EXT):
                yield Path(dirpath) / f


def resolve_include(inc: str, includer: str, files: set[str], by_suffix: dict[str, list[str]]):
    """The repository file an include names: next to the includer, else the unique file whose
    path ends with the include (preferring the includer's folder). None when not in the tree."""
    here = os.path.dirname(includer)
    local = os.path.normpath(os.path.join(here, inc))
    if local in files:
        return local
    # A file below an include/ directory is reachable only by its path relative to include/
    # ("sim/studio.h" is sim/include/sim/studio.h; a bare "studio.h" is not).
    candidates = [c for c in by_suffix.get(inc, [])
                  if "include" not in c.split("/")[:-1] or c[:-len(inc)].endswith("include/")]
    if not candidates:
        return None
    own = [c for c in candidates if c.split("/")[0] == includer.split("/")[0]]
    if len(own) == 1:
        return own[0]
    if len(candidates) == 1:
        return candidates[0]
    # Rooted includes ("core/camera.h") resolve through the include root's folder.
    head = inc.split("/")[0]
    folder = INCLUDE_ROOTS.get(head, head)
    rooted = [c for c in candidates if c.split("/")[0] == folder]
    return rooted[0] if len(rooted) == 1 else None


def scan_includes(root: Path, graph: Graph) -> None:
    paths = [p.relative_to(root).as_posix() for p in walk_sources(root)]
    files = set(paths)
    by_suffix: dict[str, list[str]] = defaultdict(list)
    for p in paths:
        parts = p.split("/")
        for k in range(len(parts)):
            by_suffix["/".join(parts[k:])].append(p)
    for rel in paths:
        src = unit_of(rel)
        if src is None:
            continue
        graph.units.add(src)
        try:
            lines = (root / rel).read_text(encoding="utf-8", errors="replace").splitlines()
        except OSError as e:
            raise SystemExit(f"check-folder-graph: cannot read {rel}: {e}")
        for n, line in enumerate(lines, 1):
            m = INCLUDE_RE.match(line)
            if not m:
                continue
            inc = m.group(1)
            target = resolve_include(inc, rel, files, by_suffix)
            if target is not None:
                dst = unit_of(target)
            elif inc in GENERATED:
                dst = GENERATED[inc]
            else:
                continue  # a system or third-party header written with quotes
            if dst is not None:
                graph.add(src, dst, f'{rel}:{n}: #include "{inc}"')


# ---------------------------------------------------------------------------------- CMake ----

COMMAND_RE = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(")
LINK_KEYWORDS = {"PUBLIC", "PRIVATE", "INTERFACE", "LINK_PUBLIC", "LINK_PRIVATE"}
LIB_KEYWORDS = {"STATIC", "SHARED", "MODULE", "OBJECT", "INTERFACE", "EXCLUDE_FROM_ALL"}
HELPER_KEYWORDS = {"NAME", "SOURCES", "LIBS", "LABELS", "TIMEOUT"}


def strip_comments(text: str) -> str:
    out = []
    for line in text.splitlines():
        # A '#' outside a quoted string starts a comment.
        quoted = False
        cut = len(line)
        for i, ch in enumerate(line):
            if ch == '"':
                quoted = not quoted
            elif ch == "#" and not quoted:
                cut = i
                break
        out.append(line[:cut])
    return "\n".join(out)


def commands(text: str):
    """(name, [arguments], line) of every command call in a CMakeLists text."""
    text = strip_comments(text)
    pos = 0
    while True:
        m = COMMAND_RE.search(text, pos)
        if not m:
            return
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            i += 1
        body = text[m.end():i - 1]
        line = text.count("\n", 0, m.start()) + 1
        args = re.findall(r'"[^"]*"|[^\s"]+', body)
        yield m.group(1).lower(), [a.strip('"') for a in args], line
        pos = i


def expand(arg: str, cmake_dir: str) -> str:
    arg = arg.replace("${CMAKE_CURRENT_SOURCE_DIR}", cmake_dir or ".")
    arg = arg.replace("${PROJECT_SOURCE_DIR}", ".").replace("${CMAKE_SOURCE_DIR}", ".")
    return arg


def rel_path(arg: str, cmake_dir: str) -> str | None:
    if "$<" in arg or "${" in expand(arg, cmake_dir):
        return None
    p = expand(arg, cmake_dir)
    if not p.startswith("./") and p != "." and not os.path.isabs(p):
        p = os.path.join(cmake_dir, p) if cmake_dir else p
    return os.path.normpath(p)


def scan_cmake(root: Path, graph: Graph) -> None:
    targets: dict[str, str] = {}           # target -> unit
    links: list[tuple[str, str, str]] = []  # (target, library, where)
    for cm in sorted(root.rglob("CMakeLists.txt")):
        rel = cm.relative_to(root).as_posix()
        if rel.split("/")[0] in SKIP_DIRS:
            continue
        cmake_dir = os.path.dirname(rel)
        text = cm.read_text(encoding="utf-8", errors="replace")
        for name, args, line in commands(text):
            where = f"{rel}:{line}"
            if name in ("add_library", "add_executable") and args:
                target = args[0]
                sources = [a for a in args[1:] if a not in LIB_KEYWORDS]
                units = source_units(sources, cmake_dir)
                targets[target] = target_unit(units, cmake_dir, test=False)
                for u, src in units:
                    if u != targets[target]:
                        graph.add(targets[target], u, f"{where}: {target} compiles {src}")
            elif name in ("studio_test", "studio_bench", "studio_fuzz"):
                opts = helper_args(args)
                if not opts.get("NAME"):
                    continue
                target = opts["NAME"][0]
                units = source_units(opts.get("SOURCES", []), cmake_dir)
                targets[target] = target_unit(units, cmake_dir, test=True)
                for u, src in units:
                    if u != targets[target] and folder_of(u) != folder_of(targets[target]):
                        graph.add(targets[target], u, f"{where}: {target} compiles {src}")
                for lib in opts.get("LIBS", []):
                    links.append((target, lib, where))
            elif name == "target_link_libraries" and args:
                for lib in args[1:]:
                    if lib not in LINK_KEYWORDS:
                        links.append((args[0], lib, where))
            elif name == "target_include_directories" and args:
                for d in args[1:]:
                    if d in LINK_KEYWORDS or d in ("SYSTEM", "BEFORE", "AFTER"):
                        continue
                    p = rel_path(d, cmake_dir)
                    if p is None or p.startswith(".."):
                        continue
                    u = unit_of(p + "/x.h")
                    if u is not None:
                        links.append((args[0], "dir:" + u, where + f": includes {p}/"))
    for target, lib, where in links:
        src = targets.get(target)
        if src is None:
            continue
        if lib.startswith("dir:"):
            graph.add(src, lib[4:], where)
        elif lib in targets:
            graph.add(src, targets[lib], f"{where}: {target} links {lib}")


def helper_args(args: list[str]) -> dict[str, list[str]]:
    opts: dict[str, list[str]] = {}
    key = None
    for a in args:
        if a in HELPER_KEYWORDS:
            key = a
            opts.setdefault(key, [])
        elif key is not None:
            opts[key].append(a)
    return opts


def source_units(sources: list[str], cmake_dir: str) -> list[tuple[str, str]]:
    out = []
    for s in sources:
        p = rel_path(s, cmake_dir)
        if p is None or p.startswith(".."):
            continue
        u = unit_of(p)
        if u is not None:
            out.append((u, p))
    return out


def target_unit(units: list[tuple[str, str]], cmake_dir: str, test: bool) -> str:
    """A target's unit: test helpers are their folder's tests; otherwise the unit most of its
    own folder's sources belong to (a target compiling another folder's sources still belongs
    to the folder that defines it)."""
    folder = cmake_dir.split("/")[0] if cmake_dir else ""
    if test:
        return "tests" if folder == "tests" else folder + "/tests"
    own = [u for u, _ in units if folder_of(u) == folder]
    if not own:
        return unit_of(cmake_dir + "/x.h") if cmake_dir else folder
    counts: dict[str, int] = defaultdict(int)
    for u in own:
        counts[u] += 1
    return max(sorted(counts), key=lambda u: counts[u])


# ---------------------------------------------------------------------------------- rules ----

def find_cycles(graph: Graph) -> list[list[str]]:
    """Strongly connected components with more than one unit (Tarjan, iterative)."""
    succ: dict[str, list[str]] = defaultdict(list)
    for a, b in graph.edges:
        # A folder's node/, cli/ and tests may use each other (studio-tracker is its node and
        # its CLI in one binary): those edges stay inside the folder and make no folder cycle.
        if folder_of(a) == folder_of(b) and part_of(a) != "lib" and part_of(b) != "lib":
            continue
        succ[a].append(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    result = []
    counter = 0
    for start in sorted(graph.units):
        if start in index:
            continue
        work = [(start, iter(sorted(succ[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(succ[w]))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    result.append(sorted(comp))
    return sorted(result)


def check(graph: Graph) -> tuple[list[str], set[tuple[str, str]]]:
    problems: list[str] = []
    used_allowances: set[tuple[str, str]] = set()
    for comp in find_cycles(graph):
        members = set(comp)
        evidence = [f"{a} -> {b} ({graph.edges[(a, b)][0]})"
                    for (a, b) in sorted(graph.edges) if a in members and b in members]
        problems.append("cycle between " + ", ".join(comp) + ": " + "; ".join(evidence))
    for (a, b), why in sorted(graph.edges.items()):
        fa, fb = folder_of(a), folder_of(b)
        if fa == fb:
            if part_of(a) == "lib" and part_of(b) != "lib":
                problems.append(f"library {a} depends on its own {b}/ ({why[0]})")
            continue
        rule = None
        if part_of(b) in ("node", "cli"):
            rule = f"{a} reaches into {fb}/{part_of(b)}/"
        elif part_of(a) != "tests" and fa in SERVICES and fb in SERVICES and part_of(b) == "lib":
            rule = f"service {a} depends on the {fb} service library"
        elif part_of(a) != "tests" and fb in ("sim", "tests"):
            rule = f"production unit {a} depends on {b}"
        if rule is None:
            continue
        if (a, b) in ALLOWED:
            used_allowances.add((a, b))
            continue
        problems.append(f"{rule} ({why[0]})")
    return problems, used_allowances


# ----------------------------------------------------------------------------------- docs ----

def mermaid(graph: Graph) -> str:
    """The production graph (libraries, nodes and CLIs; tests left out: they may use sim/ and
    tests/support) as a mermaid flowchart. Allow-listed edges are dotted."""
    units = sorted({u for e in graph.edges for u in e if part_of(u) != "tests"} |
                   {u for u in graph.units if part_of(u) == "lib" and u != "tests"})
    ident = {u: re.sub(r"[^A-Za-z0-9]", "_", u) for u in units}
    lines = ["```mermaid", "flowchart BT"]
    for u in units:
        shape = f'{ident[u]}["{u}/"]' if part_of(u) == "lib" else f'{ident[u]}(["{u}/"])'
        lines.append("  " + shape)
    for (a, b) in sorted(graph.edges):
        if a not in ident or b not in ident or b == "core":
            continue
        arrow = "-.->" if (a, b) in ALLOWED else "-->"
        lines.append(f"  {ident[a]} {arrow} {ident[b]}")
    lines.append("```")
    return "\n".join(lines)


def docs_section(graph: Graph) -> str:
    allowed = "\n".join(f"| `{a}` → `{b}` | {reason} |"
                        for (a, b), reason in sorted(ALLOWED.items())
                        if (a, b) in graph.edges)
    return "\n".join([
        DOC_BEGIN,
        "",
        "Units: a folder's library (`hull/`), its node (`hull/node/`) and its command line",
        "(`hull/cli/`); tests, benchmarks and test helpers are left out (they may add `sim/` and",
        "`tests/`). An arrow is \"depends on\" (an include, a linked target or a compiled",
        "source); dotted arrows are the allow-listed edges below. Every unit depends on `core/`;",
        "those arrows are not drawn.",
        "",
        mermaid(graph),
        "",
        "| allowed edge | reason |",
        "|---|---|",
        allowed,
        "",
        DOC_END,
    ])


def replace_section(text: str, section: str) -> str | None:
    begin, end = text.find(DOC_BEGIN), text.find(DOC_END)
    if begin < 0 or end < begin:
        return None
    return text[:begin] + section + text[end + len(DOC_END):]


# ----------------------------------------------------------------------------------- main ----

def build_graph(root: Path) -> Graph:
    graph = Graph()
    scan_includes(root, graph)
    scan_cmake(root, graph)
    return graph


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="Rules (a)-(e) and the allow-list: see the script's header.")
    ap.add_argument("--root", default=str(Path(__file__).resolve().parent.parent),
                    help="repository root (default: the checkout holding this script)")
    ap.add_argument("--docs", default=None,
                    help="file with the generated section (default: ROOT/docs/architecture.md)")
    ap.add_argument("--write-docs", action="store_true",
                    help="rewrite the generated section of the docs file, then check")
    ap.add_argument("--no-docs", action="store_true", help="skip rule (e)")
    ap.add_argument("--json", action="store_true", help="print the graph and problems as JSON")
    ap.add_argument("--verbose", action="store_true", help="print every edge with its evidence")
    args = ap.parse_args(argv)

    root = Path(args.root).resolve()
    if not root.is_dir():
        print(f"check-folder-graph: {root}: not a directory", file=sys.stderr)
        return 2
    graph = build_graph(root)
    problems, used = check(graph)

    if not args.no_docs:
        docs = Path(args.docs) if args.docs else root / "docs" / "architecture.md"
        try:
            text = docs.read_text(encoding="utf-8")
        except OSError as e:
            print(f"check-folder-graph: cannot read {docs}: {e}", file=sys.stderr)
            return 2
        updated = replace_section(text, docs_section(graph))
        if updated is None:
            problems.append(f"{docs}: no generated folder-graph section ({DOC_BEGIN!r} ... "
                            f"{DOC_END!r})")
        elif args.write_docs:
            if updated != text:
                docs.write_text(updated, encoding="utf-8")
                print(f"check-folder-graph: wrote the folder graph into {docs}")
        elif updated != text:
            problems.append(f"{docs}: the folder-graph section is stale; run "
                            "cmake/check-folder-graph.py --write-docs")

    if args.json:
        print(json.dumps({
            "units": sorted(graph.units),
            "edges": [{"from": a, "to": b, "evidence": w[:3]} for (a, b), w in sorted(graph.edges.items())],
            "problems": problems,
        }, indent=2))
    elif args.verbose:
        for (a, b), w in sorted(graph.edges.items()):
            print(f"{a} -> {b}: {w[0]}" + (f" (+{len(w) - 1} more)" if len(w) > 1 else ""))
    for p in problems:
        print("check-folder-graph: " + p, file=sys.stderr)
    if problems:
        print(f"check-folder-graph: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    for a, b in sorted(e for e in ALLOWED if e not in graph.edges):
        print(f"check-folder-graph: note: allow-listed edge {a} -> {b} no longer exists; remove it "
              "from ALLOWED")
    print(f"check-folder-graph: {len(graph.units)} units, {len(graph.edges)} edges, no cycle, "
          f"no reach into node/ or cli/ and no service-to-service edge outside the "
          f"{sum(e in graph.edges for e in ALLOWED)} allow-listed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
