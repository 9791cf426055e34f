"""Every example in the README and the topic guides (docs/*.md) runs:

* ```sh blocks run in order, page by page, with bash (-e, -u, pipefail) in a fresh folder that
  holds the examples as `imukit example all` writes them, with `imukit` the command under test (IMUKIT_BIN);
* ```python blocks without prompts run in order in one namespace per page, in that folder; the
  blocks with `>>>` prompts are doctests (scripts/test.sh passes the pages to pytest's doctest);
* every Python example passes `mypy --strict` against the installed package;
* docs/cli-reference.md is what `python scripts/cli_reference.py` writes today;
* every relative link of a page points at a file that exists.

```text blocks are shown, not run (output, synopses, set-up that needs a network). The outage
studies (`imukit study examples/study/…`, over a minute each) are run by scripts/test.sh's
examples section and are left out here.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.M | re.S)
LEFT_TO_TEST_SH = re.compile(r"^imukit study examples/study/", re.M)

sys.path.insert(0, str(ROOT / "scripts"))
import cli_reference  # noqa: E402


def blocks(page: Path, language: str) -> list[str]:
    return [m.group(2) for m in FENCE.finditer(page.read_text(encoding="utf-8")) if m.group(1) == language]


def imukit_bin() -> str:
    from test_cli_vs_python import imukit_bin as find

    return find()


@pytest.fixture()
def workdir(tmp_path):
    # The examples come from the command under test (`imukit example all`), as a user without a
    # checkout gets them.
    subprocess.run([imukit_bin(), "--quiet", "example", "all", "--out-dir", str(tmp_path / "examples")],
                   check=True)
    bindir = tmp_path / "_bin"
    bindir.mkdir()
    (bindir / "imukit").symlink_to(imukit_bin())
    return tmp_path, bindir


def page_id(page: Path) -> str:
    return str(page.relative_to(ROOT))


@pytest.mark.parametrize("page", [p for p in PAGES if blocks(p, "sh")], ids=page_id)
def test_shell_examples_run(page, workdir):
    cwd, bindir = workdir
    script = "\n".join(LEFT_TO_TEST_SH.sub("# (run by scripts/test.sh) imukit study examples/study/", b)
                       for b in blocks(page, "sh"))
    env = {**os.environ, "PATH": f"{bindir}{os.pathsep}{os.environ['PATH']}", "MPLBACKEND": "Agg"}
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, f"{page.name}:\n{script}\n--- stderr ---\n{done.stderr[-3000:]}"


@pytest.mark.parametrize("page", [p for p in PAGES if blocks(p, "python")], ids=page_id)
def test_python_examples_run(page, workdir, monkeypatch):
    cwd, _ = workdir
    monkeypatch.chdir(cwd)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "__docs__"}
    for code in blocks(page, "python"):
        if ">>>" in code:
            continue  # a doctest, run by pytest's doctest collection
        exec(compile(code, f"{page.name} example", "exec"), namespace)  # noqa: S102


def as_script(code: str) -> str:
    """A block as plain Python: doctest prompts stripped, expected output dropped."""
    if ">>>" not in code:
        return code
    out = []
    for line in code.splitlines():
        if line.startswith(">>> ") or line == ">>>":
            out.append(line[4:])
        elif line.startswith("... ") or line == "...":
            out.append(line[4:])
    return "\n".join(out) + "\n"


def test_python_examples_pass_mypy_strict(tmp_path):
    pytest.importorskip("mypy")
    files = []
    for page in PAGES:
        code = "\n".join(as_script(b) for b in blocks(page, "python"))
        if code:
            # One file per page: its examples run in order in one namespace.
            f = tmp_path / f"{page.stem.replace('-', '_')}_examples.py"
            f.write_text(code, encoding="utf-8")
            files.append(f)
    assert files
    # Dask's Client is untyped; a call into it is not the examples' fault.
    done = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--ignore-missing-imports",
                           "--untyped-calls-exclude=distributed", "--no-error-summary", *map(str, files)],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_cli_reference_is_current():
    written = (ROOT / "docs" / "cli-reference.md").read_text(encoding="utf-8")
    assert written == cli_reference.reference(imukit_bin()), \
        "docs/cli-reference.md is stale: run python scripts/cli_reference.py"


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_relative_links_point_at_files(page):
    text = page.read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if re.match(r"[a-z]+:", target):
            continue
        assert (page.parent / target).exists(), f"{page.name}: link to {target} points nowhere"
