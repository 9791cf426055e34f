"""One section of ``benches/README.md`` per benchmark script: each script replaces its own
section (between ``<!-- NAME -->`` and ``<!-- /NAME -->``) and leaves the others as they are."""
from __future__ import annotations

from pathlib import Path

HEADER = ("# Benchmarks\n\n"
          "Each section is written by the script it names; rerun that script to replace it. "
          "History is git's.\n")


def replace_section(path: Path, name: str, body: str) -> None:
    """Writes ``body`` as the section ``name`` of the page at ``path`` (created when missing),
    keeping every other section; the page is replaced atomically."""
    start, end = f"<!-- {name} -->", f"<!-- /{name} -->"
    text = path.read_text() if path.exists() else HEADER
    if not text.startswith(HEADER):
        text = HEADER  # an older page without sections: start over
    block = f"{start}\n{body.rstrip()}\n{end}\n"
    if start in text and end in text:
        before, rest = text.split(start, 1)
        after = rest.split(end, 1)[1].lstrip("\n")
        text = before + block + ("\n" + after if after else "")
    else:
        text = text.rstrip("\n") + "\n\n" + block
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)
