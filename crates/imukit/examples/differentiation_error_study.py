"""The MATLAB trajectory tool's error study (its Figure 3): numeric vs exact differentiation on the tilted circle.

The tool differentiates sampled arrays with MATLAB ``gradient`` at 200 Hz and compares with its
symbolic result. imukit reproduces that with ``order=2`` and shows its default (``order=6``).
Errors are printed relative to each quantity's largest exact magnitude, and, as the tool plots
them, relative to max |v| in percent.

Run: python examples/differentiation_error_study.py [--figures DIR]   (the figure needs matplotlib)
"""
import argparse
from pathlib import Path

import numpy as np

import imukit

F = {"f": 1.0}
POS = ["0.8*cos(2*pi*f*t)", "0.8*sin(2*pi*f*t)", "0.3*cos(2*pi*f*t)"]
YAW = "2*pi*f*t + pi/2"
PITCH = "asin(3*sqrt(2)*sin(2*pi*f*t)/sqrt(137 - 9*cos(4*pi*f*t)))"
QUANTITIES = [("v", "vel_{}_m_s"), ("a", "acc_{}_m_s2"), ("omega", "omega_{}_rad_s"), ("alpha", "alpha_{}_rad_s2")]


def stack(table, pattern):
    return np.column_stack([table[pattern.format(a)] for a in "xyz"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", default="imukit-figures", help="folder for the figures (default: %(default)s)")
    args = parser.parse_args()

    t = np.arange(0, 1.0 + 1e-12, 0.005)  # the tool's t_start:t_step:t_stop
    exact = imukit.truth_from_expressions(t, POS, yaw_rad=YAW, pitch_rad=PITCH, constants=F)
    p = stack(exact, "pos_{}_m")
    euler = np.column_stack([exact["yaw_rad"], exact["pitch_rad"], exact["roll_rad"]])
    v_max = np.max(np.abs(stack(exact, "vel_{}_m_s")))

    print("tilted circle, 200 Hz, errors of sampled input against exact derivatives")
    print(f"{'quantity':<8} {'order 2 (MATLAB gradient)':>27} {'order 6 (imukit default)':>25} {'tool scale, order 2':>21}")
    errors = {}
    for order in (2, 6):
        est = imukit.truth_from_samples(t, p, euler_rad=euler, order=order)
        for name, pattern in QUANTITIES:
            ex, es = stack(exact, pattern), stack(est, pattern)
            errors[(order, name)] = np.abs(es - ex)
    for name, pattern in QUANTITIES:
        scale = np.max(np.abs(stack(exact, pattern)))
        e2, e6 = (np.max(errors[(o, name)]) / scale for o in (2, 6))
        tool_pct = 100 * np.max(errors[(2, name)]) / v_max
        print(f"{name:<8} {e2:>27.3e} {e6:>25.3e} {tool_pct:>20.2f}%")
    interior = {n: np.max(errors[(2, n)][2:-2]) / np.max(np.abs(stack(exact, p_))) for n, p_ in QUANTITIES}
    print("order 2 without the two end samples at each side: "
          + ", ".join(f"{n} {e:.2e}" for n, e in interior.items()))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
    for ax, (name, _) in zip(axes.flat, QUANTITIES):
        for order, style in ((2, "-"), (6, "--")):
            ax.semilogy(t, np.maximum(errors[(order, name)], 1e-18), style)
        ax.set_title(f"|error| of {name} (solid: order 2, dashed: order 6)")
        ax.set_xlabel("t in s")
    fig.tight_layout()
    out = Path(args.figures)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "differentiation_error_study.png", dpi=80)
    print(f"figure differentiation_error_study.png written to {out}")


if __name__ == "__main__":
    main()
