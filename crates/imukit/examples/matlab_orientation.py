"""The orientation examples of MATLAB's imuSensor page, end to end with imukit: simulated
readings fed to ecompass and to the imufilter Kalman filter, compared with truth by quaternion
distance.

1. Stationary accelerometer-gyroscope-magnetometer: ecompass gives the level, north-facing
   orientation.
2. The platform turning 360° in 4 s, then 360° in 2 s (NED, 100 Hz) → ecompass → Euler angles,
   with an ideal and with a realistic accelerometer and magnetometer (the page's parameters).
3. A tilting IMU (yaw 120° in 2 s, pitch 60° in 1 s, roll 30° in ½ s, back again, then the
   first three as one single-axis rotation; the page loads this motion from y120p60r30.mat,
   rebuilt here with smooth angle profiles at 200 Hz) → imufilter: ideal readings with the
   default filter, realistic readings (the page's parameters) with the default filter and with
   the page's tuned settings; the quaternion distance to truth of both, RMS and maximum.

Run: python examples/matlab_orientation.py [--figures DIR]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import imukit

MAG_NED = np.array([27.5550, -2.4169, -16.0849])
DECLINATION = math.atan2(MAG_NED[1], MAG_NED[0])


def stationary() -> None:
    imu = imukit.ImuSensor("accel-gyro-mag", sample_rate=100)
    n = 1000
    accel, gyro, mag = imu(np.zeros((n, 3)), np.zeros((n, 3)), np.tile([1.0, 0, 0, 0], (n, 1)))
    q = imukit.ecompass(accel, mag, conventions="matlab")
    euler = np.degrees(imukit.quaternion_to_euler(q))
    print(f"stationary: ecompass yaw {euler[0, 0]:.3f}° (magnetic north is {math.degrees(DECLINATION):.3f}° "
          f"from true north), pitch {euler[0, 1]:.3f}°, roll {euler[0, 2]:.3f}°")


def platform(realistic: bool):
    """The turning platform's truth, readings and ecompass orientation."""
    fs = 100
    n = 6 * fs
    t = np.arange(n) / fs
    rate = np.where(t < 4, 2 * math.pi / 4, 2 * math.pi / 2)
    yaw = np.concatenate([[0.0], np.cumsum(rate[:-1]) / fs])
    q_true = imukit.euler_to_quaternion(np.column_stack([yaw, np.zeros(n), np.zeros(n)]))
    ang_vel = np.column_stack([np.zeros(n), np.zeros(n), rate])
    params = {}
    if realistic:
        params = dict(
            accelerometer=dict(MeasurementRange=19.62, Resolution=0.0023936, TemperatureScaleFactor=0.008,
                               ConstantBias=0.1962, TemperatureBias=0.0014715, NoiseDensity=0.0012361),
            magnetometer=dict(MeasurementRange=1200, Resolution=0.1, TemperatureScaleFactor=0.1, ConstantBias=1,
                              TemperatureBias=[0.8, 0.8, 2.4], NoiseDensity=[0.06, 0.06, 0.09]))
    imu = imukit.ImuSensor("accel-mag", sample_rate=fs, seed=67, **params)
    accel, mag = imu(np.zeros((n, 3)), ang_vel, q_true)
    q = imukit.ecompass(accel, mag, conventions="matlab")
    # ecompass measures yaw from magnetic north: compare with the truth turned by the declination.
    q_magnetic = imukit.euler_to_quaternion(np.column_stack([yaw - DECLINATION, np.zeros(n), np.zeros(n)]))
    d = np.degrees(imukit.quaternion_distance(q, q_magnetic))
    label = "realistic" if realistic else "ideal"
    print(f"platform, {label} accelerometer and magnetometer → ecompass: quaternion distance to truth "
          f"(from magnetic north) RMS {np.sqrt(np.mean(d ** 2)):.3g}°, max {d.max():.3g}°")
    return t, q, d


def tilting_motion(fs: float = 200.0):
    """Orientation, nav-frame angular velocity and times of the y120p60r30 motion (NED)."""
    stages = [("yaw", 120, 2.0), ("pitch", 60, 1.0), ("roll", 30, 0.5), ("roll", -30, 0.5),
              ("pitch", -60, 1.0), ("yaw", -120, 2.0)]
    seconds = sum(s[2] for s in stages) + 2.0
    t = np.arange(int(round(seconds * fs)) + 1) / fs
    euler = np.zeros((t.size, 3))  # yaw, pitch, roll
    column = {"yaw": 0, "pitch": 1, "roll": 2}
    start = 0.0
    for axis, degrees, length in stages:
        tau = np.clip((t - start) / length, 0.0, 1.0)
        euler[:, column[axis]] += math.radians(degrees) * (1 - np.cos(math.pi * tau)) / 2
        start += length
    q = imukit.euler_to_quaternion(euler)
    # Last stage: the first three rotations at once, as one rotation about a fixed axis.
    target = imukit.euler_to_quaternion([[math.radians(120), math.radians(60), math.radians(30)]])[0]
    angle = 2 * math.acos(min(1.0, target[0]))
    axis = target[1:] / np.linalg.norm(target[1:])
    tau = np.clip((t - start) / 2.0, 0.0, 1.0)
    half = angle * (1 - np.cos(math.pi * tau)) / 4
    last = np.column_stack([np.cos(half), np.outer(np.sin(half), axis)])
    q = np.where((t >= start)[:, None], last, q)
    truth = imukit.truth_from_samples(t, np.zeros((t.size, 3)), quaternion=q, nav_frame="NED")
    q_true = truth.values[:, 10:14]
    omega_b = truth.values[:, 17:20]
    omega_n = np.einsum("nij,nj->ni", imukit.quaternion_to_dcm(q_true), omega_b)
    return t, np.ascontiguousarray(q_true), np.ascontiguousarray(omega_n), fs


REALISTIC_ACCEL = dict(MeasurementRange=19.62, Resolution=0.00059875, ConstantBias=0.4905, AxesMisalignment=2,
                       NoiseDensity=0.003924, BiasInstability=0, TemperatureBias=[0.34335, 0.34335, 0.5886],
                       TemperatureScaleFactor=0.02)
REALISTIC_GYRO = dict(MeasurementRange=4.3633, Resolution=0.00013323, AxesMisalignment=2, NoiseDensity=8.7266e-05,
                      TemperatureBias=0.34907, TemperatureScaleFactor=0.02, AccelerationBias=0.00017809,
                      ConstantBias=[0.3491, 0.5, 0])
TUNED = dict(gyroscope_noise=7.6154e-7, accelerometer_noise=0.0015398, gyroscope_drift_noise=3.0462e-12,
             linear_acceleration_noise=0.00096236,
             initial_process_noise=imukit.ImuFilter.DEFAULT_INITIAL_PROCESS_NOISE * 10)


def imufilter_study(seed: int = 67) -> dict:
    """Quaternion distances (degrees) of the three imufilter runs on the tilting motion."""
    t, q_true, omega_n, fs = tilting_motion()
    acc = np.zeros_like(omega_n)
    out = {"t": t, "q_true": q_true}
    ideal = imukit.ImuSensor("accel-gyro", sample_rate=fs)
    a, g = ideal(acc, omega_n, q_true)
    out["ideal"] = imukit.ImuFilter(sample_rate=fs, conventions="matlab")(a, g)
    real = imukit.ImuSensor("accel-gyro", sample_rate=fs, seed=seed, accelerometer=REALISTIC_ACCEL,
                            gyroscope=REALISTIC_GYRO)
    a, g = real(acc, omega_n, q_true)
    out["default"] = imukit.ImuFilter(sample_rate=fs, conventions="matlab")(a, g)
    out["tuned"] = imukit.ImuFilter(sample_rate=fs, **TUNED, conventions="matlab")(a, g)
    for k in ("ideal", "default", "tuned"):
        out[f"{k}_distance_deg"] = np.degrees(imukit.quaternion_distance(q_true, out[k]))
    return out


def figures(folder: Path, platform_runs, study) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for ax, (label, (t, q, _)) in zip(axes, platform_runs.items()):
        ax.plot(t, np.degrees(imukit.quaternion_to_euler(q)), label=["Z-axis", "Y-axis", "X-axis"])
        ax.set(title=f"ecompass orientation, {label} readings", ylabel="rotation (deg)")
        ax.legend(loc="upper right")
    axes[-1].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(folder / "ecompass_platform.png", dpi=80)
    fig, axes = plt.subplots(4, 1, figsize=(7, 11), sharex=True)
    titles = {"ideal": "ideal IMU data, default imufilter", "default": "realistic IMU data, default imufilter",
              "tuned": "realistic IMU data, tuned imufilter"}
    for ax, (key, title) in zip(axes, titles.items()):
        ax.plot(study["t"], np.degrees(imukit.quaternion_to_euler(study[key])), label=["Z-axis", "Y-axis", "X-axis"])
        ax.set(title=f"Orientation estimation — {title}", ylabel="rotation (deg)")
        ax.legend(loc="upper right")
    axes[3].plot(study["t"], study["default_distance_deg"], label="realistic IMU data, default imufilter")
    axes[3].plot(study["t"], study["tuned_distance_deg"], label="realistic IMU data, tuned imufilter")
    axes[3].set(title="Quaternion distance from true orientation", xlabel="time (s)",
                ylabel="quaternion distance (deg)")
    axes[3].legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(folder / "imufilter_tilt.png", dpi=80)
    plt.close("all")
    print(f"figures ecompass_platform.png and imufilter_tilt.png written to {folder}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, default=Path("imukit-figures"))
    args = parser.parse_args()
    stationary()
    runs = {"ideal": platform(False), "realistic": platform(True)}
    study = imufilter_study()
    for key in ("ideal", "default", "tuned"):
        d = study[f"{key}_distance_deg"]
        print(f"imufilter, {key:>7}: quaternion distance to truth RMS {np.sqrt(np.mean(d ** 2)):.3g}°, "
              f"max {d.max():.3g}°")
    figures(args.figures, runs, study)


if __name__ == "__main__":
    main()
