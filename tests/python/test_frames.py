"""The Python package plays with pandas, polars and type checkers: frames and mappings go in
wherever a Table does and give the same numbers, to_pandas() is a frame you can change, results
print short and are named types."""
import numpy as np
import pandas as pd
import polars as pl
import pytest

import imukit
from imukit import Comparison, ImuError, Table

SCENARIO = {"rate_hz": 100.0, "duration_s": 2.0, "trajectory": {"type": "builtin", "name": "figure8"}}


@pytest.fixture(scope="module")
def sim():
    return imukit.simulate(SCENARIO)


def as_frames(table):
    df = table.to_pandas()
    return {
        "pandas": df,
        "polars": pl.from_pandas(df),
        "dict": {c: table[c] for c in table.columns},
        "structured": np.rec.fromarrays([table[c] for c in table.columns], names=list(table.columns)),
    }


@pytest.mark.parametrize("kind", ["pandas", "polars", "dict", "structured"])
def test_a_frame_navigates_to_the_same_numbers_as_its_table(sim, kind):
    expected = imukit.strapdown(sim.imu, initial=sim.truth)
    got = imukit.strapdown(as_frames(sim.imu)[kind], initial=as_frames(sim.truth)[kind]
                           if kind != "dict" else sim.truth)
    assert got.columns == expected.columns
    np.testing.assert_array_equal(got.values, expected.values)


@pytest.mark.parametrize("kind", ["pandas", "polars", "dict"])
def test_compare_takes_frames_and_returns_a_named_result(sim, kind):
    nav = imukit.strapdown(sim.imu, initial=sim.truth)
    result = imukit.compare(as_frames(sim.truth)[kind], as_frames(nav)[kind])
    assert isinstance(result, Comparison)
    errors, summary = result  # still unpacks
    assert errors is result.errors and summary is result.summary
    reference = imukit.compare(sim.truth, nav)
    np.testing.assert_array_equal(errors.values, reference.errors.values)
    assert summary == reference.summary
    assert all(isinstance(v, float) for v in summary.values())
    assert repr(result).startswith("Comparison(errors=Table(") and len(repr(result)) < 400


def test_a_frame_that_is_not_numbers_or_not_named_is_refused_by_name():
    with pytest.raises(TypeError, match=r"imu: column 'gyro_x_rad_s' does not hold numbers"):
        imukit.strapdown(pd.DataFrame({"t_s": [0.0, 0.1], "gyro_x_rad_s": ["a", "b"]}))
    with pytest.raises(TypeError, match=r"imu: column names must be strings, got 0"):
        imukit.strapdown(pd.DataFrame(np.zeros((2, 3))))
    with pytest.raises(ValueError, match=r"imu: column 'b' has 2 rows, column 'a' has 3"):
        imukit.strapdown({"a": [1.0, 2.0, 3.0], "b": [1.0, 2.0]})
    with pytest.raises(TypeError, match="a plain array has no column names"):
        imukit.strapdown(np.zeros((3, 7)))
    with pytest.raises(TypeError, match="got int"):
        imukit.strapdown(5)
    # The core still checks the columns the job needs.
    with pytest.raises(ImuError):
        imukit.strapdown(pd.DataFrame({"t_s": [0.0, 0.1]}))


def test_to_pandas_is_a_frame_you_can_change_and_a_view_when_asked(sim):
    df = sim.imu.to_pandas()
    df.loc[0, "gyro_x_rad_s"] = 1.0
    assert df.loc[0, "gyro_x_rad_s"] == 1.0
    assert sim.imu["gyro_x_rad_s"][0] != 1.0  # the table is untouched
    view = sim.imu.to_pandas(copy=False)
    assert np.shares_memory(view.to_numpy(), sim.imu.values)
    with pytest.raises(ValueError, match="read-only"):
        view.to_numpy()[0, 1] = 1.0
    np.testing.assert_array_equal(Table.of(df.iloc[1:]).values, sim.imu.values[1:])


def test_reprs_are_one_short_line(sim):
    r = repr(sim.imu)
    assert r == (f"Table({len(sim.imu)} rows × 10 columns: t_s, accel_x_m_s2, accel_y_m_s2, accel_z_m_s2, "
                 "gyro_x_rad_s, …, mag_z_ut)")
    assert "\n" not in repr(sim) and len(repr(sim)) < 400
    mc = imukit.monte_carlo({**SCENARIO, "imu": {"preset": "mpu-6050", "seed": 2}}, runs=3)
    assert repr(mc) == f"MonteCarlo(3 runs (0…2) × 201 samples × 10 columns; truth={mc.truth!r})"
    np.testing.assert_array_equal(mc.run(1).values, mc.imu[1])
