"""Writes docs/cli-reference.md from the `imukit` command's own --help, one section per command,
so the reference cannot drift from the program (tests/python/test_docs.py checks it is current):

    python scripts/cli_reference.py            # IMUKIT_BIN, else `imukit` on PATH
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TARGET = ROOT / "docs" / "cli-reference.md"


def imukit_bin() -> str:
    found = os.environ.get("IMUKIT_BIN") or shutil.which("imukit")
    if not found:
        sys.exit("cli_reference: set IMUKIT_BIN or put imukit on PATH")
    return found


def help_text(binary: str, *args: str) -> str:
    done = subprocess.run([binary, *args, "--help"], capture_output=True, text=True, check=True)
    return done.stdout.rstrip() + "\n"


def commands(top: str) -> list[str]:
    block = top.split("Commands:", 1)[1].split("\n\n", 1)[0]
    names = [m.group(1) for m in re.finditer(r"^  (\S+)\s", block, re.M)]
    return [n for n in names if n != "help"]


def reference(binary: str) -> str:
    top = help_text(binary)
    parts = [
        "# Command-line reference\n\n",
        "Written by `python scripts/cli_reference.py` from `imukit --help` and each command's\n",
        "`--help`; the tests check that it is current. The guide is [cli.md](cli.md).\n\n",
        "## imukit\n\n```text\n", top, "```\n",
    ]
    for name in commands(top):
        parts += [f"\n## imukit {name}\n\n```text\n", help_text(binary, name), "```\n"]
    return "".join(parts)


def main() -> None:
    TARGET.write_text(reference(imukit_bin()), encoding="utf-8")
    print(f"cli_reference: wrote {TARGET.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
