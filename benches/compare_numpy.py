"""imukit against a hand-vectorised NumPy implementation of the same pipeline, timed in one run.

The pipeline: sampled positions and Euler angles (a figure-8 with a banking, pitching body) →
truth by differentiation (MATLAB ``gradient``, imukit ``order=2``) → specific force and body rate
→ MATLAB imuSensor's full error model on accelerometer, gyroscope and magnetometer (bias,
misalignment, white noise, bias-instability filter, random walk, temperature bias and scale,
gyroscope acceleration bias, saturation, quantisation; double-sided densities, MATLAB's signs).

The NumPy reference is written as a competent NumPy user would (whole-array operations, SciPy's
``lfilter`` for the bias-instability filter). Before timing, the two are checked to agree: to
rounding with the noise terms at zero, and in distribution with noise (the white, random-walk and
bias-instability parts have the variances theory gives, in both).

Three comparisons per size: the job a user has most often — formula strings of the motion in,
readings out (imukit: ``imukit.simulate(..., truth=False)`` of an ``expression`` trajectory,
truth with exact derivatives from the compiled formulas, then the sensors, the readings kept as
the NumPy reference keeps only its readings; NumPy: the same motion written with hand-derived
closed-form derivatives, then the same error model) — the pipeline from sampled
positions and angles (truth by differentiation, MATLAB ``gradient``, + error model), and the
error model alone on prepared inputs (NumPy: body-frame inputs, its normals included; imukit:
MATLAB's call shape into a reused output buffer, the rotations to the body frame included).

Why this script once reported imukit at 1.8–3.9× NumPy while a side-by-side run of the formula
job found it at 0.36–0.64×: it timed only the sampled pipeline, where both sides differentiate
by cheap differences, never formula strings — the interpreted per-sample tree walk over dual
numbers that the formula path then was. The formula job is the first column now.
``--rust`` also runs the criterion bench of the same call in Rust and prints the Python/Rust
time ratio at 10⁶ samples.

The formula job's two Python sides are each timed in fresh processes (the median of three, each
the best of its calls), as the goal they are measured against asks, so that neither inherits the
other's warm caches or the allocator state earlier work left; the commands run in fresh
processes anyway. A "warm" column times both Python sides in this process after the agreement
check too: there NumPy is faster at small N, because the check freed large arrays and glibc then
keeps the memory of NumPy's temporaries instead of returning it and faulting it in again.

Run (prints tables of time ratios; first one core — both sides single-threaded, imukit with
``threads=1`` / ``--threads 1`` — then the formula job with imukit on every core it may use, where
one run makes its truth, readings and file a chunk apart on up to three threads, docs/design.md §1):
    python benches/compare_numpy.py                     # N = 10⁴ … 10⁶
    python benches/compare_numpy.py --sizes 1e4 1e5 1e6 1e7 --rust
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path
from typing import Optional

import numpy as np
from scipy.signal import lfilter

import imukit

# The job, its motion and its sensors: one file, read by this script and by the Rust bench.
JOB = tomllib.loads((Path(__file__).resolve().parent / "formula_job.toml").read_text())
FS = JOB["rate_hz"]
G = JOB["gravity_m_s2"]
TEMPERATURE = JOB["imu"]["temperature_c"]
MAG_NED = np.array(JOB["imu"]["magnetic_field_ut"])
SENSORS = ("accelerometer", "gyroscope", "magnetometer")
NOISE = ("NoiseDensity", "BiasInstability", "RandomWalk")


def params(noise: bool) -> dict:
    """MATLAB property values of the three sensors; the noise terms zeroed when ``noise`` is off."""
    return {s: {k: (v if noise or k not in NOISE else 0.0) for k, v in JOB["imu"][s].items()} for s in SENSORS}


W = JOB["trajectory"]["constants"]["w"]
assert W == 2 * np.pi / 20.0, "the NumPy reference's derivatives are written for w = 2π/20"

# The motion as formula strings (NED, z-y-x Euler angles), as a user writes it for imukit.
FORMULAS = {k: JOB["trajectory"][k] for k in ("position_m", "yaw_rad", "pitch_rad", "roll_rad")}


def trajectory(n: int):
    """The sampled input: times, NED positions and z-y-x Euler angles (smooth, no wrap)."""
    t = np.arange(n) / FS
    w = W
    p = np.column_stack([10 * np.sin(w * t), 5 * np.sin(2 * w * t), -2 + 0.5 * np.sin(3 * w * t)])
    e = np.column_stack([0.8 * np.sin(w * t), 0.2 * np.sin(2 * w * t), 0.3 * np.sin(w * t + 0.5)])
    return t, p, e


# --- The NumPy reference -------------------------------------------------------------------

def dcm_nb(e: np.ndarray) -> np.ndarray:
    """C_nb = Rz(yaw) Ry(pitch) Rx(roll), (N, 3, 3)."""
    cy, sy = np.cos(e[:, 0]), np.sin(e[:, 0])
    cp, sp = np.cos(e[:, 1]), np.sin(e[:, 1])
    cr, sr = np.cos(e[:, 2]), np.sin(e[:, 2])
    return np.stack([
        np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], axis=-1),
        np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], axis=-1),
        np.stack([-sp, cp * sr, cp * cr], axis=-1),
    ], axis=1)


def matlab_round(x: np.ndarray) -> np.ndarray:
    return np.sign(x) * np.floor(np.abs(x) + 0.5)


def sensor(u, p, normals, accel_n=None):
    """MATLAB imuSensor's steps 2–7 for one sensor on body-frame input ``u`` (N, 3)."""
    beta = FS / 2.0  # double-sided
    m = np.asarray(p["AxesMisalignment"]) / 100.0
    y = u @ m.T + np.asarray(p["ConstantBias"])
    n_bi, n_w, n_rw = normals[:, 0:3], normals[:, 3:6], normals[:, 6:9]
    y += lfilter([1.0], [1.0, -0.5], p["BiasInstability"] * n_bi, axis=0)
    y += p["NoiseDensity"] * np.sqrt(beta) * n_w
    y += np.cumsum(p["RandomWalk"] / np.sqrt(beta) * n_rw, axis=0)
    y += (TEMPERATURE - 25.0) * np.asarray(p["TemperatureBias"])
    if accel_n is not None:
        y += np.asarray(p["AccelerationBias"]) * accel_n
    y *= 1.0 + (TEMPERATURE - 25.0) * np.asarray(p["TemperatureScaleFactor"]) / 100.0
    r = p["MeasurementRange"]
    y = np.clip(y, -r, r)
    return p["Resolution"] * matlab_round(y / p["Resolution"])


def numpy_pipeline(t, pos, euler, prm, normals):
    vel = np.gradient(pos, t, axis=0, edge_order=1)
    acc = np.gradient(vel, t, axis=0, edge_order=1)
    de = np.gradient(euler, t, axis=0, edge_order=1)
    sp, cp = np.sin(euler[:, 1]), np.cos(euler[:, 1])
    sr, cr = np.sin(euler[:, 2]), np.cos(euler[:, 2])
    omega_b = np.column_stack([de[:, 2] - de[:, 0] * sp,
                               de[:, 1] * cr + de[:, 0] * cp * sr,
                               -de[:, 1] * sr + de[:, 0] * cp * cr])
    c = dcm_nb(euler)
    f_b = np.einsum("nji,nj->ni", c, -acc + np.array([0.0, 0.0, G]))  # R (−a + g ĝ), NED
    m_b = np.einsum("nji,j->ni", c, MAG_NED)
    return (sensor(f_b, prm["accelerometer"], normals[:, 0:9]),
            sensor(omega_b, prm["gyroscope"], normals[:, 9:18], accel_n=acc),
            sensor(m_b, prm["magnetometer"], normals[:, 18:27]))


def numpy_formula_pipeline(n, prm, normals):
    """The motion of ``FORMULAS`` with hand-derived closed-form derivatives, then the error model."""
    t = np.arange(n) / FS
    w = W
    acc = np.column_stack([-10 * w**2 * np.sin(w * t), -5 * (2 * w)**2 * np.sin(2 * w * t),
                           -0.5 * (3 * w)**2 * np.sin(3 * w * t)])
    euler = np.column_stack([0.8 * np.sin(w * t), 0.2 * np.sin(2 * w * t), 0.3 * np.sin(w * t + 0.5)])
    de = np.column_stack([0.8 * w * np.cos(w * t), 0.2 * 2 * w * np.cos(2 * w * t), 0.3 * w * np.cos(w * t + 0.5)])
    sp, cp = np.sin(euler[:, 1]), np.cos(euler[:, 1])
    sr, cr = np.sin(euler[:, 2]), np.cos(euler[:, 2])
    omega_b = np.column_stack([de[:, 2] - de[:, 0] * sp,
                               de[:, 1] * cr + de[:, 0] * cp * sr,
                               -de[:, 1] * sr + de[:, 0] * cp * cr])
    c = dcm_nb(euler)
    f_b = np.einsum("nji,nj->ni", c, -acc + np.array([0.0, 0.0, G]))
    m_b = np.einsum("nji,j->ni", c, MAG_NED)
    return (sensor(f_b, prm["accelerometer"], normals[:, 0:9]),
            sensor(omega_b, prm["gyroscope"], normals[:, 9:18], accel_n=acc),
            sensor(m_b, prm["magnetometer"], normals[:, 18:27]))


# --- imukit ---------------------------------------------------------------------------------

def formula_scenario(n: int, prm, seed=1) -> dict:
    """The job of ``formula_job.toml`` over ``n`` samples with the sensors of ``prm``."""
    return {**JOB, "duration_s": (n - 1) / FS, "imu": {**JOB["imu"], "seed": seed, **prm}}


def imukit_formula_pipeline(n, prm, seed=1, threads=1):
    """Readings only, like the NumPy reference (the CLI's ``--out`` without ``--truth``)."""
    sim = imukit.simulate(formula_scenario(n, prm, seed), threads=threads, truth=False)
    v = sim.imu.values
    return v[:, 1:4], v[:, 4:7], v[:, 7:10]

def imukit_pipeline(t, pos, euler, prm, seed=1):
    truth = imukit.truth_from_samples(t, pos, euler_rad=euler, order=2, nav_frame="NED")
    q = truth.values[:, 10:14]
    acc = truth.values[:, 7:10]
    omega_n = np.einsum("nij,nj->ni", imukit.quaternion_to_dcm(q), truth.values[:, 17:20])
    imu = imukit.ImuSensor("accel-gyro-mag", reference_frame="NED", sample_rate=FS, temperature=TEMPERATURE,
                           seed=seed, magnetic_field=MAG_NED, **prm)
    return imu(acc, omega_n, q)


def model_inputs(t, pos, euler):
    """The error model's inputs, prepared outside the timing: the NumPy reference's body-frame
    specific force, body rate and field, and the nav-frame arrays imukit's MATLAB-shaped call
    takes (C-contiguous)."""
    truth = imukit.truth_from_samples(t, pos, euler_rad=euler, order=2, nav_frame="NED")
    v = truth.values
    q = np.ascontiguousarray(v[:, 10:14])
    acc = np.ascontiguousarray(v[:, 7:10])
    c = imukit.quaternion_to_dcm(q)
    omega_n = np.einsum("nij,nj->ni", c, v[:, 17:20])
    f_b = np.einsum("nji,nj->ni", c, -acc + np.array([0.0, 0.0, G]))
    m_b = np.einsum("nji,j->ni", c, MAG_NED)
    return (acc, omega_n, q), (f_b, np.ascontiguousarray(v[:, 17:20]), m_b, acc)


def numpy_model(f_b, omega_b, m_b, acc, prm, rng_seed=1):
    """The NumPy reference's error model alone (its normals included)."""
    normals = np.random.default_rng(rng_seed).standard_normal((len(f_b), 27))
    return (sensor(f_b, prm["accelerometer"], normals[:, 0:9]),
            sensor(omega_b, prm["gyroscope"], normals[:, 9:18], accel_n=acc),
            sensor(m_b, prm["magnetometer"], normals[:, 18:27]))


def rust_matlab_call_ns_per_sample() -> Optional[float]:
    """Criterion's estimate for the same call in Rust (`--bench sensor`, `matlab_call`, 10⁶
    samples, output buffer reused), run now; None where cargo is not available."""
    root = Path(__file__).resolve().parents[1]
    if shutil.which("cargo") is None:
        return None
    subprocess.run(["cargo", "bench", "-q", "-p", "imu-benches", "--bench", "sensor", "--", "matlab_call"],
                   cwd=root, check=True, capture_output=True)
    est = root / "target" / "criterion" / "sensor_model_matlab_call" / "accel-gyro-mag" / "1000000" / "new"
    mean_ns = json.loads((est / "estimates.json").read_text())["mean"]["point_estimate"]
    return mean_ns / 1e6


def check_formula_agreement(n: int) -> None:
    """Noise-free, the formula job's readings equal the closed-form NumPy reference's to rounding
    (each side's exact derivatives round differently: a reading may sit one resolution step off)."""
    quiet = params(noise=False)
    ours = imukit_formula_pipeline(n, quiet)
    ref = numpy_formula_pipeline(n, quiet, np.zeros((n, 27)))
    for name, a, b, res in zip(("accel", "gyro", "mag"), ours, ref, (1e-6, 1e-7, 1e-3)):
        diff = np.abs(a - b)
        assert np.all(diff <= res * (1 + 1e-9)), f"formulas, {name}: max difference {diff.max():.3e}"
        assert np.mean(diff > 0) < 1e-2, f"formulas, {name}: {np.mean(diff > 0):.2%} of readings differ"


def check_agreement(n: int) -> None:
    check_formula_agreement(n)
    t, pos, euler = trajectory(n)
    quiet = params(noise=False)
    ours = imukit_pipeline(t, pos, euler, quiet)
    ref = numpy_pipeline(t, pos, euler, quiet, np.zeros((n, 27)))
    for name, a, b, res in zip(("accel", "gyro", "mag"), ours, ref, (1e-6, 1e-7, 1e-3)):
        # Equal to rounding; a reading may sit one resolution step apart where the rounded
        # value lies within rounding error of a half step.
        diff = np.abs(a - b)
        assert np.all(diff <= res * (1 + 1e-9)), f"{name}: max difference {diff.max():.3e}"
        assert np.mean(diff > 0) < 1e-3, f"{name}: {np.mean(diff > 0):.2%} of readings differ"
    # With noise: the drift (readings minus the noise-free ones) has theory's variance in both.
    noisy = params(noise=True)
    ours_n = imukit_pipeline(t, pos, euler, noisy, seed=7)
    ref_n = numpy_pipeline(t, pos, euler, noisy, np.random.default_rng(7).standard_normal((n, 27)))
    for k, name in enumerate(("accelerometer", "gyroscope", "magnetometer")):
        p = noisy[name]
        scale = 1.0 + (TEMPERATURE - 25.0) * np.asarray(p["TemperatureScaleFactor"]) / 100.0
        # Increments of the drift remove the random walk's growth: white + AR(1) bias instability
        # + one random-walk step, each independent.
        var_w = p["NoiseDensity"] ** 2 * FS / 2
        var_bi = p["BiasInstability"] ** 2 / (1 - 0.25)  # stationary AR(1), pole 0.5
        lag1_bi = 0.5 * var_bi
        var_rw = p["RandomWalk"] ** 2 / (FS / 2)
        expected = scale ** 2 * (2 * var_w + 2 * (var_bi - lag1_bi) + var_rw)
        for label, noisy_out, quiet_out in (("imukit", ours_n[k], ours[k]), ("numpy", ref_n[k], ref[k])):
            d = np.diff(noisy_out - quiet_out, axis=0)[n // 10:]
            var = d.var(axis=0)
            # Increments are MA(1)-correlated: allow 8/√n relative (> 5 standard errors).
            assert np.all(np.abs(var / expected - 1) < 8 / np.sqrt(len(d))), f"{name} {label}: {var / expected}"


def best_of(f, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - start)
    return best


# The formula job's two Python sides, each timed alone in a fresh interpreter (`fresh_time`).
FRESH_JOBS = {
    "numpy": lambda n, prm: numpy_formula_pipeline(n, prm, np.random.default_rng(1).standard_normal((n, 27))),
    "imukit": lambda n, prm: imukit_formula_pipeline(n, prm),
    "imukit-every-core": lambda n, prm: imukit_formula_pipeline(n, prm, threads=None),
}


def fresh_time(job: str, n: int, repeat: int, processes: int) -> float:
    """The median, over ``processes`` fresh Python processes, of each one's best of ``repeat``
    runs of the formula job ``job`` (a key of ``FRESH_JOBS``) at ``n`` samples: neither side
    inherits the other's warm caches or the allocator state that earlier work left."""
    times = []
    for _ in range(processes):
        done = subprocess.run([sys.executable, __file__, "--time-one", job, str(n), str(repeat)],
                              check=True, capture_output=True, text=True)
        times.append(float(done.stdout.split()[-1]))
    return statistics.median(times)


def imukit_binary() -> str:
    return os.environ.get("IMUKIT_BIN") or shutil.which("imukit") or str(
        Path(__file__).resolve().parents[1] / "target" / "release" / "imukit")


def cli_formula_time(n, prm, work: Path, ext: str = "csv", threads: Optional[int] = 1, repeat: int = 1) -> float:
    """`imukit simulate` of the formula scenario, readings to a file of format ``ext`` (process
    start and writing included), on ``threads`` (None: every core it may use); the best of
    ``repeat`` fresh processes."""
    spec = work / "formulas.json"
    spec.write_text(json.dumps(formula_scenario(n, prm)))
    out = work / f"formula_imu.{ext}"
    cap = [] if threads is None else ["--threads", str(threads)]
    return best_of(lambda: subprocess.run([imukit_binary(), "simulate", str(spec), "--out", str(out), *cap],
                                          check=True, capture_output=True), repeat)


def cli_time(t, pos, euler, prm, work: Path, repeat: int = 1) -> float:
    """`imukit simulate` on the same samples, from CSV in to CSV out (parsing and writing included)."""
    binary = imukit_binary()
    samples = work / "samples.csv"
    header = "t_s,pos_x_m,pos_y_m,pos_z_m,yaw_rad,pitch_rad,roll_rad"
    np.savetxt(samples, np.column_stack([t, pos, euler]), delimiter=",", header=header, comments="", fmt="%.17g")
    scenario = {
        "rate_hz": FS, "nav_frame": "NED",
        "trajectory": {"type": "samples", "file": str(samples), "order": 2},
        "imu": {"kind": "accel-gyro-mag", "profile": "matlab", "seed": 1, "temperature_c": TEMPERATURE,
                "magnetic_field_ut": MAG_NED.tolist(), **prm},
    }
    spec = work / "scenario.json"
    spec.write_text(json.dumps(scenario))
    out = work / "imu.csv"
    return best_of(lambda: subprocess.run([binary, "simulate", str(spec), "--out", str(out), "--threads", "1"],
                                          check=True, capture_output=True), repeat)


def write_readme(path: Path, lines: list) -> None:
    """The benchmark page: the tables this run printed, and what made them (the one current table;
    history is git's)."""
    import platform

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((l.split(":", 1)[1].strip() for l in f if l.startswith("model name")), cpu)
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    command = "python benches/compare_numpy.py " + " ".join(sys.argv[1:])
    body = (
        "## Speed beside NumPy\n\n"
        f"- machine: {cpu}, {cores} cores, {platform.system()} {platform.release()}, Python {platform.python_version()}\n"
        f"- date: {time.strftime('%Y-%m-%d', time.gmtime())}\n"
        f"- command: `{command}`\n\n"
        "Time ratios NumPy / imukit (> 1: imukit is faster). The criterion benches "
        "(`cargo bench -p imu-benches`) print their own figures.\n\n"
        "```text\n" + "\n".join(lines) + "\n```\n"
    )
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from readme_section import replace_section

    replace_section(path, "compare_numpy", body)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", nargs="+", type=float, default=[1e4, 1e5, 1e6])
    parser.add_argument("--no-cli", action="store_true", help="leave out the CLI column")
    parser.add_argument("--rust", action="store_true",
                        help="also run the Rust criterion bench of the same call and compare at 10⁶")
    parser.add_argument("--time-one", nargs=3, metavar=("JOB", "N", "REPEAT"),
                        help="(used by the script itself) time one side of the formula job in this process "
                             "and print the best of REPEAT runs in seconds")
    parser.add_argument("--write-readme", metavar="PATH",
                        help="also write the tables to PATH (benches/README.md), with the machine, date and command")
    args = parser.parse_args()
    if args.time_one:
        job, n, repeat = args.time_one[0], int(args.time_one[1]), int(args.time_one[2])
        prm = params(noise=True)
        print(best_of(lambda: FRESH_JOBS[job](n, prm), repeat))
        return
    lines: list = []

    def say(line: str) -> None:
        print(line)
        lines.append(line)

    check_agreement(20_000)
    say("agreement: noise-free outputs equal to rounding; drift variances match theory in both")
    prm = params(noise=True)
    say("time ratios, NumPy / imukit (> 1: imukit is faster); one core on both sides. The formula job: each "
          "side in fresh processes (Python: the median of three processes' best times; the CLI: the best of "
          "its processes); 'warm' times both sides in this process, after the agreement check, where NumPy "
          "runs faster at small N (its temporaries' memory is kept, not returned and faulted in again)")
    say(f"{'N':>10} {'formulas, Python':>17} {'(warm)':>7} {'formulas, CLI (CSV)':>20} {'formulas, CLI (Parquet)':>24} "
          f"{'formulas, CLI (.npy)':>20} {'samples, Python':>16} {'samples, CLI (CSV in+out)':>26} {'error model, Python':>20}")
    python_model_s, numpy_model_s = {}, {}
    every_core = {}  # N → (NumPy time, imukit times on every core: Python, CSV, Parquet, .npy)
    with tempfile.TemporaryDirectory() as tmp:
        for size in args.sizes:
            n = int(size)
            t, pos, euler = trajectory(n)
            # Best of seven below 10⁶ samples, where a call or a process start takes milliseconds
            # (with three, one run put Python at 3.3× NumPy at 10⁴ where seven calls gave 4.4×),
            # of three at 10⁶; every side, NumPy's included, gets the same number of tries.
            repeat = 7 if n < 1_000_000 else 3 if n == 1_000_000 else 1
            # The measure: each side of the formula job alone in fresh processes, the
            # median of three (one at 10⁷, where NumPy's run takes seconds).
            processes = 3 if n < 10_000_000 else 1
            t_fnp = fresh_time("numpy", n, repeat, processes)
            t_fpy = fresh_time("imukit", n, repeat, processes)
            warm_np = best_of(lambda: FRESH_JOBS["numpy"](n, prm), repeat)
            warm_py = best_of(lambda: FRESH_JOBS["imukit"](n, prm), repeat)
            fcli = "" if args.no_cli else f"{t_fnp / cli_formula_time(n, prm, Path(tmp), repeat=repeat):>20.2f}"
            fpq = "" if args.no_cli else f"{t_fnp / cli_formula_time(n, prm, Path(tmp), 'parquet', repeat=repeat):>24.2f}"
            fnpy = "" if args.no_cli else f"{t_fnp / cli_formula_time(n, prm, Path(tmp), 'npy', repeat=repeat):>20.2f}"
            t_np = best_of(lambda: numpy_pipeline(t, pos, euler, prm,
                                                  np.random.default_rng(1).standard_normal((n, 27))), repeat)
            t_py = best_of(lambda: imukit_pipeline(t, pos, euler, prm), repeat)
            cli = "" if args.no_cli else f"{t_np / cli_time(t, pos, euler, prm, Path(tmp), repeat):>26.2f}"
            ours_in, ref_in = model_inputs(t, pos, euler)
            imu = imukit.ImuSensor("accel-gyro-mag", reference_frame="NED", sample_rate=FS,
                                   temperature=TEMPERATURE, seed=1, magnetic_field=MAG_NED, **prm)
            out = np.empty((n, 9))
            imu(*ours_in, out=out)  # the buffer's pages are touched once, as in a chunked run
            t_model_np = best_of(lambda: numpy_model(*ref_in, prm), repeat)
            t_model_py = best_of(lambda: imu(*ours_in, out=out), repeat)
            python_model_s[n], numpy_model_s[n] = t_model_py, t_model_np
            say(f"{n:>10} {t_fnp / t_fpy:>17.2f} {warm_np / warm_py:>7.2f} {fcli:>20} {fpq:>24} {fnpy:>20} {t_np / t_py:>16.2f} {cli:>26} "
                  f"{t_model_np / t_model_py:>20.2f}")
            every_core[n] = (t_fnp, fresh_time("imukit-every-core", n, repeat, processes),
                             *(None if args.no_cli else cli_formula_time(n, prm, Path(tmp), ext, threads=None,
                                                                         repeat=repeat)
                               for ext in ("csv", "parquet", "npy")))
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    say(f"the formula job with imukit on every core it may use ({cores} here: one run makes its truth, its "
          "readings and its file a chunk apart on up to three threads, same numbers); NumPy as above, "
          "single-threaded")
    say(f"{'N':>10} {'formulas, Python':>17} {'formulas, CLI (CSV)':>20} {'formulas, CLI (Parquet)':>24} "
          f"{'formulas, CLI (.npy)':>20}")
    for n, (t_fnp, *ours) in every_core.items():
        cells = ["" if t is None else f"{t_fnp / t:.2f}" for t in ours]
        say(f"{n:>10} {cells[0]:>17} {cells[1]:>20} {cells[2]:>24} {cells[3]:>20}")
    if args.rust:
        rust = rust_matlab_call_ns_per_sample()
        n = 1_000_000
        if rust is None:
            say("Rust comparison left out: cargo not found")
        else:
            if n not in python_model_s:
                t, pos, euler = trajectory(n)
                ours_in, ref_in = model_inputs(t, pos, euler)
                imu = imukit.ImuSensor("accel-gyro-mag", reference_frame="NED", sample_rate=FS,
                                       temperature=TEMPERATURE, seed=1, magnetic_field=MAG_NED, **prm)
                out = np.empty((n, 9))
                imu(*ours_in, out=out)
                python_model_s[n] = best_of(lambda: imu(*ours_in, out=out), 3)
                numpy_model_s[n] = best_of(lambda: numpy_model(*ref_in, prm), 3)
            py_ns = python_model_s[n] / n * 1e9
            np_ns = numpy_model_s[n] / n * 1e9
            say(f"error model at 10⁶ samples: Python call / Rust (criterion matlab_call) = "
                  f"{py_ns / rust:.2f} (target ≤ 1.20); NumPy / Rust = {np_ns / rust:.2f} (target ≥ 5)")

    if args.write_readme:
        write_readme(Path(args.write_readme), lines)

if __name__ == "__main__":
    main()
