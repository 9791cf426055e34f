#!/usr/bin/env python3
"""Whether the fusion filter's uncertainty holds when the fixes' errors are correlated in time.

`examples/car_tunnel.toml` without its outage and odometer, its receiver's MATLAB `DecayFactor`
set to each value asked for (0: white fixes, what the filter assumes; 0.99 and 0.999: a slow
drift, as receivers make), simulated `--runs` times (seeded runs 0…) and fused with the
scenario's own model — the fixes' errors as filter states when correlated — filtered and
smoothed (`--sensor-errors`: with the part's scale-factor and misalignment states too). Printed per decay factor: the position NEES (3
degrees of freedom) averaged over the runs and then over the last three quarters of the drive,
beside the two-sided 95 % bounds of such an average (χ² with 3·runs degrees of freedom over
runs), and the share of rows whose north and east errors both lie within 3σ.

    python benches/gnss_consistency.py --runs 50 --decay 0 0.99 0.999
"""
from __future__ import annotations

import argparse
import copy
import tomllib
from pathlib import Path

import numpy as np
from scipy.stats import chi2

import imukit

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=50)
    parser.add_argument("--decay", type=float, nargs="+", default=[0.0, 0.99, 0.999])
    parser.add_argument("--sensor-errors", action="store_true",
                        help="the filter also estimates the part's scale factors and misalignment (36 states + 3)")
    args = parser.parse_args()
    base = tomllib.loads((ROOT / "examples" / "car_tunnel.toml").read_text(encoding="utf-8"))
    base.pop("odometer", None)
    base["gnss"].pop("outages", None)
    lo, hi = (chi2.ppf(p, 3 * args.runs) / args.runs for p in (0.025, 0.975))
    print(f"position NEES, mean of {args.runs} runs over the last 3/4 of the drive; 95 % bounds "
          f"[{lo:.2f}, {hi:.2f}]")
    for k in args.decay:
        scenario = copy.deepcopy(base)
        scenario["gnss"]["decay_factor"] = k
        nees = {False: [], True: []}
        inside = {False: [], True: []}
        for run in range(args.runs):
            sim = imukit.simulate(scenario, run=run)
            for smooth in (False, True):
                nav = imukit.fuse(sim.imu, sim.gnss, initial=sim.truth, scenario=scenario, smooth=smooth,
                                   sensor_errors=args.sensor_errors)
                e = np.column_stack([nav[f"pos_{a}_m"] - np.interp(nav["t_s"], sim.truth["t_s"],
                                                                   sim.truth[f"pos_{a}_m"]) for a in "xyz"])
                s = np.column_stack([nav[f"pos_{a}_sigma_m"] for a in "xyz"])
                late = slice(len(e) // 4, None)
                nees[smooth].append(((e / s) ** 2).sum(axis=1)[late])
                inside[smooth].append(np.all(np.abs(e[late, :2]) < 3 * s[late, :2], axis=1).mean())
        cells = [f"{'smoothed' if smooth else 'filtered'} NEES {np.mean(np.mean(nees[smooth], axis=0)):.2f}, "
                 f"N and E within 3σ {100 * np.mean(inside[smooth]):.0f} %" for smooth in (False, True)]
        print(f"decay factor {k}: " + "; ".join(cells))


if __name__ == "__main__":
    main()
