"""Hostile input against the command line and the Python API: seeded random and adversarial
cases per class, each checked for what must never happen.

Never: a panic (exit 101), a signal or abort (negative exit, 134), a hang (a case over its time
bound), a leftover ``*.imukit-partial`` file, an input changed, a non-finite number in an output
written with exit 0, or — from Python — an exception other than ``ImuError``, ``ValueError`` or
``TypeError``. A refusal (exit 65/74/2, ``ImuError``) is a pass: the point is that the program
says no cleanly.

    python tests/fuzz/hostile.py                     # the short seeded run CI does (~400 cases)
    python tests/fuzz/hostile.py --cases 5000 --seed 7   # a long run; any seed reproduces itself
    python tests/fuzz/hostile.py --cases 10 --process-cases 2000   # signals and two writers, long

Classes: byte mutations of valid scenario, CSV and parameter files; generated formulas (deep,
long, extreme numbers); extreme numeric options; scenarios and navigation on the WGS-84 Earth
(extreme origins, geodetic formulas, dates, vertical channels); mutated and truncated Parquet,
``.npy`` and ``.npz`` tables and ROS 2 bags (``.mcap``) fed to the commands that read tables; NMEA logs (checksums
wrong, or right over damaged sentences) and Kalibr files fed to ``fuse``; crafted binary tables (archives whose members
lie about their sizes, repeat, fail their CRC or expand like bombs, ``.npy`` headers against their files, Parquet
footers damaged field by field, a column twice); barometer and odometer files fed to ``integrate`` and ``fuse``;
output paths that collide with inputs, special files and folders; crafted bags whose lengths declare gigabytes
(MCAP strings and maps, ROS 1 chunks, under a 3 GiB address space), a ``.db3`` whose messages are an endless SQL
view, NMEA fields ``nan``/``inf``/``1e308``, a link planted inside an output folder, outputs named ``.xlsx``,
``.mat``, ``.db3``…; time windows at extreme values, shipped examples written into a folder
with a link or a file planted in it, hostile bag topic and frame names and start stamps, track
waits at extreme values; real signals (SIGINT, SIGTERM, SIGHUP) sent to
a command at a random moment of its run; two processes writing one output name at once; Python calls with NaN,
inf, huge and misshapen arguments, empty tables, and tables written under hostile column names. Prints one line
per class and a closing ``N passed, M failed`` line; exits 1 on any failure.
"""
from __future__ import annotations

import argparse
import hashlib
import io
import signal
import struct
import time
import zipfile
import zlib
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TIME_LIMIT_S = 30.0
ALLOWED_EXITS = {0, 2, 65, 74}
SIGNAL_EXITS = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129}

CALIBRATION = """[accelerometer]
matrix = [[1.01, 0.002, -0.001], [0, 0.99, 0.003], [0, 0, 1.002]]
bias_m_s2 = [0.05, -0.02, 0.1]
[gyroscope]
matrix = [[1.0, 0.01, 0], [0.002, 1.0, 0], [0, 0, 1.0]]
bias_rad_s = [0.001, 0, -0.002]
"""

SCENARIO = """rate_hz = 100.0
duration_s = 0.5
nav_frame = "ENU"
[trajectory]
type = "expression"
constants = { f = 1.0 }
position_m = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
attitude = "tangent"
[imu]
kind = "accel-gyro-mag"
lever_arm_m = [-0.075, -0.075, 0.025]
seed = 3
[imu.gyroscope]
NoiseDensity = 1e-4
"""

PARAMS = json.dumps({"Part": {"Gyroscope": {"NoiseDensity": 0.001, "MeasurementRange": "inf"},
                              "Accelerometer": {"ConstantBias": [0.1, 0.2, 0.3]}}})

EXTREMES = ["nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-1", "1e9", "-0", "3", "0.5"]


def imukit_bin() -> str:
    explicit = os.environ.get("IMUKIT_BIN")
    if explicit:
        return explicit
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "imukit"
        if p.exists():
            return str(p)
    sys.exit("the imukit binary was not found: build it (cargo build --release -p imu-cli) or set IMUKIT_BIN")


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "absent"


class Run:
    """The checks of one case and the tally of a class."""

    def __init__(self, name: str) -> None:
        self.name, self.passed, self.failures = name, 0, []

    def fail(self, case: str, why: str) -> None:
        self.failures.append(f"{self.name}: {case}: {why}")


def run_cli(run: Run, work: Path, args: list, inputs: list, case: str, memory_gb: float = 0) -> None:
    """Runs one command in `work` and checks it against every rule; `memory_gb` caps its address
    space (an allocation beyond it aborts the process: a failure)."""
    before = {p: digest(work / p) for p in inputs}

    def limit() -> None:
        import resource
        cap = int(memory_gb * (1 << 30))
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    try:
        out = subprocess.run([imukit_bin(), *args], cwd=work, capture_output=True, timeout=TIME_LIMIT_S,
                             preexec_fn=limit if memory_gb else None)
    except subprocess.TimeoutExpired:
        run.fail(case, f"no answer within {TIME_LIMIT_S} s: {args}")
        return
    code = out.returncode
    problems = []
    if code not in ALLOWED_EXITS:
        problems.append(f"exit {code}: {out.stderr.decode(errors='replace')[-300:]}")
    if b"panicked" in out.stderr:
        problems.append("a panic message")
    left = [p.name for p in work.iterdir() if p.name.endswith(".imukit-partial")]
    if left:
        problems.append(f"partial files left: {left}")
    for p, d in before.items():
        if digest(work / p) != d:
            problems.append(f"input {p} changed")
    if code == 0:
        for p in work.iterdir():
            if p.name in inputs or not p.is_file():
                continue
            if p.suffix == ".csv":
                # The table, after its description line (whose sensor may say `inf`: no limit).
                text = "\n".join(l for l in p.read_text(errors="replace").lower().splitlines()
                                  if not l.startswith("#"))
                if "nan" in text.replace("nan_", "") or "inf" in text:
                    problems.append(f"non-finite value written to {p.name}")
                p.unlink()
            elif p.suffix in (".npy", ".npz", ".parquet") and p.name.startswith("o"):
                bad = non_finite_binary(p)
                if bad:
                    problems.append(f"{bad} written to {p.name}")
                p.unlink()
    if problems:
        run.fail(case, "; ".join(problems) + f" [{' '.join(args)}]")
    else:
        run.passed += 1


def non_finite_binary(path: Path) -> str:
    """'' when every value of a binary table imukit wrote is finite (or the readers are absent)."""
    try:
        import numpy as np
    except ImportError:
        return ""
    try:
        if path.suffix == ".npy":
            a = np.load(path)
            arrays = [a[n] for n in a.dtype.names or []]
        elif path.suffix == ".npz":
            with np.load(path) as z:
                arrays = [z[k] for k in z.files]
        else:
            try:
                import pyarrow.parquet as pq
            except ImportError:
                return ""
            arrays = [c.to_numpy() for c in pq.read_table(path).columns]
    except Exception as e:  # noqa: BLE001 - a file imukit wrote that NumPy cannot read
        return f"an unreadable table ({type(e).__name__}: {e})"
    return "a non-finite value" if any(not np.all(np.isfinite(a)) for a in arrays) else ""


def npy_bytes(values, shape=None, descr="'<f8'") -> bytes:
    """An .npy file of float64 `values` whose header may say another `shape` or `descr`."""
    shape = (len(values),) if shape is None else shape
    text = f"{{'descr': {descr}, 'fortran_order': False, 'shape': {shape!r}, }}".encode()
    text += b" " * (-(10 + len(text) + 1) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(text)) + text + struct.pack(f"<{len(values)}d", *values)


def zip_bytes(members, sizes=None, crcs=None, method=zipfile.ZIP_STORED) -> bytes:
    """A zip archive of `members` (name, bytes) whose directory may lie: `sizes[k]` and
    `crcs[k]` replace member k's declared size (zip64 when large) and CRC-32."""
    out, central = io.BytesIO(), io.BytesIO()
    for k, (name, data) in enumerate(members):
        stored = data
        if method == zipfile.ZIP_DEFLATED:
            c = zlib.compressobj(9, zlib.DEFLATED, -15)
            stored = c.compress(data) + c.flush()
        size = (sizes or {}).get(k, len(data))
        crc = (crcs or {}).get(k, zlib.crc32(data))
        wide = size >= 0xFFFFFFFF or len(stored) >= 0xFFFFFFFF
        extra = struct.pack("<HHQQ", 1, 16, size, len(stored)) if wide else b""
        short, cshort = (0xFFFFFFFF, 0xFFFFFFFF) if wide else (size, len(stored))
        offset = out.tell()
        out.write(struct.pack("<IHHHHHIIIHH", 0x04034B50, 45, 0, method, 0, 0, crc, cshort, short, len(name), len(extra)))
        out.write(name.encode() + extra + stored)
        central.write(struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 45, 45, 0, method, 0, 0, crc, cshort, short,
                                  len(name), len(extra), 0, 0, 0, 0, offset))
        central.write(name.encode() + extra)
    start, body = out.tell(), central.getvalue()
    out.write(body)
    out.write(struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(members), len(members), len(body), start, 0))
    return out.getvalue()


def crafted_table(rng: random.Random, fmt: str, good: bytes) -> bytes:
    """A binary table crafted to lie in one of the ways a reader must catch."""
    n = rng.choice([0, 1, 5, 100])
    t = [k / 100 for k in range(n)]
    x = [rng.uniform(-5, 5) for _ in range(n)]
    if fmt == "npy":
        kind = rng.randrange(4)
        rec = "[('t_s', '<f8'), ('accel_x_m_s2', '<f8')]"
        values = [v for pair in zip(t, x) for v in pair]
        if kind == 0:  # a shape that the file does not hold
            return npy_bytes(values, shape=(rng.choice([2**62, 2**31, n + 1, 0]),), descr=rec)
        if kind == 1:  # a shape of two dimensions, or another type
            return npy_bytes(values, shape=rng.choice([(n, 2), (2, n)]), descr=rng.choice([rec, "'<f4'", "'|O'"]))
        if kind == 2:  # a header length beyond what NumPy reads
            return b"\x93NUMPY\x02\x00" + struct.pack("<I", rng.choice([2**32 - 1, 10_001, 70_000])) + b"{" * 64
        return npy_bytes(values, descr="[" + ", ".join(["('t_s', '<f8')"] * 2) + "]")  # a field twice
    if fmt == "npz":
        members = [("t_s.npy", npy_bytes(t)), ("accel_x_m_s2.npy", npy_bytes(x))]
        kind = rng.randrange(6)
        if kind == 0:
            return zip_bytes(members, sizes={1: rng.choice([2**62, 2**40, 2**32 + 5])})
        if kind == 1:
            return zip_bytes(members + [("t_s.npy", npy_bytes(x))])
        if kind == 2:
            return zip_bytes(members, crcs={rng.randrange(2): rng.randrange(2**32)})
        if kind == 3:  # a bomb: zeros deflated
            big = npy_bytes([0.0] * rng.choice([1 << 20, 10 << 20]))
            return zip_bytes([("t_s.npy", big), ("accel_x_m_s2.npy", big)], method=zipfile.ZIP_DEFLATED)
        if kind == 4:  # columns of different lengths, or a member that is not an array
            return zip_bytes([("t_s.npy", npy_bytes(t + [1.0])), rng.choice(members[1:] + [("x.txt", b"x")])])
        return zip_bytes(members, sizes={0: max(0, len(members[0][1]) - rng.randrange(1, 64))})
    # Parquet: the footer's bytes damaged (the metadata a reader trusts), or its length.
    data = bytearray(good)
    footer = struct.unpack("<I", data[-8:-4])[0]
    start = max(4, len(data) - 8 - footer)
    if rng.random() < 0.2:
        struct.pack_into("<I", data, len(data) - 8, rng.choice([0, 1, footer + 1, 2**31, 2**32 - 1]))
    else:
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(start, len(data) - 8)
            data[i] = rng.choice([0, 0xFF, 0x7F, 0x80, data[i] ^ (1 << rng.randrange(8)), rng.randrange(256)])
    return bytes(data)


def mutate(rng: random.Random, data: bytes) -> bytes:
    """One of: flip bytes, cut, duplicate a slice, insert extreme text, swap lines."""
    b = bytearray(data)
    kind = rng.randrange(5)
    if kind == 0 and b:
        for _ in range(rng.randint(1, 8)):
            b[rng.randrange(len(b))] = rng.randrange(256)
    elif kind == 1 and b:
        b = b[: rng.randrange(len(b))]
    elif kind == 2 and b:
        i, j = sorted(rng.randrange(len(b)) for _ in range(2))
        b[i:i] = b[i:j] * rng.randint(1, 50)
    elif kind == 3:
        i = rng.randrange(len(b) + 1)
        b[i:i] = rng.choice(EXTREMES + ["(" * 500, ",,,", '"', "\n\n", "t_s", "\x00"]).encode()
    else:
        lines = bytes(b).split(b"\n")
        rng.shuffle(lines)
        b = bytearray(b"\n".join(lines))
    return bytes(b)


def formula(rng: random.Random, depth: int = 0, limit: int = 0) -> str:
    """A random formula: mostly legal, sometimes deep (nested to `limit`), long or extreme."""
    limit = limit or rng.choice([3, 8, 30, 63, 64, 65, 120])
    if depth == 0 and rng.random() < 0.15:  # a long flat sum or product
        return rng.choice(["+", "*", "-"]).join([rng.choice(["t", "1e308", "pi"])] * rng.choice([10, 999, 1000, 1001, 40000]))
    if depth >= limit or (depth > 2 and rng.random() < 0.3):
        return rng.choice(["t", "pi", "e", "f", "1", "2.5", "1e308", "1e-308", "0"])
    inner = formula(rng, depth + 1, limit)
    op = rng.randrange(5)
    if op == 0:
        return f"({inner})"
    if op == 1:
        return f"-{inner}"
    if op == 2:
        return f"{rng.choice(['sin', 'cos', 'exp', 'sqrt', 'ln', 'abs', 'tan', 'asin'])}({inner})"
    if op == 3:
        return f"{inner}{rng.choice(['+', '-', '*', '/', '^'])}{rng.choice(['t', '2', '1e308', '0'])}"
    return f"if(t < {rng.choice(EXTREMES[3:])}, {inner}, {rng.choice(['t', '0', '1e308'])})"


def cli_cases(rng: random.Random, cases: int, process_cases: int = 0) -> list:
    runs = []
    work = Path(tempfile.mkdtemp(prefix="imukit-hostile-"))
    try:
        (work / "s.toml").write_text(SCENARIO)
        subprocess.run([imukit_bin(), "simulate", "s.toml", "--out", "imu.csv", "--truth", "truth.csv"],
                       cwd=work, check=True, capture_output=True)
        subprocess.run([imukit_bin(), "allan", "imu.csv", "--out", "allan.csv"], cwd=work, check=True, capture_output=True)
        (work / "p.json").write_text(PARAMS)
        (work / "cal.toml").write_text(CALIBRATION)
        valid = {name: (work / name).read_bytes()
                 for name in ("s.toml", "imu.csv", "truth.csv", "p.json", "allan.csv", "cal.toml")}
        per = max(1, cases // 7)
        # The classes that run a process for a second or so: a quarter of the others' cases.
        slow = process_cases or max(1, per // 4)

        r = Run("byte mutations of valid files")
        for k in range(per):
            name = rng.choice(list(valid))
            bad = work / f"m{k}{Path(name).suffix}"
            bad.write_bytes(mutate(rng, valid[name]))
            args = {
                "s.toml": ["simulate", bad.name, "--out", "o.csv"],
                "imu.csv": rng.choice([["integrate", bad.name, "--out", "o.csv"],
                                       ["orient", bad.name, "--out", "o.csv"],
                                       ["orient", bad.name, "--smooth", "--out", "o.csv"],
                                       ["allan", bad.name, "--out", "o.csv"],
                                       ["calibrate", bad.name, "--out", "o.toml"],
                                       ["spectrum", bad.name, "--out", "o.csv", "--plot", "o.svg"],
                                       ["plot", bad.name, "--out", "o.svg"]]),
                "truth.csv": rng.choice([["compare", bad.name, "truth.csv"], ["plot", bad.name, "--out", "o.svg"],
                                         ["compare", bad.name, "truth.csv", "--align-heading"],
                                         ["animate", bad.name, "--out", "o.html"]]),
                "p.json": ["simulate", "ps.toml", "--out", "o.csv"],
                "allan.csv": ["plot", bad.name, "--out", rng.choice(["o.svg", "o.png"])],
                "cal.toml": rng.choice([["orient", "imu.csv", "--calibration", bad.name, "--out", "o.csv"],
                                        ["allan", "imu.csv", "--calibration", bad.name, "--out", "o.csv"]]),
            }[name]
            if name == "p.json":
                (work / "ps.toml").write_text(f'[trajectory]\ntype = "builtin"\nname = "static"\n[imu]\nparams = "{bad.name}"\n')
            run_cli(r, work, args, [bad.name, "imu.csv", "truth.csv", "s.toml"], f"case {k}")
            bad.unlink()
            for leftover in ("o.svg", "o.png", "o.html", "o.toml"):
                (work / leftover).unlink(missing_ok=True)
        runs.append(r)

        r = Run("generated formulas")
        for k in range(per):
            f = formula(rng).replace('"', "")
            (work / "f.toml").write_text(
                f'rate_hz = 20.0\nduration_s = 0.5\n[trajectory]\ntype = "expression"\n'
                f'constants = {{ f = 1.0 }}\nposition_m = ["{f}", "0", "t"]\n')
            run_cli(r, work, ["simulate", "f.toml", "--out", "o.csv", "--truth", "ot.csv"], ["f.toml"], f"case {k}")
        runs.append(r)

        r = Run("extreme numeric options")
        for k in range(per):
            x = lambda: rng.choice(EXTREMES)  # noqa: E731
            args = rng.choice([
                ["integrate", "imu.csv", "--gravity-m-s2", x(), "--out", "o.csv"],
                ["integrate", "imu.csv", "--scheme", "rk4", "--substeps", rng.choice(["0", "1", "1000", "1001", "999999999"]), "--out", "o.csv"],
                ["integrate", "imu.csv", "--position0-m", x(), x(), x(), "--euler0-rad", x(), x(), x(), "--out", "o.csv"],
                ["animate", "truth.csv", "--fps", x(), "--out", "o.html"],
                ["animate", "truth.csv", "--speed", x(), "--body-m", x(), x(), x(), "--out", "o.gif"],
                ["convert", x(), rng.choice(["°/h", "°/√h", "mg", "µg/√Hz", "furlong"])],
                ["orient", "imu.csv", "--param", f"GyroscopeNoise={x()}", "--out", "o.csv"],
                ["orient", "imu.csv", "--filter", "madgwick", "--param", f"Beta={x()}", "--out", "o.csv"],
                ["orient", "imu.csv", "--smooth", "--param",
                 rng.choice(["AccelerometerTimeConstant", "AccelerationThreshold", "AccelerationSustainedTime",
                             "BiasForgettingTime", "MagneticRejectionFactor", "BiasSigmaMotion",
                             "BiasStepThreshold", "BiasStepForgettingTime"]) + f"={x()}",
                 "--out", "o.csv"],
            ])
            run_cli(r, work, args, ["imu.csv", "truth.csv"], f"case {k}")
            for leftover in ("o.html", "o.gif"):
                (work / leftover).unlink(missing_ok=True)
        runs.append(r)

        r = Run("scenarios and navigation on the WGS-84 Earth")
        for k in range(per):
            x = lambda: rng.choice(EXTREMES + ["45", "-89.9", "89.95", "90", "180", "1e6", "-2000"])  # noqa: E731
            motion = rng.choice([
                f'position_m = ["{rng.choice(["300*t", "1e7*t", "t", "0"])}", "0", "{x()}"]\nattitude = "tangent"',
                f'latitude_rad = "{x()}"\nlongitude_rad = "{rng.choice(["0.1", "t", "1e9*t"])}"\nheight_m = "{x()}"\nyaw_rad = "1"',
                'latitude_rad = "0.5"\nlongitude_rad = "0.1"',
            ])
            extra = rng.choice(["", f'magnetic_model = "wmm2025"\ndate = "{rng.choice(["2026-06-01", "2031-01-01", "2026-02-30", "x"])}"\n'])
            aid = rng.choice([
                "",
                f"[gnss]\nrate_hz = {rng.choice(['1.0', '3.0', '10.0', x()])}\nhorizontal_accuracy_m = {x()}\n"
                f"decay_factor = {rng.choice(['0.0', '0.999', '1.0', x()])}\nlatency_s = {x()}\n"
                f"outages = [{{ start_s = {x()}, duration_s = {x()} }}]\n",
                f"[baro]\nrate_hz = {rng.choice(['5.0', x()])}\nnoise_m = {x()}\n[odometer]\nscale_factor_error = {x()}\n",
            ])
            # A part's signal chain and the mount's vibration, read on either Earth.
            chain = rng.choice([
                "",
                f'[imu]\npreset = "mpu-6050"\n[imu.chain]\nsetting = {rng.choice(["3", "0", "9", "-1", chr(34) + "x" + chr(34)])}\n',
                f'[imu.chain]\ngyroscope_internal_rate_hz = {rng.choice(["40.0", "1e5", x()])}\n'
                f'accelerometer_internal_rate_hz = {rng.choice(["20.0", x()])}\n'
                f'accelerometer = {{ filter = "bandwidth_delay", bandwidth_hz = {x()}, delay_s = {x()} }}\n'
                f'[imu.vibration]\nsines = [{{ kind = "angular-rate", axis = "x", frequency_hz = {x()}, amplitude = {x()} }}]\n'
                f'random = [{{ kind = "acceleration", axis = "z", psd = [[1, {x()}], [{x()}, 1]] }}]\n',
            ])
            (work / "e.toml").write_text(
                f'rate_hz = 10.0\nduration_s = {rng.choice(["1", "5", "0"])}\nnav_frame = "{rng.choice(["NED", "ENU"])}"\n'
                f'earth = "{rng.choice(["wgs84", "wgs84", "flat"])}"\n'
                f'origin = {{ latitude_deg = {x()}, longitude_deg = {x()}, height_m = {x()} }}\n{extra}'
                f'[trajectory]\ntype = "expression"\n{motion}\n{aid}{chain}')
            extra_out = (["--gnss", "eg.csv"] if "[gnss]" in aid else []) + \
                (["--baro", "eb.csv", "--odometer", "eod.csv"] if "[baro]" in aid else [])
            run_cli(r, work, ["simulate", "e.toml", "--out", "eo.csv", "--truth", "et.csv", *extra_out], ["e.toml"],
                    f"case {k}")
            if (work / "eo.csv").exists() and (work / "et.csv").exists():
                run_cli(r, work, rng.choice([
                    ["integrate", "eo.csv", "--init", "et.csv", "--earth", "wgs84", "--vertical",
                     rng.choice(["free", "hold", "baro", "up"]), "--out", "en.csv"],
                    ["integrate", "eo.csv", "--earth", "wgs84", "--lat0-deg", x(), "--lon0-deg", x(),
                     "--height0-m", x(), "--out", "en.csv"],
                ]), ["eo.csv", "et.csv"], f"case {k} (navigation)")
            for leftover in ("eo.csv", "et.csv", "en.csv", "eg.csv", "eb.csv", "eod.csv"):
                (work / leftover).unlink(missing_ok=True)
        runs.append(r)

        r = Run("fusion and outage studies")
        for k in range(per):
            x = lambda: rng.choice(EXTREMES)  # noqa: E731
            path = rng.choice(["10*t", "60*sin(0.16*t)", "0", "1e7*t"])
            side = rng.choice(["0", "60*(1 - cos(0.16*t))"])
            (work / "c.toml").write_text(
                f'rate_hz = 20.0\nduration_s = {rng.choice(["20", "2", "0"])}\n'
                f'earth = "{rng.choice(["flat", "flat", "wgs84"])}"\n'
                'origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 0.0 }\n'
                f'[trajectory]\ntype = "expression"\nposition_m = ["{path}", "{side}", "0"]\nattitude = "tangent"\n'
                f'[imu]\nkind = "accel-gyro"\npreset = "{rng.choice(["stim300", "mpu-6050", "ideal"])}"\n'
                f'[gnss]\nrate_hz = {rng.choice(["5.0", "4.0", x()])}\n'
                f'horizontal_accuracy_m = {rng.choice(["1.0", x()])}\nlatency_s = {rng.choice(["0.0", "0.2", x()])}\n'
                f'outages = [{{ start_s = {rng.choice(["5.0", x()])}, duration_s = {rng.choice(["5.0", x()])} }}]\n'
                f'[odometer]\nrate_hz = 10.0\nnoise_m_s = {rng.choice(["0.05", x()])}\n')
            made = ["ci.csv", "ct.csv", "cg.csv", "co.csv"]
            run_cli(r, work, ["simulate", "c.toml", "--out", "ci.csv", "--truth", "ct.csv", "--gnss", "cg.csv",
                              "--odometer", "co.csv"], ["c.toml"], f"case {k}")
            if all((work / f).exists() for f in made):
                (work / "cgm.csv").write_bytes(mutate(rng, (work / "cg.csv").read_bytes()))
                start = rng.choice([["--init", "ct.csv"], ["--align", rng.choice(["gnss", "static", "x"])], [],
                                    ["--init", "ct.csv", "--align", "gnss"]])
                extra = rng.choice([[], ["--odometer", "co.csv"], ["--nhc"], ["--nhc", x()],
                                    ["--covariance-interval-s", x()], ["--no-gate"], ["--baro", "co.csv"],
                                    ["--earth", rng.choice(["flat", "wgs84", "mars"])],
                                    ["--sensor-errors"], [f"--rest-s={x()}"], ["--rest-s", "5", "--sensor-errors"]])
                run_cli(r, work, ["fuse", "ci.csv", rng.choice(["cg.csv", "cgm.csv"]), *start, "--scenario", "c.toml",
                                  *extra, "--out", "cn.csv"], [*made, "cgm.csv", "c.toml"], f"case {k} (fusion)")
                presets = rng.choice(['"stim300"', "", '"nosuch"', '"hg1700", "hg1700"', '"ideal", "mpu-6050"'])
                (work / "st.toml").write_text(
                    f'scenario = "c.toml"\npresets = [{presets}]\nruns = {rng.choice(["2", "0", "1", "-1", "1e9", "100001"])}\n'
                    f'nhc_sigma_m_s = {rng.choice(["0.05", x()])}\nodometer = {rng.choice(["true", "false"])}\n'
                    f'rest_s = {rng.choice(["0", "5", x()])}\nsensor_errors = {rng.choice(["true", "false", "1"])}\n'
                    f'draw_parts = {rng.choice(["true", "false", "2"])}\n')
                run_cli(r, work, ["study", "st.toml", "--out", "sn.csv",
                                  *rng.choice([[], ["--plot", "sn.png"], ["--plot", "sn.gif"]])],
                        ["st.toml", "c.toml"], f"case {k} (study)")
            for leftover in (*made, "cgm.csv", "cn.csv", "st.toml", "sn.csv", "sn.png"):
                (work / leftover).unlink(missing_ok=True)
        runs.append(r)

        for fmt in ("parquet", "npy", "npz", "mcap"):
            r = Run(f"{fmt} files, mutated")
            base = work / "pq.toml"
            base.write_text('rate_hz = 50.0\nduration_s = 4.0\n[trajectory]\ntype = "builtin"\nname = "figure8"\n'
                            '[imu]\nkind = "accel-gyro"\npreset = "mpu-6050"\n')
            seeds = (f"pi.{fmt}", f"pt.{fmt}")
            run_cli(r, work, ["simulate", "pq.toml", "--out", seeds[0], "--truth", seeds[1]], ["pq.toml"],
                    f"{fmt} seed files")
            good = {n: (work / n).read_bytes() for n in seeds if (work / n).exists()}
            m, mo = f"m.{fmt}", f"mo.{fmt}"
            for k in range(per if good else 0):
                name = rng.choice(sorted(good))
                data = good[name]
                if rng.random() < 0.5:
                    data = mutate(rng, data)
                else:  # a truncated file, or one byte flipped
                    cut = rng.randrange(len(data))
                    data = data[:cut] if rng.random() < 0.5 else data[:cut] + bytes([data[cut] ^ 0xFF]) + data[cut + 1:]
                (work / m).write_bytes(data)
                other = seeds[1] if name == seeds[0] else seeds[0]
                args = rng.choice([
                    ["integrate", m, "--init", seeds[1], "--out", mo],
                    ["integrate", seeds[0], "--init", m, "--out", "mo.csv"],
                    ["compare", m, other, "--out", mo],
                    ["allan", m, "--out", "mo.csv"],
                    ["plot", m, "--out", "mo.png"],
                    ["orient", m, "--filter", "imufilter", "--out", mo],
                ])
                run_cli(r, work, args, [m, *good], f"case {k} ({fmt})")
                for leftover in (m, mo, "mo.csv", "mo.png"):
                    (work / leftover).unlink(missing_ok=True)
            for n in ("pq.toml", *good):
                (work / n).unlink(missing_ok=True)
            runs.append(r)

        for fmt in ("parquet", "npy", "npz"):
            r = Run(f"{fmt} files, crafted to lie")
            (work / "cr.toml").write_text('rate_hz = 50.0\nduration_s = 2.0\n[trajectory]\ntype = "builtin"\n'
                                          'name = "figure8"\n[imu]\nkind = "accel-gyro"\n')
            run_cli(r, work, ["simulate", "cr.toml", "--out", f"ci.{fmt}", "--truth", f"ct.{fmt}"], ["cr.toml"],
                    f"{fmt} seed files")
            good = (work / f"ci.{fmt}").read_bytes() if (work / f"ci.{fmt}").exists() else b""
            for k in range(per if good else 0):
                m = f"c.{fmt}"
                (work / m).write_bytes(crafted_table(rng, fmt, good))
                args = rng.choice([
                    ["allan", m, "--out", "co.csv"],
                    ["integrate", m, "--init", f"ct.{fmt}", "--out", f"o.{fmt}"],
                    ["compare", f"ct.{fmt}", m, "--out", "co.csv"],
                    ["orient", m, "--filter", "madgwick", "--out", f"o.{fmt}"],
                    ["plot", m, "--out", "co.png"],
                ])
                run_cli(r, work, args, [m, f"ci.{fmt}", f"ct.{fmt}"], f"case {k} ({fmt})")
                for leftover in (m, "co.csv", "co.png", f"o.{fmt}"):
                    (work / leftover).unlink(missing_ok=True)
            for n in ("cr.toml", f"ci.{fmt}", f"ct.{fmt}"):
                (work / n).unlink(missing_ok=True)
            runs.append(r)

        r = Run("barometer and odometer files")
        (work / "ae.toml").write_text(
            'rate_hz = 20.0\nduration_s = 30.0\nnav_frame = "NED"\nearth = "wgs84"\n'
            'origin = { latitude_deg = 45.0, longitude_deg = 7.0, height_m = 300.0 }\n'
            '[trajectory]\ntype = "expression"\nposition_m = ["10*t", "0", "0"]\nattitude = "tangent"\n'
            '[imu]\nkind = "accel-gyro"\n[gnss]\nrate_hz = 5.0\n[baro]\nrate_hz = 5.0\n[odometer]\nrate_hz = 10.0\n')
        subprocess.run([imukit_bin(), "simulate", "ae.toml", "--out", "ai.csv", "--truth", "at.csv", "--gnss", "ag.csv",
                        "--baro", "ab.csv", "--odometer", "ao.csv"], cwd=work, check=True, capture_output=True)
        aids = {n: (work / n).read_bytes() for n in ("ab.csv", "ao.csv") if (work / n).exists()}
        for k in range(per if len(aids) == 2 else 0):
            name = rng.choice(sorted(aids))
            data = aids[name]
            if rng.random() < 0.5:
                data = mutate(rng, data)
            else:  # times shifted, stretched or reversed
                # The description line (`# imukit: {...}`) is kept as it is, before the header.
                described = [l for l in data.decode().splitlines() if l.startswith("#")]
                lines = [l for l in data.decode().splitlines() if not l.startswith("#")]
                shift = rng.choice(["1e4", "-1e4", "1e308", "0"])
                body = [f"{float(l.split(',')[0]) * rng.choice([1, -1, 1e6]) + float(shift)},{l.split(',', 1)[1]}"
                        for l in lines[1:]]
                data = ("\n".join([*described, lines[0], *rng.choice([body, body[::-1]])]) + "\n").encode()
            (work / "ax.csv").write_bytes(data)
            args = rng.choice([
                ["integrate", "ai.csv", "--init", "at.csv", "--nav-frame", "NED", "--earth", "wgs84",
                 "--vertical", "baro", "--baro", "ax.csv", "--out", "an.csv"],
                ["fuse", "ai.csv", "ag.csv", "--init", "at.csv", "--scenario", "ae.toml", "--baro", "ax.csv",
                 "--out", "an.csv"],
                ["fuse", "ai.csv", "ag.csv", "--init", "at.csv", "--scenario", "ae.toml", "--odometer", "ax.csv",
                 "--nhc", "--out", "an.csv"],
            ])
            run_cli(r, work, args, ["ax.csv", "ai.csv", "at.csv", "ag.csv", "ae.toml"], f"case {k} ({name})")
        runs.append(r)

        r = Run("NMEA logs and Kalibr files, mutated")
        # The fixes as GGA and RMC sentences, and a part as Kalibr's imu.yaml.
        def sentence(body: str) -> str:
            total = 0
            for ch in body.encode(errors="replace"):
                total ^= ch
            return f"${body}*{total:02X}"
        fixes = [l.split(",") for l in (work / "ag.csv").read_text().splitlines() if l and not l.startswith(("#", "t_s"))]
        nmea = []
        for t, lat, lon, h, *_ in fixes:
            hh, rest = divmod(float(t), 3600.0)
            mm, ss = divmod(rest, 60.0)
            la, lo = abs(math.degrees(float(lat))), abs(math.degrees(float(lon)))
            pos = f"{int(la):02d}{(la % 1) * 60:09.6f},N,{int(lo):03d}{(lo % 1) * 60:09.6f},E"
            stamp = f"{int(hh):02d}{int(mm):02d}{ss:05.2f}"
            nmea.append(sentence(f"GPGGA,{stamp},{pos},1,08,0.9,{float(h):.3f},M,0.0,M,,"))
            nmea.append(sentence(f"GPRMC,{stamp},A,{pos},19.4,90.0,270326,,,A"))
        kalibr = subprocess.run([imukit_bin(), "presets", "mpu-6050", "--format", "kalibr"], cwd=work,
                                capture_output=True).stdout
        for k in range(per if nmea and kalibr else 0):
            if rng.random() < 0.5:
                lines = list(nmea)
                for _ in range(rng.randint(1, 4)):
                    i = rng.randrange(len(lines))
                    body = lines[i][1:].rsplit("*", 1)[0]
                    body = mutate(rng, body.encode()).decode(errors="replace").replace("\n", "")
                    # The checksum made right again half the time: the parser sees the damage.
                    lines[i] = sentence(body) if rng.random() < 0.5 else "$" + body + lines[i][-3:]
                (work / "ax.nmea").write_text("\r\n".join(lines) + "\r\n")
                args = ["fuse", "ai.csv", "ax.nmea", "--init", "at.csv", "--scenario", "ae.toml",
                        *rng.choice([[], ["--gnss-uere-m", rng.choice(["2", "0", "-1", "1e308"])]]), "--out", "an.csv"]
                run_cli(r, work, args, ["ax.nmea", "ai.csv", "at.csv", "ae.toml"], f"case {k} (nmea)")
            else:
                (work / "kx.yaml").write_bytes(mutate(rng, kalibr))
                args = ["fuse", "ai.csv", "ag.csv", "--init", "at.csv", "--imu", "kx.yaml", "--out", "an.csv"]
                run_cli(r, work, args, ["kx.yaml", "ai.csv", "at.csv", "ag.csv"], f"case {k} (kalibr)")
        for n in ("ae.toml", "ai.csv", "at.csv", "ag.csv", "ab.csv", "ao.csv", "ax.csv", "an.csv", "ax.nmea", "kx.yaml"):
            (work / n).unlink(missing_ok=True)
        runs.append(r)

        r = Run("crafted bags, logs, output folders and names")
        # Lengths that declare gigabytes, SQL that never ends, numbers that are not numbers, a
        # link planted inside an output folder, names of formats imukit does not write: each
        # refused by name, within a 3 GiB address space, the link's target untouched.
        def mcap_metadata(key_len: int) -> bytes:
            def record(op: int, body: bytes) -> bytes:
                return bytes([op]) + struct.pack("<Q", len(body)) + body
            string = lambda b: struct.pack("<I", len(b)) + b  # noqa: E731
            entries = struct.pack("<I", key_len) + b"abc"
            body = string(b"m") + struct.pack("<I", len(entries)) + entries
            magic = b"\x89MCAP0\r\n"
            return (magic + record(0x01, string(b"ros2") + string(b"x")) + record(0x0C, body)
                    + record(0x0F, b"\0" * 4) + record(0x02, b"\0" * 20) + magic)

        def ros1_chunk(size: int) -> bytes:
            field = lambda n, v: struct.pack("<I", len(n) + 1 + len(v)) + n + b"=" + v  # noqa: E731
            header = field(b"op", b"\x05") + field(b"compression", b"bz2") + field(b"size", struct.pack("<I", size))
            return b"#ROSBAG V2.0\n" + struct.pack("<I", len(header)) + header + struct.pack("<I", 4) + b"BZh9"

        def endless_db3(path: Path) -> None:
            import sqlite3
            path.unlink(missing_ok=True)
            with sqlite3.connect(path) as db:
                db.executescript(
                    "CREATE TABLE topics (id INTEGER, name TEXT, type TEXT, serialization_format TEXT);"
                    "INSERT INTO topics VALUES (1, '/imu', 'sensor_msgs/msg/Imu', 'cdr');"
                    "CREATE VIEW messages AS WITH RECURSIVE n(id) AS (SELECT 1 UNION ALL SELECT id + 1 FROM n) "
                    "SELECT 1 AS topic_id, x'00' AS data, id AS timestamp, id FROM n;")
            db.close()

        for k in range(per):
            kind = k % 6
            if kind == 0:
                (work / "cx.mcap").write_bytes(mcap_metadata(rng.choice([0xFFFF0003, 2**31, 2**32 - 1, 1 << 29])))
                run_cli(r, work, [rng.choice(["integrate", "orient", "allan"]), "cx.mcap", "--out", "o.csv"],
                        ["cx.mcap"], f"case {k} (mcap length)", memory_gb=3)
            elif kind == 1:
                (work / "cx.bag").write_bytes(ros1_chunk(rng.choice([2**32 - 1, 1 << 29, 3 << 30])))
                run_cli(r, work, [rng.choice(["integrate", "orient"]), "cx.bag", "--out", "o.csv"],
                        ["cx.bag"], f"case {k} (ros 1 chunk)", memory_gb=3)
            elif kind == 2:
                endless_db3(work / "cx.db3")
                run_cli(r, work, ["integrate", "cx.db3", "--out", "o.csv"], ["cx.db3"], f"case {k} (sqlite view)")
                left = [p.name for p in work.iterdir() if p.name.startswith("cx.db3-")]
                if left:
                    r.fail(f"case {k} (sqlite view)", f"side files left: {left}")
            elif kind == 3:
                bad = rng.choice(["nan", "inf", "-inf", "1e308"])
                field = rng.choice(["alt", "speed", "course"])
                alt, speed, course = (bad if field == f else v for f, v in
                                      (("alt", "545.4"), ("speed", "10.0"), ("course", "90.0")))
                def sentence(body: str) -> str:
                    total = 0
                    for ch in body.encode():
                        total ^= ch
                    return f"${body}*{total:02X}"
                lines = [sentence(f"GPGGA,000000.60,4807.038,N,01131.000,E,1,08,0.9,{alt},M,47.0,M,,"),
                         sentence(f"GPRMC,000000.60,A,4807.038,N,01131.000,E,{speed},{course},230394,003.1,W")]
                (work / "cx.nmea").write_text("\r\n".join(lines) + "\r\n")
                run_cli(r, work, ["fuse", "imu.csv", "cx.nmea", "--imu", "stim300", "--align", "gnss",
                                  "--out", "o.csv"], ["cx.nmea", "imu.csv"], f"case {k} (nmea {field} {bad})")
            elif kind == 4:
                shutil.rmtree(work / "seq", ignore_errors=True)
                shutil.rmtree(work / "elsewhere", ignore_errors=True)
                (work / "elsewhere" / "imu0").mkdir(parents=True)
                (work / "elsewhere" / "imu0" / "data.csv").write_text("not yours\n")
                (work / "seq").mkdir()
                os.symlink(work / "elsewhere", work / "seq" / "mav0")
                run_cli(r, work, ["simulate", "s.toml", "--layout", "euroc", "--out", "seq"],
                        ["s.toml", "elsewhere/imu0/data.csv"], f"case {k} (link inside an output folder)")
            else:
                name = "o." + rng.choice(["xlsx", "mat", "h5", "db3", "bag", "nmea", "json"])
                run_cli(r, work, rng.choice([["integrate", "imu.csv", "--out", name],
                                             ["simulate", "s.toml", "--out", name],
                                             ["compare", "truth.csv", "truth.csv", "--out", name]]),
                        ["imu.csv", "s.toml", "truth.csv"], f"case {k} ({name})")
                if (work / name).exists():
                    r.fail(f"case {k} ({name})", f"{name} was written")
                    (work / name).unlink()
        for n in ("cx.mcap", "cx.bag", "cx.db3", "cx.nmea"):
            (work / n).unlink(missing_ok=True)
        shutil.rmtree(work / "seq", ignore_errors=True)
        shutil.rmtree(work / "elsewhere", ignore_errors=True)
        runs.append(r)

        r = Run("time windows, shipped examples, bag names and track waits")
        (work / "elsewhere").mkdir(exist_ok=True)
        (work / "elsewhere" / "keep.txt").write_text("not yours")
        hostile_names = ["", "/", "//imu", "/imu/", "imu", "/imu data", "/2x", "/a\nb", "/" + "a" * 5000,
                         "/ok/topic", "frame", "../x", "imu_link", "é", "/imu\x00"]
        for k in range(per):
            kind = rng.choice(["window", "example", "bag", "wait"])
            if kind == "window":
                start, end = rng.choice(EXTREMES + ["0.2", "10"]), rng.choice(EXTREMES + ["0.3", "1e3"])
                flags = rng.choice([["--start-s", start], ["--end-s", end], ["--start-s", start, "--end-s", end]])
                args = rng.choice([["integrate", "imu.csv", "--init", "truth.csv", "--out", "o.csv"],
                                   ["orient", "imu.csv", "--out", "o.csv"],
                                   ["allan", "imu.csv", "--out", "o.csv"],
                                   ["compare", "truth.csv", "truth.csv", "--out", "o.csv"],
                                   ["plot", "truth.csv", "--out", "o.svg"]])
                run_cli(r, work, [*args, *flags], ["imu.csv", "truth.csv"], f"case {k} (window)")
                (work / "o.svg").unlink(missing_ok=True)
            elif kind == "example":
                ex = work / "ex"
                shutil.rmtree(ex, ignore_errors=True)
                ex.mkdir()
                plant = rng.choice(["link", "file", "edited", "none"])
                if plant == "link":
                    os.symlink(work / "elsewhere", ex / rng.choice(["study", "data"]))
                elif plant == "file":
                    (ex / rng.choice(["study", "data"])).write_text("a file where a folder goes")
                elif plant == "edited":
                    (ex / "car_tunnel.toml").write_text("# mine")
                name = rng.choice(["all", "study/tunnel", "data/euroc", "samples", "car_tunnel", "../x", "",
                                   "/etc/passwd", "study/../../x", "a" * 3000, "track.toml"])
                run_cli(r, work, ["example", name, "--out-dir", "ex"], ["imu.csv"], f"case {k} (example {plant})")
                if sorted(p.name for p in (work / "elsewhere").iterdir()) != ["keep.txt"]:
                    r.fail(f"case {k} (example {plant})", "wrote through a link planted in the examples folder")
                if plant == "edited" and (ex / "car_tunnel.toml").read_text() != "# mine":
                    r.fail(f"case {k} (example edited)", "an edited example was overwritten")
                shutil.rmtree(ex, ignore_errors=True)
            elif kind == "bag":
                flags = rng.choice([["--bag-topic", rng.choice(hostile_names)],
                                    ["--bag-frame-id", rng.choice(hostile_names)],
                                    ["--bag-start-s", rng.choice(EXTREMES + ["1700000000", "2147483647", "2147483648"])]])
                out = rng.choice(["o.mcap", "o.csv"])
                try:
                    run_cli(r, work, ["simulate", "s.toml", "--out", out, *flags], ["s.toml"], f"case {k} (bag)")
                except ValueError:  # a NUL in an argument: the OS refuses it before imukit runs
                    r.passed += 1
                (work / "o.mcap").unlink(missing_ok=True)
            else:
                wait = rng.choice(EXTREMES + ["20", "3600"])
                where = rng.choice(["first", "middle", "last", "only"])
                segs = {"first": f"{{ wait_s = {wait} }}, {{ straight_m = 5 }}",
                        "middle": f"{{ straight_m = 5 }}, {{ wait_s = {wait} }}, {{ straight_m = 5 }}",
                        "last": f"{{ straight_m = 5 }}, {{ wait_s = {wait} }}",
                        "only": f"{{ wait_s = {wait} }}"}[where]
                accel = rng.choice(["accel_m_s2 = 1.0\n", ""])
                (work / "w.toml").write_text(f'rate_hz = 20.0\n[trajectory]\ntype = "track"\nspeed_m_s = 2.0\n'
                                             f'{accel}segments = [{segs}]\n')
                run_cli(r, work, ["simulate", "w.toml", "--out", "o.csv"], ["w.toml"], f"case {k} (wait {wait})")
        shutil.rmtree(work / "elsewhere", ignore_errors=True)
        runs.append(r)

        r = Run("signals at a random moment")
        (work / "long.toml").write_text('rate_hz = 1000.0\nduration_s = 6000.0\n[trajectory]\ntype = "builtin"\n'
                                        'name = "figure8"\n[imu]\npreset = "mpu-6050"\n')
        for k in range(slow):
            ext = rng.choice(["csv", "parquet", "npy", "npz"])
            sig = rng.choice(list(SIGNAL_EXITS))
            args = ["simulate", "long.toml", "--out", f"s.{ext}", *rng.choice([[], ["--truth", f"st.{ext}"],
                                                                               ["--runs", "2"]])]
            proc = subprocess.Popen([imukit_bin(), *args], cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            time.sleep(rng.uniform(0.0, 1.0))
            proc.send_signal(sig)
            try:
                _, err = proc.communicate(timeout=TIME_LIMIT_S)
            except subprocess.TimeoutExpired:
                proc.kill()
                r.fail(f"case {k}", f"no end within {TIME_LIMIT_S} s of {sig.name}")
                continue
            left = sorted(p.name for p in work.iterdir()
                          if (p.name.startswith("s") or "imukit-partial" in p.name) and p.name != "s.toml")
            # Before its handler is set up (the first milliseconds) the process ends by the signal
            # itself, which a shell reports as the same status; a run that ended before the signal
            # has put all its outputs in place.
            expected = {"--truth": 2, "--runs": 2}.get(args[-2], 1)
            finished = proc.returncode == 0 and len(left) == expected and not any("partial" in n for n in left)
            if not finished and (proc.returncode not in (SIGNAL_EXITS[sig], -sig) or left) or b"panicked" in err:
                r.fail(f"case {k}", f"{sig.name}: exit {proc.returncode}, left {left} [{' '.join(args)}]")
            else:
                r.passed += 1
            for p in work.iterdir():
                if p.name.startswith(("s.", "st.", "s_run", ".s")):
                    p.unlink()
        runs.append(r)

        r = Run("two processes writing one name")
        (work / "w1.toml").write_text('rate_hz = 200.0\nduration_s = 20.0\n[trajectory]\ntype = "builtin"\n'
                                      'name = "figure8"\n')
        (work / "w2.toml").write_text('rate_hz = 100.0\nduration_s = 30.0\n[trajectory]\ntype = "builtin"\n'
                                      'name = "tilted-circle"\n')
        for k in range(slow):
            ext = rng.choice(["csv", "parquet", "npy", "npz"])
            whole = {}
            for w in ("w1", "w2"):
                subprocess.run([imukit_bin(), "simulate", f"{w}.toml", "--out", f"{w}.{ext}"], cwd=work,
                               capture_output=True, check=True)
                whole[w] = (work / f"{w}.{ext}").read_bytes()
            procs = [subprocess.Popen([imukit_bin(), "simulate", f"{w}.toml", "--out", f"same.{ext}"], cwd=work,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for w in ("w1", "w2")]
            codes = [p.wait(timeout=TIME_LIMIT_S) for p in procs]
            got = (work / f"same.{ext}").read_bytes() if (work / f"same.{ext}").exists() else b""
            left = [p.name for p in work.iterdir() if "imukit-partial" in p.name]
            if codes != [0, 0] or got not in whole.values() or left:
                r.fail(f"case {k}", f"exits {codes}, {len(got)} bytes matching neither run, left {left} ({ext})")
            else:
                r.passed += 1
            for p in (f"same.{ext}", f"w1.{ext}", f"w2.{ext}"):
                (work / p).unlink(missing_ok=True)
        runs.append(r)

        r = Run("colliding and special output paths")
        (work / "folder").mkdir(exist_ok=True)
        long = "x" * 250 + ".csv"
        for k in range(per):
            out = rng.choice(["s.toml", "imu.csv", "truth.csv", "./imu.csv", "../" + work.name + "/truth.csv",
                              "/dev/null", "folder", "-", long, "o.csv"])
            args, inputs = rng.choice([
                (["simulate", "s.toml", "--out", out, "--truth", rng.choice(["truth2.csv", out, "/dev/null"])],
                 ["s.toml"]),
                (["integrate", "imu.csv", "--init", "truth.csv", "--out", out], ["imu.csv", "truth.csv"]),
                (["compare", "truth.csv", "truth.csv", "--out", out], ["truth.csv"]),
                (["allan", "imu.csv", "--out", out, "--plot", rng.choice(["a.svg", "a.txt", out])], ["imu.csv"]),
                (["calibrate", "imu.csv", "--out", out], ["imu.csv"]),
                (["spectrum", "imu.csv", "--segment-s", rng.choice(["0.1", "1e300", "-1", "nan"]), "--out", out],
                 ["imu.csv"]),
            ])
            run_cli(r, work, args, inputs, f"case {k}")
            for leftover in ("truth2.csv", long, "a.svg"):
                (work / leftover).unlink(missing_ok=True)
            for name, data in valid.items():  # an output may legitimately replace a file of another case
                (work / name).write_bytes(data)
        runs.append(r)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return runs


PY_CASES = r"""
import os, random, shutil, sys, tempfile, numpy as np, imukit
rng = random.Random(int(sys.argv[1]))
cases = int(sys.argv[2])
X = [np.nan, np.inf, -np.inf, 1e308, -1e308, 0.0, -1.0, 1e9, 1e-320]
def arr(shape):
    a = np.array([[rng.choice(X + [rng.uniform(-5, 5)] * 6) for _ in range(shape[1])] for _ in range(shape[0])])
    return a
OUT = tempfile.mkdtemp(prefix="imukit-hostile-py-")
FUSE_SCENARIO = {"rate_hz": 10.0, "duration_s": 10.0, "imu": {"kind": "accel-gyro"}, "gnss": {"rate_hz": 1.0},
                 "trajectory": {"type": "expression", "position_m": ["5*t", "0", "0"], "attitude": "tangent"}}
BASE = imukit.simulate(FUSE_SCENARIO)
NAMES = ["x" * rng.choice([255, 256, 100_000]), "a,b", "t_s", "", " x", "#x", "a\nb", "it's", "a/b", "ok_name", "é"]
def rows(table, n):
    return imukit.Table(list(table.columns), np.array(table.values)[:n])
def imu_table(n):
    return rows(BASE.imu, n)
def gnss_table(n):
    return rows(BASE.gnss, n)
def truth_table(n):
    return rows(BASE.truth, n)
passed = failed = 0
for k in range(cases):
    n = rng.choice([0, 1, 2, 5, 50])
    calls = [
        lambda: imukit.ImuSensor("accel-gyro-mag", sample_rate=rng.choice(X + [100.0]))(arr((n, 3)), arr((n, 3)), arr((n, 4))),
        lambda: imukit.ImuSensor(accelerometer={"MeasurementRange": rng.choice(X), "NoiseDensity": rng.choice(X)})(arr((n, 3)), arr((n, 3))),
        lambda: imukit.truth_from_samples(np.sort(arr((n, 1))[:, 0]) if n else np.zeros(0), arr((n, 3)), attitude="tangent"),
        lambda: imukit.truth_from_expressions(np.linspace(0, 1, max(n, 2)), [rng.choice(["t", "1e308*t*t", "(" * 70 + "t" + ")" * 70, "ln(t-2)"]), "0", "0"]),
        lambda: imukit.allan_deviation(arr((n, rng.choice([1, 3]))), rng.choice(X + [100.0])),
        lambda: imukit.euler_to_quaternion(arr((n, rng.choice([2, 3, 4])))),
        lambda: imukit.quaternion_to_dcm(arr((n, 4))),
        lambda: imukit.simulate({"rate_hz": rng.choice(X + [100.0]), "duration_s": rng.choice(X + [1.0]),
                                 "trajectory": {"type": "builtin", "name": "static"}}),
        lambda: imukit.simulate({"duration_s": 30.0, "trajectory": {"type": "builtin", "name": "static"}},
                                threads=rng.choice([None, 0, 1, 2, -1, 2**64, -2**64, True, 2.5, np.nan, "2"]),
                                run=rng.choice([None, 0, 3, -1, 2**64, 1.5, False]),
                                truth=rng.choice([True, False, np.bool_(False), 0, None, "yes"])),
        lambda: imukit.planar_dead_reckon(np.arange(n, dtype=float), arr((n, 1))[:, 0] if n else np.zeros(0),
                                          np.zeros(n), np.zeros(n), heading0_rad=rng.choice(X)),
        lambda: imukit.ImuFilter(sample_rate=rng.choice(X + [100.0]), conventions="matlab")(arr((n, 3)), arr((n, 3))),
        lambda: imukit.fuse(imu_table(n), gnss_table(rng.choice([0, 1, 3])), initial=truth_table(max(n, 1)),
                            scenario=FUSE_SCENARIO),
        lambda: imukit.strapdown(imu_table(n), truth_table(max(n, 1))),
        lambda: imukit.compare(truth_table(n), truth_table(rng.choice([0, 1, n]))),
        lambda: imukit.Table(["t_s", rng.choice(NAMES)], np.ones((max(n, 1), 2))).write(
            os.path.join(OUT, "o." + rng.choice(["csv", "parquet", "npy", "npz"]))),
    ]
    call = rng.choice(calls)
    try:
        out = call()
        values = [v for v in (out if isinstance(out, tuple) else (out,))]
        for v in values:
            data = getattr(v, "values", v)
            if isinstance(data, np.ndarray) and data.dtype.kind == "f" and not np.all(np.isfinite(data)):
                failed += 1
                print(f"case {k}: a non-finite result was returned")
                break
        else:
            passed += 1
    except (imukit.ImuError, ValueError, TypeError):
        passed += 1
    except Exception as e:  # anything else is a failure of the binding
        failed += 1
        print(f"case {k}: {type(e).__name__}: {e}")
left = [f for f in os.listdir(OUT) if "imukit-partial" in f]
if left:
    failed += 1
    print(f"partial files left: {left}")
shutil.rmtree(OUT, ignore_errors=True)
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
"""


def python_cases(seed: int, cases: int) -> Run:
    r = Run("Python API with NaN, inf, huge and misshapen arguments")
    try:
        out = subprocess.run([sys.executable, "-c", PY_CASES, str(seed), str(cases)], capture_output=True,
                             timeout=TIME_LIMIT_S * 10, text=True)
    except subprocess.TimeoutExpired:
        r.fail("all", "no answer in time")
        return r
    if out.returncode not in (0, 1):
        r.fail("all", f"the interpreter died (exit {out.returncode}): {out.stderr[-400:]}")
        return r
    last = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else ""
    try:
        passed, failed = (int(last.split()[0]), int(last.split()[2]))
    except (IndexError, ValueError):
        r.fail("all", f"unreadable result: {out.stdout[-300:]} {out.stderr[-300:]}")
        return r
    r.passed = passed
    for line in out.stdout.strip().splitlines()[:-1]:
        r.fail("case", line)
    if failed and not r.failures:
        r.fail("all", f"{failed} failures")
    return r


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=400, help="cases in all (CLI classes share 4/5)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--process-cases", type=int, default=0,
                    help="cases of each class that signals or races real processes (default: a quarter of the others')")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    runs = cli_cases(rng, a.cases * 4 // 5, a.process_cases)
    runs.append(python_cases(a.seed, max(1, a.cases // 5)))
    total_pass = sum(r.passed for r in runs)
    total_fail = sum(len(r.failures) for r in runs)
    for r in runs:
        print(f"{r.name}: {r.passed} passed, {len(r.failures)} failed")
        for f in r.failures[:20]:
            print("   ", f)
    print(f"{total_pass} passed, {total_fail} failed")
    return 1 if total_fail else 0


if __name__ == "__main__":
    sys.exit(main())
