"""Closing the loop: exact truth → ideal IMU → strapdown → errors, on the figure-8
(1 kHz, 30 s, reference point), with docs/models.md §4's coning/sculling scheme (second order) and the
fourth-order RK4 scheme.

Run: python examples/navigation_round_trip.py [--figures DIR]
Figures (matplotlib): truth against both estimates, and the errors of each scheme.
"""
import argparse
from pathlib import Path

import imukit
import imukit.plot


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", default="imukit-figures", help="folder for the figures (default: %(default)s)")
    args = parser.parse_args()
    sim = imukit.simulate({
        "rate_hz": 1000.0, "duration_s": 30.0,
        "trajectory": {"type": "builtin", "name": "figure8"},
        "imu": {"lever_arm_m": [0.0, 0.0, 0.0], "kind": "accel-gyro"},
    })
    print("figure-8, 30 s at 1 kHz, ideal IMU → strapdown")
    navs, errors = {}, {}
    for scheme in ("coning", "rk4"):
        navs[scheme] = imukit.strapdown(sim.imu, initial=sim.truth, scheme=scheme)
        errors[scheme], s = imukit.compare(sim.truth, navs[scheme])
        print(f"  {scheme:<7} final position error {s['position_final_m']:.3e} m, "
              f"attitude error {s['attitude_final_rad']:.3e} rad")

    import matplotlib

    matplotlib.use("Agg")

    out = Path(args.figures)
    out.mkdir(parents=True, exist_ok=True)
    imukit.plot.figure(sim.truth, *navs.values(), labels=["truth", *navs]).savefig(out / "round_trip.png", dpi=80)
    imukit.plot.figure(*errors.values(), labels=list(errors)).savefig(out / "round_trip_errors.png", dpi=80)
    print(f"figures round_trip.png and round_trip_errors.png written to {out}")


if __name__ == "__main__":
    main()
