#!/usr/bin/env python3
"""BROAD: imukit's orientation filters beside VQF, x-io Fusion (imufusion) and ahrs on the
Berlin Robust Orientation Estimation Assessment Dataset, scored with the dataset's own metric.

The data: D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust Inertial
Orientation Estimation", Data 6(7):72, 2021; https://github.com/dlaidig/broad (CC BY 4.0): 39
trials of a myon aktos-t IMU at 285.7 Hz beside an optical reference (Optitrack), as
``data_hdf5/*.hdf5`` or ``data_mat/*.mat``. Give the folder that holds them (either format, or
both mixed); the trials found are scored, and the table says how many.

The metric (BROAD's ``broad_utils.py``): the error quaternion in the Earth frame,
``q_imu ⊗ q_ref⁻¹``; its total angle, its heading part (about the vertical) and its inclination
part; the RMS of each over the samples the trial marks as motion, samples without a reference
(NaN) dropped. In 6D (no magnetometer) the heading is arbitrary: one constant heading offset per
trial — the circular mean of the heading error over the motion — is removed first. Each figure is
the mean over trials (and over the trials of a group).

Every filter runs with its defaults. The peers run when installed: ``pip install vqf imufusion
ahrs h5py``.

    python benches/broad/broad.py --data /path/to/broad --write-readme benches/README.md
"""
from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

# Rotation taking North-West-Up coordinates to East-North-Up: +90° about the vertical.
NWU_TO_ENU = np.array([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)])


def load_trial(path: Path) -> dict:
    """One trial's readings, reference, motion mask and rate, from BROAD's HDF5 or MAT file."""
    if path.suffix == ".hdf5":
        import h5py

        with h5py.File(path, "r") as f:
            d = {k: np.array(f[k]) for k in ("imu_acc", "imu_gyr", "imu_mag", "opt_quat", "movement")}
            d["rate"] = float(f.attrs["sampling_rate"])
    else:
        import scipy.io

        m = scipy.io.loadmat(path)
        d = {k: np.ascontiguousarray(m[k], dtype=float) for k in ("imu_acc", "imu_gyr", "imu_mag", "opt_quat")}
        d["movement"] = m["movement"].ravel().astype(bool)
        d["rate"] = float(np.squeeze(m["sampling_rate"]))
    for k in ("imu_acc", "imu_gyr", "imu_mag"):
        d[k] = np.ascontiguousarray(d[k], dtype=float)
    d["movement"] = d["movement"].astype(bool).ravel()
    return d


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise Hamilton product of [w, x, y, z] quaternions (either may be one quaternion)."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    w1, x1, y1, z1 = a.T
    w2, x2, y2, z2 = b.T
    return np.stack([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2], axis=1)


def conj(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def errors(q_est: np.ndarray, q_ref: np.ndarray, motion: np.ndarray, align_heading: bool) -> dict:
    """BROAD's total, heading and inclination RMSE (degrees) over the motion samples."""
    q_est = q_est / np.linalg.norm(q_est, axis=1)[:, None]
    q_ref = q_ref / np.linalg.norm(q_ref, axis=1)[:, None]
    e = qmul(q_est, conj(q_ref))
    if align_heading:
        h = 2.0 * np.arctan2(e[:, 3], e[:, 0])
        ok = motion & np.isfinite(h)
        offset = np.arctan2(np.mean(np.sin(h[ok])), np.mean(np.cos(h[ok])))
        e = qmul(np.array([np.cos(offset / 2), 0.0, 0.0, -np.sin(offset / 2)]), e)
    e = e / np.linalg.norm(e, axis=1)[:, None]
    total = 2.0 * np.arccos(np.clip(np.abs(e[:, 0]), 0.0, 1.0))
    heading = 2.0 * np.arctan(np.abs(e[:, 3] / e[:, 0]))
    incl = 2.0 * np.arccos(np.clip(np.sqrt(e[:, 0] ** 2 + e[:, 3] ** 2), 0.0, 1.0))
    rms = lambda x: float(np.degrees(np.sqrt(np.nanmean(x[motion] ** 2))))  # noqa: E731
    return {"total": rms(total), "heading": rms(heading), "inclination": rms(incl)}


# ---- the filters: each returns q (N, 4), body to ENU, for readings (N, 3) at `rate` ----

def imukit_filter(kind: str):
    def run(d: dict, mag: bool) -> np.ndarray:
        import imukit

        if kind == "robust":
            f = imukit.RobustFilter(sample_rate=d["rate"], has_magnetometer=mag, settings=d["settings"])
        else:
            f = imukit.MadgwickFilter(sample_rate=d["rate"], has_magnetometer=mag)
        return f(d["imu_acc"], d["imu_gyr"], d["imu_mag"] if mag else None)
    return run


def imukit_smoothed(d: dict, mag: bool) -> np.ndarray:
    import imukit

    f = imukit.RobustFilter(sample_rate=d["rate"], has_magnetometer=mag, settings=d["settings"], smooth=True)
    return f(d["imu_acc"], d["imu_gyr"], d["imu_mag"] if mag else None)


def vqf_causal(d: dict, mag: bool) -> np.ndarray:
    from vqf import VQF

    f = VQF(1.0 / d["rate"])
    out = f.updateBatch(d["imu_gyr"], d["imu_acc"], d["imu_mag"] if mag else None)
    return out["quat9D" if mag else "quat6D"]


def vqf_offline(d: dict, mag: bool) -> np.ndarray:
    from vqf import offlineVQF

    out = offlineVQF(d["imu_gyr"], d["imu_acc"], d["imu_mag"] if mag else None, 1.0 / d["rate"])
    return out["quat9D" if mag else "quat6D"]


def imufusion_ahrs(d: dict, mag: bool) -> np.ndarray:
    import imufusion

    ahrs = imufusion.Ahrs()
    ahrs.set_settings(imufusion.AhrsSettings(sample_rate=d["rate"]))  # North-West-Up, its default
    ahrs.set_sample_period(1.0 / d["rate"])
    gyr = np.degrees(d["imu_gyr"])
    acc = d["imu_acc"] / 9.80665
    q = np.empty((len(gyr), 4))
    for i in range(len(gyr)):
        if mag:
            ahrs.update(gyr[i], acc[i], d["imu_mag"][i])
        else:
            ahrs.update_no_magnetometer(gyr[i], acc[i])
        q[i] = ahrs.get_quaternion()
    return qmul(NWU_TO_ENU, q)


def ahrs_madgwick(d: dict, mag: bool) -> np.ndarray:
    from ahrs.filters import Madgwick

    f = Madgwick(gyr=d["imu_gyr"], acc=d["imu_acc"], mag=d["imu_mag"] if mag else None, frequency=d["rate"])
    return qmul(NWU_TO_ENU, f.Q)


FILTERS = {
    "imukit robust (default)": ("imukit", imukit_filter("robust")),
    "imukit robust --smooth": ("imukit", imukit_smoothed),
    "imukit madgwick": ("imukit", imukit_filter("madgwick")),
    "VQF (causal)": ("vqf", vqf_causal),
    "VQF offline": ("vqf", vqf_offline),
    "x-io Fusion (imufusion)": ("imufusion", imufusion_ahrs),
    "ahrs Madgwick": ("ahrs", ahrs_madgwick),
}


def available(names: list[str]) -> dict:
    import importlib.util

    out = {}
    for name in names:
        module, fn = FILTERS[name]
        if importlib.util.find_spec(module) is None:
            print(f"skipped {name}: `{module}` is not installed", file=sys.stderr)
            continue
        if fn is imukit_smoothed:
            import imukit
            import inspect

            if "smooth" not in inspect.signature(imukit.RobustFilter).parameters:
                print(f"skipped {name}: this imukit has no smoothing", file=sys.stderr)
                continue
        out[name] = fn
    return out


def score_trial(args) -> tuple[str, dict]:
    path, names, settings = args
    d = load_trial(Path(path))
    d["settings"] = settings
    result = {}
    for name in names:
        fn = FILTERS[name][1]
        for mag in (False, True):
            t0 = time.perf_counter()
            q = fn(d, mag)
            result[(name, "9D" if mag else "6D")] = errors(q, d["opt_quat"], d["movement"], align_heading=not mag)
            result[(name, "9D" if mag else "6D")]["seconds"] = time.perf_counter() - t0
    return Path(path).stem, result


def trials_in(folder: Path) -> list[Path]:
    found = {}
    for p in sorted(folder.glob("*.hdf5")) + sorted(folder.glob("*.mat")):
        if p.stem[:2].isdigit():
            found.setdefault(p.stem, p)
    return [found[k] for k in sorted(found)]


def groups_of(folder: Path, trials: list[str]) -> dict:
    """BROAD's groups (from its trials.json when present, else from the trial names)."""
    info = folder / "trials.json"
    if info.exists():
        meta = json.loads(info.read_text())
        return {g["name"]: [t for t in trials if g["name"] in meta["trials"].get(t, {}).get("groups", [])]
                for g in meta["groups"]}
    return {}


def table(results: dict, names: list[str], trials: list[str], groups: dict) -> list[str]:
    lines = [f"{len(trials)} BROAD trials; RMSE in degrees over the motion phases, mean over trials "
             "(6D: one constant heading offset per trial removed)", ""]
    peer = "VQF (causal)" if "VQF (causal)" in names else None
    lines.append("| filter | 6D total | 6D heading | 6D inclination | 9D total | 9D heading | 9D inclination "
                 "| worst 6D / 9D trial |" + (" trials > VQF + 2° (6D / 9D) |" if peer else ""))
    lines.append("|---|---|---|---|---|---|---|---|" + ("---|" if peer else ""))
    for name in names:
        row = [name]
        worst = []
        for dim in ("6D", "9D"):
            for k in ("total", "heading", "inclination"):
                row.append(f"{np.mean([results[t][(name, dim)][k] for t in trials]):.3f}")
            worst.append(f"{max(results[t][(name, dim)]['total'] for t in trials):.2f}")
        row.append(" / ".join(worst))
        if peer:
            row.append(" / ".join(
                str(sum(results[t][(name, dim)]["total"] > results[t][(peer, dim)]["total"] + 2.0 for t in trials))
                for dim in ("6D", "9D")))
        lines.append("| " + " | ".join(row) + " |")
    if groups:
        lines += ["", "Total RMSE by BROAD group (6D / 9D), degrees:", ""]
        present = {g: ts for g, ts in groups.items() if ts}
        lines.append("| filter | " + " | ".join(f"{g} ({len(ts)})" for g, ts in present.items()) + " |")
        lines.append("|---|" + "---|" * len(present))
        for name in names:
            cells = []
            for ts in present.values():
                a = np.mean([results[t][(name, "6D")]["total"] for t in ts])
                b = np.mean([results[t][(name, "9D")]["total"] for t in ts])
                cells.append(f"{a:.2f} / {b:.2f}")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def core_speed(d: dict) -> tuple[dict, str] | None:
    """Both cores in native loops on the trial's readings: imukit's `orientation_speed` example
    (built with cargo) and VQF's C++ core (`vqf_speed.cpp`, built with g++ against the vqf
    package's own sources). None when a tool or the sources are missing."""
    import shutil
    import subprocess
    import tempfile

    try:
        import vqf
    except ImportError:
        return None
    cpp = Path(vqf.__file__).parent / "cpp"
    if not (cpp / "vqf.cpp").exists() or not shutil.which("g++") or not shutil.which("cargo"):
        return None
    root = Path(__file__).resolve().parents[2]
    with tempfile.TemporaryDirectory() as tmp:
        rows = Path(tmp) / "rows.bin"
        np.hstack([d["imu_acc"], d["imu_gyr"], d["imu_mag"]]).astype("<f8").tofile(rows)
        exe = Path(tmp) / "vqf_speed"
        subprocess.run(["g++", "-O2", "-std=c++17", f"-I{cpp}", "-o", str(exe),
                        str(Path(__file__).parent / "vqf_speed.cpp"), str(cpp / "vqf.cpp")], check=True)
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "imu-benches", "--example",
                        "orientation_speed"], check=True, cwd=root)
        ours = root / "target" / "release" / "examples" / "orientation_speed"
        out = {}
        for name, cmd in (("imukit", [str(ours)]), ("VQF", [str(exe)])):
            text = subprocess.run(cmd + [str(rows), repr(d["rate"]), "20"], check=True, capture_output=True,
                                  text=True).stdout
            out[name] = dict(line.split() for line in text.splitlines())
    version = subprocess.run(["g++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    return out, version


def speed(paths: list[Path]) -> list[str]:
    """Per-sample update time of imukit's default filter and of VQF's C++ core: each core in a
    native loop over one whole trial (best of 20), and each through its Python package's batch
    call (best of 5), 6D and 9D."""
    import imukit

    d = load_trial(paths[0])
    n = len(d["imu_gyr"])
    batch = {}
    for mag in (False, True):
        def ours():
            f = imukit.RobustFilter(sample_rate=d["rate"], has_magnetometer=mag)
            f(d["imu_acc"], d["imu_gyr"], d["imu_mag"] if mag else None)

        def theirs():
            from vqf import VQF

            VQF(1.0 / d["rate"]).updateBatch(d["imu_gyr"], d["imu_acc"], d["imu_mag"] if mag else None)

        cells = []
        for fn in (ours, theirs):
            best = float("inf")
            for _ in range(5):
                t0 = time.perf_counter()
                fn()
                best = min(best, time.perf_counter() - t0)
            cells.append(best / n * 1e9)
        batch["9D" if mag else "6D"] = cells
    core = core_speed(d)
    lines = [f"Per-sample update time, ns ({n} samples of {paths[0].stem}, each sample one update; the same "
             "machine, one core):", ""]
    if core:
        (times, compiler) = core
        lines.append(f"- core: each filter's own loop over the trial, best of 20 (imukit: `cargo build --release`; "
                     f"VQF: its C++ core from the vqf package's sources, `g++ -O2`, {compiler})")
    lines.append("- Python: each package's batch call on the whole trial, best of 5 (imukit's returns its flags "
                 "and bias too)")
    lines += ["", "| | imukit robust, core | VQF 2.1.2, core (C++) | imukit robust, Python | VQF 2.1.2, Python |",
              "|---|---|---|---|---|"]
    for dim in ("6D", "9D"):
        c = [f"{float(core[0][k][dim]):.0f}" for k in ("imukit", "VQF")] if core else ["–", "–"]
        lines.append(f"| {dim} | {c[0]} | {c[1]} | {batch[dim][0]:.0f} | {batch[dim][1]:.0f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True,
                        help="folder with BROAD's trial files (*.hdf5 and/or *.mat, and trials.json)")
    parser.add_argument("--filters", nargs="+", default=list(FILTERS), choices=list(FILTERS), metavar="NAME")
    parser.add_argument("--trials", nargs="+", help="only these trials (name prefixes, e.g. 15 16)")
    parser.add_argument("--jobs", type=int, default=len(__import__("os").sched_getaffinity(0)))
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                        help="settings of imukit's robust filter (as `imukit orient --param` takes them)")
    parser.add_argument("--speed", action="store_true",
                        help="also time the default filter beside VQF's C++ core (per-sample update)")
    parser.add_argument("--per-trial", action="store_true", help="also print each trial's 6D/9D total RMSE")
    parser.add_argument("--write-readme", type=Path, metavar="PATH",
                        help="also write the table as the BROAD section of PATH (benches/README.md)")
    args = parser.parse_args()

    paths = trials_in(args.data)
    if args.trials:
        paths = [p for p in paths if any(p.stem.startswith(t) for t in args.trials)]
    if not paths:
        sys.exit(f"no BROAD trial files (NN_*.hdf5 or NN_*.mat) in {args.data}")
    settings = {}
    for kv in args.set:
        key, _, value = kv.partition("=")
        settings[key] = float(value)
    fns = available(args.filters)
    names = list(fns)
    with multiprocessing.Pool(args.jobs) as pool:
        results = dict(pool.map(score_trial, [(str(p), names, settings) for p in paths], chunksize=1))
    trials = [p.stem for p in paths]
    if args.per_trial:
        for t in trials:
            print(t, "  ".join(f"{n}: {results[t][(n, '6D')]['total']:.2f}/{results[t][(n, '9D')]['total']:.2f}"
                               for n in names))
    lines = table(results, names, trials, groups_of(args.data, trials))
    if args.speed:
        lines += [""] + speed(paths)
    print("\n".join(lines))
    if args.write_readme:
        from readme_section import replace_section

        import platform

        versions = []
        for module in ("imukit", "vqf", "imufusion", "ahrs"):
            try:
                versions.append(f"{module} {__import__('importlib.metadata').metadata.version(module)}")
            except Exception:  # noqa: BLE001 - a peer that is not installed
                pass
        body = ("## Orientation on BROAD\n\n"
                f"- data: BROAD (Laidig et al., Data 2021, CC BY 4.0), {len(trials)} of its 39 trials\n"
                f"- versions: {', '.join(versions)}; Python {platform.python_version()}\n"
                f"- command: `python benches/broad/broad.py --data BROAD{' --speed' if args.speed else ''} "
                f"--write-readme {args.write_readme}` (BROAD: a local copy of its data_hdf5 or data_mat folder)\n\n"
                + "\n".join(lines) + "\n")
        replace_section(args.write_readme, "broad", body)


if __name__ == "__main__":
    main()
