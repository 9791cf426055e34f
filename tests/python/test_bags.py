"""ROS 2 bags (MCAP): a bag written by rosbags (not by imukit) read by the CLI and by Python with
the same numbers; imukit's own bags read by rosbags as ROS 2 would, and by imukit's commands as
their CSV twins; bad bags refused by file and topic."""
import subprocess

import numpy as np
import pytest
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.convert import convert
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

import imukit
from test_cli_vs_python import ROOT, imukit_bin

STORE = get_typestore(Stores.ROS2_HUMBLE)
STORE1 = get_typestore(Stores.ROS1_NOETIC)
# 2023-11-14 22:13:20 UTC: a real clock, far from the epoch.
START_NS = 1_700_000_000_000_000_000
DAY_NS = 86_400 * 10**9


def imu_values(n):
    """A level IMU turning about z at a varying rate, stamped with ±20 % jitter at 200 Hz."""
    rng = np.random.default_rng(7)
    stamps = START_NS + np.cumsum(np.round(5e6 * (1 + 0.2 * rng.uniform(-1, 1, n))).astype(np.int64))
    t = (stamps - START_NS) * 1e-9
    accel = np.column_stack([0.1 * np.sin(t), 0.05 * np.cos(3 * t), 9.81 + 0 * t])
    gyro = np.column_stack([1e-3 * t, -2e-3 * np.ones(n), 0.3 * np.sin(0.5 * t)])
    return stamps, accel, gyro


def write_foreign_bag(path, storage="mcap", n=600):
    """A bag as rosbags writes it — ROS 2 with MCAP or sqlite3 storage, or ROS 1 — holding an
    IMU, its fixes and a string topic. Returns what it holds and the bag's path."""
    stamps, accel, gyro = imu_values(n)
    store = STORE1 if storage == "ros1" else STORE
    T = store.types
    Imu, Quaternion, Vector3 = (T["sensor_msgs/msg/Imu"], T["geometry_msgs/msg/Quaternion"],
                                T["geometry_msgs/msg/Vector3"])
    Fix, Status, String = T["sensor_msgs/msg/NavSatFix"], T["sensor_msgs/msg/NavSatStatus"], T["std_msgs/msg/String"]
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]

    def header(ns, frame):
        time = Time(sec=ns // 10**9, nanosec=ns % 10**9)
        return Header(seq=0, stamp=time, frame_id=frame) if storage == "ros1" else Header(stamp=time, frame_id=frame)

    def serialize(m):
        return store.serialize_ros1(m, m.__msgtype__) if storage == "ros1" else store.serialize_cdr(m, m.__msgtype__)

    fixes = [(START_NS + k * 10**9, 48.1 + 1e-5 * k, 11.5 - 2e-5 * k, 520.0 + k) for k in range(3)]
    if storage == "ros1":
        path = path.with_suffix(".bag")
        writer = Writer1(path)
        add = lambda topic, kind: writer.add_connection(topic, kind, typestore=store)  # noqa: E731
    else:
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer = Writer(path, version=9 if storage == "mcap" else 8, storage_plugin=plugin)
        add = lambda topic, kind: writer.add_connection(topic, kind, typestore=store)  # noqa: E731
    with writer as w:
        imu = add("/sensors/imu", Imu.__msgtype__)
        fix = add("/sensors/fix", Fix.__msgtype__)
        note = add("/note", String.__msgtype__)
        w.write(note, int(START_NS), serialize(String(data="hello")))
        nine = np.zeros(9)
        for k in range(n):
            m = Imu(header=header(int(stamps[k]), "imu_link"),
                    orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                    orientation_covariance=np.array([-1.0, 0, 0, 0, 0, 0, 0, 0, 0]),
                    angular_velocity=Vector3(*gyro[k]), angular_velocity_covariance=nine,
                    linear_acceleration=Vector3(*accel[k]), linear_acceleration_covariance=nine)
            # Received a little late: the header's stamp is the one read.
            w.write(imu, int(stamps[k]) + 1_234_567, serialize(m))
        for ns, lat, lon, alt in fixes:
            m = Fix(header=header(ns, "gnss"), status=Status(status=0, service=1), latitude=lat,
                    longitude=lon, altitude=alt, position_covariance=nine, position_covariance_type=0)
            w.write(fix, ns, serialize(m))
    return (stamps, accel, gyro, fixes), path


@pytest.mark.parametrize("storage", ["mcap", "sqlite3", "ros1"])
def test_a_bag_written_by_rosbags_reads_with_the_same_numbers_in_python_and_the_cli(tmp_path, storage):
    (stamps, accel, gyro, fixes), bag = write_foreign_bag(tmp_path / "walk", storage)
    # A ROS 2 bag's folder (metadata.yaml beside its storage file) and the file itself read alike.
    paths = [bag] if storage == "ros1" else [bag, *bag.glob("*.mcap"), *bag.glob("*.db3")]
    assert len(paths) == (1 if storage == "ros1" else 2)
    for path in paths:
        t = imukit.read(path)  # several topics: the IMU's is the bag's main table
        assert t.columns == ("t_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2",
                             "gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s")
        assert np.array_equal(t.values[:, 1:4], accel) and np.array_equal(t.values[:, 4:7], gyro)
        # Seconds after the UTC midnight before the first stamp, to the nanosecond.
        midnight = START_NS // DAY_NS * DAY_NS
        assert np.array_equal(np.round(t["t_s"] * 1e9).astype(np.int64), stamps - midnight)
    # The recorder's receive times instead (written 1 234 567 ns after each header stamp).
    late = imukit.read(bag, topic="/sensors/imu", receive_time=True)
    assert np.array_equal(np.round(late["t_s"] * 1e9).astype(np.int64), stamps + 1_234_567 - midnight)
    assert np.array_equal(late.values[:, 1:], t.values[:, 1:])
    f = imukit.read(bag, topic="/sensors/fix")
    assert f.columns == ("t_s", "lat_rad", "lon_rad", "height_m")
    assert np.allclose(f.values[:, 1:3], np.radians([[lat, lon] for _, lat, lon, _ in fixes]), rtol=0, atol=1e-16)
    assert np.array_equal(f["height_m"], [alt for *_, alt in fixes])
    # The CLI reads the bag as Python does: the same Allan table and orientation as from the CSV
    # Python wrote of the same table.
    imukit.read(bag).write(tmp_path / "imu.csv")
    for command in (["allan"], ["orient", "--filter", "complementary"]):
        outs = []
        for source in (bag, tmp_path / "imu.csv"):
            out = tmp_path / f"{command[0]}-{source.suffix or 'bag'}.csv"
            extra = ["--topic", "/sensors/imu"] if source == bag else []
            if source != bag and command[0] == "allan":
                imukit.read(bag, receive_time=True).write(tmp_path / "late.csv")
                done = subprocess.run([imukit_bin(), "allan", str(bag), "--receive-time", "--out", str(tmp_path / "a1.csv")],
                                      capture_output=True, text=True)
                assert done.returncode == 0, done.stderr
                done = subprocess.run([imukit_bin(), "allan", str(tmp_path / "late.csv"), "--out", str(tmp_path / "a2.csv")],
                                      capture_output=True, text=True)
                assert np.array_equal(imukit.read(tmp_path / "a1.csv").values, imukit.read(tmp_path / "a2.csv").values)
            run = subprocess.run([imukit_bin(), command[0], str(source), *command[1:], *extra, "--out", str(out)],
                                 capture_output=True, text=True)
            assert run.returncode == 0, run.stderr
            outs.append(imukit.read(out))
        assert outs[0].columns == outs[1].columns and np.array_equal(outs[0].values, outs[1].values), command


def test_bad_bags_and_bad_topics_are_refused_by_file_and_topic(tmp_path):
    _, folder = write_foreign_bag(tmp_path / "walk", n=50)
    with pytest.raises(imukit.ImuError, match=r"no topic /nope \(its topics: /note \(std_msgs/msg/String"):
        imukit.read(folder, topic="/nope")
    with pytest.raises(imukit.ImuError, match="topic /note holds std_msgs/msg/String, a type imukit does not read"):
        imukit.read(folder, topic="/note")
    with pytest.raises(imukit.ImuError, match="topic= and receive_time= are a ROS bag"):
        imukit.read(ROOT / "examples" / "data" / "vendor_log.csv", topic="/imu")
    # A truncated file: refused by name, nothing written by the command that read it.
    (mcap,) = folder.glob("*.mcap")
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(mcap.read_bytes()[: mcap.stat().st_size // 2])
    with pytest.raises(imukit.ImuError, match="cut.mcap: not a readable MCAP file"):
        imukit.read(cut)
    out = tmp_path / "o.csv"
    run = subprocess.run([imukit_bin(), "orient", str(cut), "--out", str(out)], capture_output=True, text=True)
    assert run.returncode == 65 and "cut.mcap" in run.stderr and not out.exists(), run.stderr
    # A ROS 1 bag cut short, and a file that is no bag at all.
    _, bag1 = write_foreign_bag(tmp_path / "old", "ros1", n=50)
    cut = tmp_path / "cut.bag"
    cut.write_bytes(bag1.read_bytes()[: bag1.stat().st_size // 2])
    with pytest.raises(imukit.ImuError, match="cut.bag: not a readable ROS 1 bag"):
        imukit.read(cut)
    (tmp_path / "noise.db3").write_bytes(b"not sqlite" * 100)
    with pytest.raises(imukit.ImuError, match="noise.db3: not a readable ROS 2 sqlite3 bag"):
        imukit.read(tmp_path / "noise.db3")


def test_imukit_writes_a_bag_rosbags_replays_and_its_commands_read_as_the_csv(tmp_path):
    scenario = ROOT / "examples" / "car_tunnel.toml"
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(tmp_path / "run.mcap")],
                   check=True, capture_output=True)
    subprocess.run([imukit_bin(), "simulate", str(scenario), "--out", str(tmp_path / "imu.csv"),
                    "--truth", str(tmp_path / "truth.csv"), "--gnss", str(tmp_path / "gnss.csv")],
                   check=True, capture_output=True)
    imu, truth, gnss = (imukit.read(tmp_path / f"{n}.csv") for n in ("imu", "truth", "gnss"))
    # As a ROS 2 user's tools read it: types, counts, stamps in integer nanoseconds, readings
    # bit for bit.
    with AnyReader([tmp_path / "run.mcap"], default_typestore=STORE) as reader:
        kinds = {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
        assert kinds == {"/imu": ("sensor_msgs/msg/Imu", len(imu)),
                         "/ground_truth": ("nav_msgs/msg/Odometry", len(truth)),
                         "/gnss/position": ("geometry_msgs/msg/PointStamped", len(gnss)),
                         "/gnss/vel": ("geometry_msgs/msg/TwistStamped", len(gnss))}
        rows, times = [], []
        connections = [c for c in reader.connections if c.topic == "/imu"]
        for c, _, raw in reader.messages(connections=connections):
            m = reader.deserialize(raw, c.msgtype)
            a, w = m.linear_acceleration, m.angular_velocity
            times.append(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec)
            rows.append([a.x, a.y, a.z, w.x, w.y, w.z])
    assert np.array_equal(np.array(rows), imu.values[:, 1:7])
    assert np.array_equal(times, np.round(imu["t_s"] * 1e9).astype(np.int64))
    # imukit reads its bag back: each topic by the columns a reader asks for.
    bag = tmp_path / "run.mcap"
    assert np.array_equal(imukit.read(bag).values[:, 1:], imu.values[:, 1:])
    # For ROS 1, rosbags' converter makes a .bag of it (imukit writes ROS 2's MCAP only), which
    # reads back as the MCAP does.
    convert([bag], tmp_path / "run.bag", dst_storage="sqlite3", dst_version=9, compress=None,
            compress_mode="file", default_typestore=None, typestore=None, exclude_topics=[],
            include_topics=[], exclude_msgtypes=[], include_msgtypes=[])
    for topic in ("/imu", "/gnss/position"):
        a, b = imukit.read(bag, topic=topic), imukit.read(tmp_path / "run.bag", topic=topic)
        assert a.columns == b.columns and np.array_equal(a.values, b.values), topic
    back = imukit.read(bag, topic="/gnss/position")
    assert back.columns == gnss.columns
    assert np.array_equal(back.values[:, 1:], gnss.values[:, 1:])
    reference = imukit.read(bag, topic="/ground_truth")
    for c in ("pos_x_m", "pos_y_m", "pos_z_m", "q_w", "q_x", "q_y", "q_z"):
        assert np.array_equal(reference[c], truth[c]), c
    for c in ("vel_x_m_s", "vel_y_m_s", "vel_z_m_s"):  # through the body frame and back
        assert np.allclose(reference[c], truth[c], rtol=0, atol=1e-12), c
    # The commands: the bag alone, with no flag, gives the CSV files' fused run.
    outs = {}
    for name, args in (("bag", [bag, bag, "--init", bag]),
                       ("csv", [tmp_path / "imu.csv", tmp_path / "gnss.csv", "--init", tmp_path / "truth.csv"])):
        out = tmp_path / f"fused-{name}.csv"
        run = subprocess.run([imukit_bin(), "fuse", *map(str, args), "--scenario", str(scenario), "--out", str(out)],
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        outs[name] = imukit.read(out)
    # Stamps rounded to the nanosecond are all that differs.
    assert outs["bag"].columns == outs["csv"].columns
    assert np.abs(outs["bag"].values - outs["csv"].values).max() < 1e-8
