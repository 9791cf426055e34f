"""Checks what `maturin build` and `maturin sdist` put in dist/: one wheel and one source
distribution of the workspace's version, the wheel abi3 and (on Linux) manylinux2014 with the
extension, its stubs, the `imukit` command and the licences; the sdist with every crate the build
needs, the lock file and the licences.

    python scripts/check_dist.py dist
"""
from __future__ import annotations

import re
import sys
import tarfile
import zipfile
from pathlib import Path


def fail(message: str) -> None:
    sys.exit(f"check_dist: {message}")


def workspace_version(root: Path) -> str:
    text = (root / "Cargo.toml").read_text()
    match = re.search(r'^\[workspace\.package\][^\[]*?^version = "([^"]+)"', text, re.M | re.S)
    if match is None:
        fail("no version in [workspace.package] of Cargo.toml")
    return match.group(1)


def check_wheel(wheel: Path, version: str) -> None:
    name = wheel.name
    if not name.startswith(f"imukit-{version}-") or "-abi3-" not in name:
        fail(f"{name}: expected imukit-{version}-cp39-abi3-<platform>.whl")
    if sys.platform.startswith("linux") and "manylinux2014" not in name:
        fail(f"{name}: not tagged manylinux2014 (built without --zig --compatibility manylinux2014?)")
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        info = f"imukit-{version}.dist-info"
        needed = [
            "_imukit_cli/__init__.py",
            "imukit/__init__.py",
            "imukit/__main__.py",
            "imukit/_core.pyi",
            "imukit/py.typed",
            f"{info}/licenses/LICENSE-MIT",
            f"{info}/licenses/LICENSE-APACHE",
            f"{info}/licenses/NOTICE.md",
        ]
        for member in needed:
            if member not in names:
                fail(f"{name}: {member} missing")
        if not any(re.fullmatch(r"imukit/_core\.(abi3\.so|pyd)", n) for n in names):
            fail(f"{name}: the extension module imukit/_core is missing")
        entry_points = z.read(f"{info}/entry_points.txt").decode()
        if not re.search(r"^imukit\s*=\s*_imukit_cli:main$", entry_points, re.M):
            fail(f"{name}: no console script `imukit = _imukit_cli:main` in entry_points.txt")
        metadata = z.read(f"{info}/METADATA").decode()
        for line in ("License-Expression: MIT OR Apache-2.0", f"Version: {version}",
                     "Provides-Extra: plot", "Provides-Extra: pandas", "Provides-Extra: test"):
            if line not in metadata.splitlines():
                fail(f"{name}: METADATA lacks `{line}`")


def check_sdist(sdist: Path, version: str) -> None:
    top = f"imukit-{version}"
    with tarfile.open(sdist) as t:
        names = set(t.getnames())
    needed = ["Cargo.toml", "Cargo.lock", "pyproject.toml", "LICENSE-MIT", "LICENSE-APACHE", "NOTICE.md",
              "crates/imu-core/src/lib.rs", "crates/imu-io/src/lib.rs", "crates/imukit/src/lib.rs", "crates/imu-plot/src/lib.rs",
              "crates/imu-cli/src/lib.rs", "crates/imu-py/src/lib.rs", "python/_imukit_cli/__init__.py",
              "python/imukit/__init__.py"]
    for member in needed:
        if f"{top}/{member}" not in names:
            fail(f"{sdist.name}: {member} missing")
    if f"{top}/crates/imukit/examples/study/tunnel.toml" not in names:
        fail(f"{sdist.name}: the examples (crates/imukit/examples, built into the library) are missing")
    if not any(n.startswith(f"{top}/crates/imu-io/presets/") for n in names):
        fail(f"{sdist.name}: the presets (crates/imu-io/presets) are missing")


def main() -> None:
    dist = Path(sys.argv[1] if len(sys.argv) > 1 else "dist")
    root = Path(__file__).resolve().parent.parent
    version = workspace_version(root)
    wheels = sorted(dist.glob("imukit-*.whl"))
    sdists = sorted(dist.glob("imukit-*.tar.gz"))
    if len(wheels) != 1 or len(sdists) != 1:
        fail(f"{dist}: expected one wheel and one sdist, found {[p.name for p in wheels + sdists]}")
    check_wheel(wheels[0], version)
    check_sdist(sdists[0], version)
    print(f"check_dist: {wheels[0].name} and {sdists[0].name} hold what a release needs")


if __name__ == "__main__":
    main()
