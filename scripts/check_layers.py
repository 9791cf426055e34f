#!/usr/bin/env python3
"""Fails when a room of the library imports a room above its own.

The rooms of `crates/imukit/src` stand on each other in one order, `run` → `scenario` →
`motion`, all of them on `imu-io` (its own crate, below: Cargo refuses a cycle between crates,
so that arrow cannot turn). A room may name itself and the rooms below it, never one above. The
check lists every `crate::<room>` path of every file (imports and paths written inline) and
prints each one that points up with its file and line; with `--list`, it prints every room's
imports of the others.
"""
import re
import sys
from collections import Counter
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "crates" / "imukit" / "src"
# Bottom first; a room may use the rooms before it in this list.
ORDER = ["examples", "motion", "scenario", "run"]
PATH = re.compile(r"\bcrate::(\w+)\b")
GROUP = re.compile(r"\buse crate::\{([^;]*)\};", re.S)


def room_of(path: Path) -> str | None:
    first = path.relative_to(SRC).parts[0]
    name = first[:-3] if first.endswith(".rs") else first
    return name if name in ORDER else None


def main() -> int:
    up, seen = [], Counter()
    for path in sorted(SRC.rglob("*.rs")):
        room = room_of(path)
        if room is None:  # lib.rs: the crate's face, above every room
            continue
        text = path.read_text(encoding="utf-8")
        names = [(m.start(), m.group(1)) for m in PATH.finditer(text)]
        for g in GROUP.finditer(text):
            names += [(g.start(), n.strip().split("::")[0]) for n in g.group(1).split(",") if n.strip()]
        for at, target in names:
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
    if up:
        print(f"{len(up)} import(s) point up; the order is {' < '.join(ORDER)} (scripts/check_layers.py)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
