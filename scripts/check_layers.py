#!/usr/bin/env python3
"""Fails when a room of the library imports a room above its own.

The rooms of `crates/imukit/src` stand on each other in one order, `run` → `scenario` →
`motion`, all of them on `imu-io` (its own crate, below: Cargo refuses a cycle between crates,
so that arrow cannot turn). A room may name itself and the rooms below it, never one above. The
check lists every `crate::<room>` path of every file (imports and paths written inline) and
prints each one that points up with its file and line; with `--list`, it prints every room's
imports of the others.

It also fails on a circle between rooms in `imu-core` and `imu-io`, whose rooms have no fixed
order: a room (a top-level module) that imports, directly or through others, a room that
imports it. A circle inside one room is that room's business.

And it fails when a front end (the command line, Python's binding, the figures) reaches past the
library's face: every job is at the crate's root (`imukit::fuse`, not `imukit::run::fuse`), and
a front end names an item of a job's own module, never of a room inside a job
(`imukit::fuse::detect::…`); the rooms of data, `io` (its own crate, one room per format or
concept), `scenario` and `motion`, may be named one level down (`imukit::io::rows::TimeWindow`).
The core (`imukit::core`) is its own crate with its own rooms.
"""
import re
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "crates" / "imukit" / "src"
# The crates whose rooms must not import each other in a circle.
UNORDERED = [ROOT / "crates" / "imu-core" / "src", ROOT / "crates" / "imu-io" / "src"]
# The front ends, which use the library through its face.
FRONT_ENDS = [ROOT / "crates" / n / "src" for n in ("imu-cli", "imu-py", "imu-plot")]
# The library's rooms a front end may name one level down.
DATA_ROOMS = {"io": ROOT / "crates" / "imu-io" / "src", "scenario": SRC / "scenario", "motion": SRC / "motion"}
IMUKIT_PATH = re.compile(r"(?<![\w:])imukit((?:::\w+)+)")
IMUKIT_GROUP = re.compile(r"\buse imukit::\{([^;]*)\};", re.S)
# Bottom first; a room may use the rooms before it in this list.
ORDER = ["examples", "motion", "scenario", "run"]
PATH = re.compile(r"\bcrate::(\w+)\b")
GROUP = re.compile(r"\buse crate::\{([^;]*)\};", re.S)


def top_module(path: Path, src: Path) -> str:
    """The top-level module of `src` that the file at `path` belongs to."""
    first = path.relative_to(src).parts[0]
    return first[:-3] if first.endswith(".rs") else first


def room_of(path: Path) -> str | None:
    name = top_module(path, SRC)
    return name if name in ORDER else None


def crate_paths(text: str) -> list[tuple[int, str]]:
    """Every `crate::<room>` the text names (imports and paths written inline), with where."""
    names = [(m.start(), m.group(1)) for m in PATH.finditer(text)]
    for g in GROUP.finditer(text):
        names += [(g.start(), n.strip().split("::")[0]) for n in g.group(1).split(",") if n.strip()]
    return names


def room_imports(src: Path) -> dict[str, dict[str, str]]:
    """Each room of `src` (a top-level module) and the rooms it imports, each with a place."""
    rooms = {p.stem if p.suffix == ".rs" else p.name for p in src.iterdir()}
    edges: dict[str, dict[str, str]] = {}
    for path in sorted(src.rglob("*.rs")):
        room = top_module(path, src)
        text = path.read_text(encoding="utf-8")
        for at, target in crate_paths(text):
            start = text.rfind("\n", 0, at) + 1
            if text[start:at].lstrip().startswith("//") or target not in rooms or target == room:
                continue
            line = text.count("\n", 0, at) + 1
            edges.setdefault(room, {}).setdefault(target, f"{path.relative_to(ROOT)}:{line}")
    return edges


def circles(edges: dict[str, dict[str, str]]) -> list[list[str]]:
    """The rooms that import each other in a circle (strongly connected, more than one)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def is_module(folder: Path, name: str) -> bool:
    return (folder / f"{name}.rs").exists() or (folder / name / "mod.rs").exists()


def module_depth(segments: list[str]) -> tuple[int, str]:
    """How many modules deep below `imukit` a path's segments go, and through which first one."""
    first = segments[0]
    if first in DATA_ROOMS:
        folder, depth = DATA_ROOMS[first], 1
    elif is_module(SRC, first) or is_module(SRC / "run", first):
        folder, depth = (SRC / first if is_module(SRC, first) else SRC / "run" / first), 1
    else:
        return 0, first
    for name in segments[1:]:
        if not is_module(folder, name):
            break
        folder, depth = folder / name, depth + 1
    return depth, first


def past_the_face() -> list[str]:
    """Every path of a front end into the library that reaches past its face, with where."""
    found = []
    for src in FRONT_ENDS:
        for path in sorted(src.rglob("*.rs")):
            text = path.read_text(encoding="utf-8")
            spans = [(m.start(), m.group(1).strip(":").split("::")) for m in IMUKIT_PATH.finditer(text)]
            for g in IMUKIT_GROUP.finditer(text):
                spans += [(g.start(), n.strip().split("::")) for n in g.group(1).split(",") if n.strip()]
            for at, segments in spans:
                if not segments or not segments[0] or segments[0] == "core":
                    continue
                depth, first = module_depth(segments)
                allowed = 2 if first in DATA_ROOMS else 1
                if segments[0] == "run" or depth > allowed:
                    line = text.count("\n", 0, at) + 1
                    found.append(f"{path.relative_to(ROOT)}:{line}: imukit::{'::'.join(segments)} reaches past the library's face")
    return found


def main() -> int:
    up, seen = [], Counter()
    for path in sorted(SRC.rglob("*.rs")):
        room = room_of(path)
        if room is None:  # lib.rs: the crate's face, above every room
            continue
        text = path.read_text(encoding="utf-8")
        for at, target in crate_paths(text):
            if target not in ORDER or target == room:
                continue
            seen[(room, target)] += 1
            if ORDER.index(target) > ORDER.index(room):
                line = text.count("\n", 0, at) + 1
                up.append(f"{path.relative_to(SRC.parent.parent.parent)}:{line}: {room} imports {target}, a room above it")
    if "--list" in sys.argv:
        for (room, target), n in sorted(seen.items()):
            print(f"{room} -> {target}: {n}")
    for u in up:
        print(u)
    failed = bool(up)
    if up:
        print(f"{len(up)} import(s) point up; the order is {' < '.join(ORDER)} (scripts/check_layers.py)")
    deep = past_the_face()
    for d in deep:
        print(d)
    if deep:
        failed = True
        print(f"{len(deep)} path(s) of the front ends reach past the library's face (scripts/check_layers.py)")
    for src in UNORDERED:
        edges = room_imports(src)
        for group in circles(edges):
            failed = True
            print(f"{src.relative_to(ROOT)}: rooms {', '.join(group)} import each other in a circle:")
            for a in group:
                for b, place in sorted(edges.get(a, {}).items()):
                    if b in group:
                        print(f"  {place}: {a} imports {b}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
