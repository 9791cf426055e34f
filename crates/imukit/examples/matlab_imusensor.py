"""MATLAB's imuSensor examples, ported line by line to imukit.ImuSensor.

Run: python examples/matlab_imusensor.py [--figures DIR]
Figure (matplotlib): the rotating platform's accelerometer and magnetometer readings.
"""
import argparse
import math
from pathlib import Path

import numpy as np

import imukit
import imukit.plot


def stationary():
    # IMU = imuSensor('accel-gyro-mag','SampleRate',100); [a,g,m] = IMU(zeros(N,3), zeros(N,3), quaternion.ones(N,1))
    imu = imukit.ImuSensor("accel-gyro-mag", sample_rate=100)
    n = 1000
    accel, gyro, mag = imu(np.zeros((n, 3)), np.zeros((n, 3)), np.tile([1.0, 0, 0, 0], (n, 1)))
    print("stationary: accel", accel[0], "gyro", gyro[0], "mag", mag[0])


def rotating_platform(figures: Path):
    # kinematicTrajectory: 360° in 4 s then 360° in 2 s about z, NED, 100 Hz
    fs = 100
    n = 6 * fs
    t = np.arange(n) / fs
    rate = np.where(t < 4, 2 * math.pi / 4, 2 * math.pi / 2)
    yaw = np.concatenate([[0.0], np.cumsum(rate[:-1]) / fs])
    q = imukit.euler_to_quaternion(np.column_stack([yaw, np.zeros(n), np.zeros(n)]))
    ang_vel = np.column_stack([np.zeros(n), np.zeros(n), rate])
    imu = imukit.ImuSensor(
        "accel-mag", sample_rate=fs, seed=67,
        accelerometer=dict(MeasurementRange=19.62, Resolution=0.0023936, TemperatureScaleFactor=0.008,
                           ConstantBias=0.1962, TemperatureBias=0.0014715, NoiseDensity=0.0012361),
        magnetometer=dict(MeasurementRange=1200, Resolution=0.1, TemperatureScaleFactor=0.1, ConstantBias=1,
                          TemperatureBias=[0.8, 0.8, 2.4], NoiseDensity=[0.06, 0.06, 0.09]),
    )
    accel, mag = imu(np.zeros((n, 3)), ang_vel, q)
    heading = np.degrees(np.unwrap(np.arctan2(-mag[:, 1], mag[:, 0])))
    print(f"rotating platform: heading from the magnetometer went from {heading[0]:.1f}° to {heading[-1]:.1f}°")

    import matplotlib

    matplotlib.use("Agg")

    columns = ["t_s", *(f"accel_{a}_m_s2" for a in "xyz"), *(f"mag_{a}_ut" for a in "xyz")]
    readings = imukit.Table(columns, np.column_stack([t, accel, mag]))
    figures.mkdir(parents=True, exist_ok=True)
    imukit.plot.figure(readings, labels=["imuSensor"]).savefig(figures / "matlab_rotating_platform.png", dpi=80)
    print(f"figure matlab_rotating_platform.png written to {figures}")


def spec_sheet_accelerometer():
    imu = imukit.ImuSensor(
        "accel-gyro", sample_rate=100, temperature=35,
        accelerometer=dict(MeasurementRange=19.62, Resolution=0.00059875, ConstantBias=0.4905, AxesMisalignment=2,
                           NoiseDensity=0.003924, BiasInstability=0, TemperatureBias=[0.34335, 0.34335, 0.5886],
                           TemperatureScaleFactor=0.02),
    )
    accel, _ = imu(np.zeros((1000, 3)), np.zeros((1000, 3)), np.tile([1.0, 0, 0, 0], (1000, 1)))
    print("spec-sheet accelerometer at 35 °C: mean", accel.mean(axis=0), "std", accel.std(axis=0))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", default="imukit-figures", help="folder for the figures (default: %(default)s)")
    args = parser.parse_args()
    stationary()
    rotating_platform(Path(args.figures))
    spec_sheet_accelerometer()
