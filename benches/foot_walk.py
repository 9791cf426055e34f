#!/usr/bin/env python3
"""Foot-mounted navigation on x-io Technologies' public walks: the loop-closure error.

x-io's Gait-Tracking repository (github.com/xioTechnologies/Gait-Tracking, MIT licence) holds
two logs of an NGIMU on a foot at about 400 Hz, `short_walk.csv` (about 25 m) and
`long_walk.csv` (about 60 m); in both the subject walks a loop, so the foot ends where it
started. The dataset's metric is the final displacement of the foot; x-io's README gives its
own algorithm's: 82 mm and 421 mm. Each log is fused as a user would, with nothing but the
readings and their column map (`imukit fuse LOG --map ngimu.map.toml --zupt`): the part, the
stance detector's threshold and the start are learnt from the log.

    python benches/foot_walk.py --data Gait-Tracking [--write-readme benches/README.md]

`--data` is a local copy of the repository (or any folder holding the two CSV files).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import imukit

ROOT = Path(__file__).resolve().parents[1]
MAP = ROOT / "tests" / "data" / "gait" / "ngimu.map.toml"
# Distance walked and x-io's own final displacement, from its README.
WALKS = {"short_walk": (25.0, 0.082), "long_walk": (60.0, 0.421)}


def imukit_bin() -> str:
    return os.environ.get("IMUKIT_BIN", "imukit")


def closure(log: Path, workdir: Path) -> tuple[float, str]:
    """The foot's final horizontal displacement from its start, m, and what the run said."""
    out = workdir / f"{log.stem}_nav.csv"
    done = subprocess.run([imukit_bin(), "fuse", str(log), "--map", str(MAP), "--zupt", "--out", str(out)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return float("nan"), done.stderr.strip()
    nav = imukit.read(str(out))
    p = np.column_stack([nav["pos_x_m"], nav["pos_y_m"]])
    stances = next((line for line in done.stderr.splitlines() if "stances" in line), "")
    return float(np.linalg.norm(p[-1] - p[0])), stances


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="folder with short_walk.csv and long_walk.csv")
    parser.add_argument("--write-readme", type=Path, help="replace this page's foot_walk section")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, (distance, xio) in WALKS.items():
            error, said = closure(args.data / f"{name}.csv", Path(tmp))
            rows.append((name, distance, error, xio))
            print(f"{name}: {error:.3f} m ({100 * error / distance:.2f} % of {distance:.0f} m); "
                  f"x-io's algorithm {xio:.3f} m ({100 * xio / distance:.2f} %)\n  {said}")
    if args.write_readme:
        sys.path.insert(0, str(Path(__file__).parent))
        from readme_section import replace_section

        lines = ["## A foot on x-io's public walks", "",
                 "- data: x-io Technologies' Gait-Tracking logs (github.com/xioTechnologies/Gait-Tracking, "
                 "MIT), an NGIMU on a foot at about 400 Hz, walking a loop",
                 f"- versions: imukit {imukit.__version__}; Python {sys.version.split()[0]}",
                 "- command: `python benches/foot_walk.py --data Gait-Tracking --write-readme "
                 "benches/README.md` (a local copy of the repository)", "",
                 "`imukit fuse LOG --map ngimu.map.toml --zupt`, nothing else given; the final "
                 "horizontal displacement of the foot (the loop's start and end are one place). "
                 "x-io's figures are its README's, for its own algorithm.", "",
                 "| walk | distance | imukit | x-io's algorithm |", "|---|---|---|---|"]
        for name, distance, error, xio in rows:
            lines.append(f"| {name} | {distance:.0f} m | {error:.3f} m ({100 * error / distance:.2f} %) | "
                         f"{xio:.3f} m ({100 * xio / distance:.2f} %) |")
        replace_section(args.write_readme, "foot_walk", "\n".join(lines))


if __name__ == "__main__":
    main()
