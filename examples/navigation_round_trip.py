"""Closing the loop: exact truth → ideal IMU → strapdown → errors, on the seed's figure-8
(1 kHz, 30 s, reference point), with DESIGN §6's coning/sculling scheme (second order) and the
fourth-order RK4 scheme.

Run: python examples/navigation_round_trip.py
"""
import imukit


def main():
    sim = imukit.simulate({
        "rate_hz": 1000.0, "duration_s": 30.0,
        "trajectory": {"type": "builtin", "name": "figure8"},
        "imu": {"lever_arm_m": [0.0, 0.0, 0.0], "kind": "accel-gyro"},
    })
    print("figure-8, 30 s at 1 kHz, ideal IMU → strapdown")
    for scheme in ("coning", "rk4"):
        nav = imukit.strapdown(sim.imu, initial=sim.truth, scheme=scheme)
        _, s = imukit.compare(sim.truth, nav)
        print(f"  {scheme:<7} final position error {s['position_final_m']:.3e} m, "
              f"attitude error {s['attitude_final_rad']:.3e} rad")


if __name__ == "__main__":
    main()
