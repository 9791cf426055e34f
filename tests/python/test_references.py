"""References as users have them: latitude, longitude and height (or ECEF), at their own rate,
with or without velocity and attitude, work as ``--init`` and in ``compare``, which reports
errors north, east and down at the reference point."""
import json
import subprocess

import numpy as np
import pytest

import imukit
from test_cli_vs_python import ROOT, imukit_bin

# WGS-84: the meridian radius of curvature M(φ), for a displacement of 1 m north.
A, E2 = 6378137.0, 6.69437999014e-3


def meridian_radius(lat):
    return A * (1 - E2) / (1 - E2 * np.sin(lat) ** 2) ** 1.5


def run(*args):
    done = subprocess.run([imukit_bin(), *map(str, args)], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def write_reference(path, columns, description=None):
    """A reference CSV as another program writes it (17 significant digits), with imukit's
    description line only when given."""
    import pandas as pd
    text = pd.DataFrame(columns).to_csv(index=False, float_format="%.17g")
    if description is not None:
        text = "# imukit: " + json.dumps(description) + "\n" + text
    path.write_text(text)


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    """Ten minutes of flight on the WGS-84 Earth (NED), 60 s kept, and its strapdown run."""
    d = tmp_path_factory.mktemp("flight")
    text = (ROOT / "examples" / "earth_flight.toml").read_text().replace("duration_s = 600.0", "duration_s = 60.0")
    (d / "f.toml").write_text(text)
    assert run("simulate", d / "f.toml", "--out", d / "imu.csv", "--truth", d / "truth.csv")[0] == 0
    assert run("integrate", d / "imu.csv", "--init", d / "truth.csv", "--out", d / "nav.csv")[0] == 0
    return d, imukit.read(d / "truth.csv"), imukit.read(d / "nav.csv")


def test_a_reference_displaced_north_east_and_down_gives_those_errors(flight, tmp_path):
    d, truth, nav = flight
    # The reference at a third of the rate, 1 m north, 2 m east and 3 m below the truth: the
    # estimate (the truth to 1e-7 m) is then 1 m south, 2 m west and 3 m above it.
    k = np.unique(np.r_[0:len(truth):3, len(truth) - 1])
    lat, lon, h = truth["lat_rad"][k], truth["lon_rad"][k], truth["height_m"][k]
    parallel = (A / np.sqrt(1 - E2 * np.sin(lat) ** 2) + h) * np.cos(lat)  # the parallel's radius
    moved = {"lat_deg": np.degrees(lat + 1.0 / (meridian_radius(lat) + h)),
             "lon_deg": np.degrees(lon + 2.0 / parallel), "height_m": h - 3.0}
    write_reference(tmp_path / "llh.csv", {"t_s": truth["t_s"][k], **moved})
    code, text = run("compare", tmp_path / "llh.csv", d / "nav.csv", "--out", tmp_path / "err.csv")
    assert code == 0, text
    err = imukit.read(tmp_path / "err.csv")
    assert err.columns == ("t_s", "pos_err_n_m", "pos_err_e_m", "pos_err_d_m", "pos_err_m")
    assert "velocity" not in text and "attitude" not in text
    # At the reference's own times the offset comes back to the accuracy of the radii
    # (h ≪ R: the displacement on the ellipsoid's curvature, 1e-6 m) …
    on = np.isin(err["t_s"], truth["t_s"][k])
    for c, want in (("pos_err_n_m", -1.0), ("pos_err_e_m", -2.0), ("pos_err_d_m", -3.0)):
        assert np.abs(err[c][on] - want).max() < 1e-5, c
    # … and between them the linear interpolation of a turning flight's positions errs by
    # ≤ a·Δt²/8 (a ≈ 6 m/s², Δt = 0.03 s: 0.7 mm).
    assert np.abs(err["pos_err_m"] - np.sqrt(14.0)).max() < 1e-3
    # The same reference as ECEF points, and in degrees or radians: the same errors.
    g = [imukit.read(tmp_path / "llh.csv")[c] for c in ("lat_deg", "lon_deg", "height_m")]
    lat_r, lon_r = np.radians(g[0]), np.radians(g[1])
    n = A / np.sqrt(1 - E2 * np.sin(lat_r) ** 2)
    ecef = {"ecef_x_m": (n + g[2]) * np.cos(lat_r) * np.cos(lon_r), "ecef_y_m": (n + g[2]) * np.cos(lat_r) * np.sin(lon_r),
            "ecef_z_m": (n * (1 - E2) + g[2]) * np.sin(lat_r)}
    write_reference(tmp_path / "ecef.csv", {"t_s": truth["t_s"][k], **ecef})
    assert run("compare", tmp_path / "ecef.csv", d / "nav.csv", "--out", tmp_path / "err_ecef.csv")[0] == 0
    assert np.abs(imukit.read(tmp_path / "err_ecef.csv").values - err.values).max() < 1e-6


def test_a_geodetic_reference_with_attitude_and_velocity_starts_a_run_as_the_truth_does(flight, tmp_path):
    d, truth, nav = flight
    # Latitude, longitude, height, north-east-down velocity and the attitude, in NED as the
    # reference's description says.
    columns = {"t_s": truth["t_s"], "lat_rad": truth["lat_rad"], "lon_rad": truth["lon_rad"],
               "height_m": truth["height_m"], "vel_n_m_s": truth["vel_x_m_s"],
               "vel_e_m_s": truth["vel_y_m_s"], "vel_d_m_s": truth["vel_z_m_s"],
               **{c: truth[c] for c in ("q_w", "q_x", "q_y", "q_z")}}
    write_reference(tmp_path / "ref.csv", columns, {"nav_frame": "NED"})
    code, text = run("integrate", d / "imu.csv", "--init", tmp_path / "ref.csv", "--out", tmp_path / "nav.csv")
    assert code == 0, text
    ours = imukit.read(tmp_path / "nav.csv")
    assert np.abs(ours["lat_rad"] - nav["lat_rad"]).max() * A < 1e-6
    assert np.abs(ours["height_m"] - nav["height_m"]).max() < 1e-6
    # Compared with it: velocity north, east, down and the attitude too, all at rounding.
    code, text = run("compare", tmp_path / "ref.csv", tmp_path / "nav.csv", "--out", tmp_path / "err.csv")
    assert code == 0, text
    err = imukit.read(tmp_path / "err.csv")
    assert err.columns[5:] == ("vel_err_n_m_s", "vel_err_e_m_s", "vel_err_d_m_s", "att_err_rad")
    assert err["pos_err_m"].max() < 1e-6 and np.abs(err.values[:, 5:8]).max() < 1e-8
    assert err["att_err_rad"].max() < 1e-9


def test_a_position_only_reference_needs_the_attitude_said_and_the_earth(flight, tmp_path):
    d, truth, _ = flight
    write_reference(tmp_path / "ref.csv", {"t_s": truth["t_s"], "lat_rad": truth["lat_rad"],
                                           "lon_rad": truth["lon_rad"], "height_m": truth["height_m"]})
    code, text = run("integrate", d / "imu.csv", "--init", tmp_path / "ref.csv", "--out", tmp_path / "nav.csv")
    assert code == 65 and "gives no attitude" in text and "--euler0-rad" in text, text
    assert not (tmp_path / "nav.csv").exists()
    e = truth.values[0, [truth.columns.index(c) for c in ("yaw_rad", "pitch_rad", "roll_rad")]]
    code, text = run("integrate", d / "imu.csv", "--init", tmp_path / "ref.csv", "--euler0-rad", *e,
                     "--out", tmp_path / "nav.csv")
    assert code == 0, text
    # Its velocity comes from the first two positions (10 ms apart, the flight at 110 m/s):
    # good to the acceleration's a·Δt/2, so the run stays within metres of the truth in 60 s.
    code, text = run("compare", tmp_path / "ref.csv", tmp_path / "nav.csv", "--out", tmp_path / "err.csv")
    assert code == 0, text
    assert imukit.read(tmp_path / "err.csv")["pos_err_m"].max() < 5.0
    # A reference on the Earth does not start a run on the flat one.
    code, text = run("integrate", d / "imu.csv", "--init", tmp_path / "ref.csv", "--euler0-rad", *e,
                     "--earth", "flat", "--nav-frame", "NED", "--out", tmp_path / "flat.csv")
    assert code == 65, text
    # fuse names its own way to the attitude.
    code, text = run("fuse", d / "imu.csv", d / "imu.csv", "--init", tmp_path / "ref.csv", "--imu", "stim300",
                     "--out", tmp_path / "fused.csv")
    assert code == 65 and "--align" in text, text
