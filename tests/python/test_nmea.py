"""NMEA 0183 logs (GGA, RMC, VTG) read as GNSS fixes by ``imukit.read`` and by ``imukit fuse``:
a simulated drive's fixes written as a receiver writes them read back to the log's resolution,
fused as the CSV fixes are; a bad checksum is refused by file and line."""
import subprocess

import numpy as np

import imukit
from test_cli_vs_python import ROOT, imukit_bin

SEPARATION_M = 47.0  # the geoid above the ellipsoid, as GGA gives it
KNOT_M_S = 1852.0 / 3600.0


def checksum(body):
    total = 0
    for b in body.encode():
        total ^= b
    return f"${body}*{total:02X}"


def degrees_minutes(angle_deg, positive, negative, width):
    hemisphere = positive if angle_deg >= 0 else negative
    a = abs(angle_deg)
    whole = int(a)
    return f"{whole:0{width}d}{(a - whole) * 60:012.9f}", hemisphere


def nmea_lines(fixes):
    """GGA and RMC of each fix (time of day = t_s from midnight), and a GSV to skip."""
    lines = [checksum("GPGSV,1,1,01,10,63,137,17")]
    for t, lat, lon, h, vn, ve in fixes:
        hh, rest = divmod(t, 3600.0)
        mm, ss = divmod(rest, 60.0)
        time = f"{int(hh):02d}{int(mm):02d}{ss:05.2f}"
        la, ns = degrees_minutes(np.degrees(lat), "N", "S", 2)
        lo, ew = degrees_minutes(np.degrees(lon), "E", "W", 3)
        lines.append(checksum(f"GPGGA,{time},{la},{ns},{lo},{ew},1,10,0.8,{h - SEPARATION_M:.4f},M,{SEPARATION_M},M,,"))
        speed = np.hypot(vn, ve) / KNOT_M_S
        course = np.degrees(np.arctan2(ve, vn)) % 360.0
        lines.append(checksum(f"GPRMC,{time},A,{la},{ns},{lo},{ew},{speed:.6f},{course:.6f},270326,,,A"))
    return lines


def test_a_drive_s_fixes_as_nmea_read_back_and_fuse_as_the_csv_fixes(tmp_path):
    # The car of examples/car_tunnel.toml on the WGS-84 Earth.
    text = (ROOT / "examples" / "car_tunnel.toml").read_text().replace(
        'nav_frame = "ENU"', 'nav_frame = "ENU"\nearth = "wgs84"\norigin = { latitude_deg = 46.5, longitude_deg = 8.0, height_m = 500.0 }')
    scenario = tmp_path / "car.toml"
    scenario.write_text(text)
    files = {n: tmp_path / f"{n}.csv" for n in ("imu", "truth", "gnss")}
    subprocess.run([imukit_bin(), "simulate", scenario, "--out", files["imu"], "--truth", files["truth"],
                    "--gnss", files["gnss"], "--quiet"], check=True, capture_output=True)
    gnss = imukit.read(files["gnss"])
    cols = ("t_s", "lat_rad", "lon_rad", "height_m", "vel_n_m_s", "vel_e_m_s")
    (tmp_path / "fixes.nmea").write_text("\r\n".join(nmea_lines(np.column_stack([gnss[c] for c in cols]))) + "\r\n")
    fixes = imukit.read(tmp_path / "fixes.nmea")
    assert fixes.columns == gnss.columns[:6] + ("hdop",)  # no vertical speed in NMEA
    assert np.all(fixes["hdop"] == np.float32(0.8))
    assert np.allclose(fixes["t_s"], gnss["t_s"], rtol=0, atol=5e-10)
    # Minutes to nine decimals (2e-6 m); the altitude as the nmea crate keeps it (f32: 1e-4 m at 500 m);
    # the speed to its six decimals of a knot and the crate's f32.
    assert np.abs(fixes.values[:, 1:3] - gnss.values[:, 1:3]).max() * 6.4e6 < 1e-5
    assert np.abs(fixes["height_m"] - gnss["height_m"]).max() < 1e-3
    assert np.abs(fixes.values[:, 4:6] - gnss.values[:, 4:6]).max() < 1e-4
    # Fused from the log as from the CSV fixes, but for the vertical speed the log lacks (the
    # filter takes its velocities as horizontal only): as close to the truth.
    outs = {}
    for name, path in (("csv", files["gnss"]), ("nmea", tmp_path / "fixes.nmea")):
        out = tmp_path / f"fused-{name}.csv"
        done = subprocess.run([imukit_bin(), "fuse", files["imu"], path, "--init", files["truth"],
                               "--scenario", scenario, "--out", out], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        outs[name] = imukit.read(out)
    truth = imukit.read(files["truth"])
    rms = {name: imukit.compare(truth, out).summary["position_rms_m"] for name, out in outs.items()}
    assert rms["nmea"] < 1.1 * rms["csv"], rms
    horizontal = np.hypot(outs["csv"]["pos_x_m"] - outs["nmea"]["pos_x_m"], outs["csv"]["pos_y_m"] - outs["nmea"]["pos_y_m"])
    # Apart from one row: a fix stamped on a sample (0.6 s read from "000000.60", 3 × 0.2 s
    # simulated: 1e-16 s apart) may be applied at that sample or the next, and that row then
    # differs by the fix's correction.
    assert np.sort(horizontal)[-2] < 0.2, np.sort(horizontal)[-5:]
    # HDOP × UERE as each fix's horizontal accuracy: the filter's horizontal one-sigma follows
    # it, the vertical stays the receiver's; Python's gnss_uere_m= gives the same file.
    sigma = {}
    for uere in ("1", "10"):
        out = tmp_path / f"fused-uere-{uere}.csv"
        done = subprocess.run([imukit_bin(), "fuse", files["imu"], tmp_path / "fixes.nmea", "--init", files["truth"],
                               "--scenario", scenario, "--gnss-uere-m", uere, "--out", out], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        fused = imukit.read(out)
        sigma[uere] = (fused["pos_x_sigma_m"][-1], fused["pos_z_sigma_m"][-1])
    assert sigma["10"][0] > 3 * sigma["1"][0] and abs(sigma["10"][1] / sigma["1"][1] - 1) < 0.2, sigma
    python = imukit.fuse(imukit.read(files["imu"]), fixes, initial=imukit.read(files["truth"]), scenario=scenario,
                         gnss_uere_m=10.0)
    assert np.array_equal(python.values, imukit.read(tmp_path / "fused-uere-10.csv").values)
    done = subprocess.run([imukit_bin(), "fuse", files["imu"], files["gnss"], "--init", files["truth"],
                           "--scenario", scenario, "--gnss-uere-m", "1.875", "--out", out], capture_output=True, text=True)
    assert done.returncode == 65 and f"--gnss-uere-m ({files['gnss']})" in done.stderr \
        and "no hdop column" in done.stderr, done.stderr
    # A log whose checksum is wrong is refused by file and line; nothing is written.
    lines = (tmp_path / "fixes.nmea").read_text().splitlines()
    lines[7] = lines[7][:-2] + ("00" if not lines[7].endswith("00") else "01")
    (tmp_path / "bad.nmea").write_text("\n".join(lines) + "\n")
    out = tmp_path / "bad.csv"
    done = subprocess.run([imukit_bin(), "fuse", files["imu"], tmp_path / "bad.nmea", "--init", files["truth"],
                           "--scenario", scenario, "--out", out], capture_output=True, text=True)
    assert done.returncode == 65 and "bad.nmea: line 8: checksum" in done.stderr and not out.exists(), done.stderr
