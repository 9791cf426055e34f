"""Type stubs of the compiled core (checked with ``python -m mypy.stubtest imukit._core``)."""
from typing import Any, Mapping, Optional, Sequence, Union, final

import numpy as np
import numpy.typing as npt

_Table = tuple[list[str], npt.NDArray[np.float64]]
#: A table with its description's entries.
_Described = tuple[list[str], npt.NDArray[np.float64], dict[str, Union[str, float]]]
#: The descriptions of a job's table arguments: (argument, entries).
_DescribedIn = Sequence[tuple[str, dict[str, Union[str, float]]]]
#: A run's tables: truth (None when not kept), IMU, and the GNSS, barometer and odometer ones.
_Simulation = tuple[Optional[_Described], _Described, Optional[_Described], Optional[_Described], Optional[_Described], list[str]]

__version__: str
DEFAULTS: dict[str, Any]

__all__ = [
    "cli_main",
    "__version__",
    "DEFAULTS",
    "ImuError",
    "study_plan",
    "study_undescribed",
    "study_run",
    "study_summarise",
    "DEFAULT_GRAVITY_M_S2",
    "read_csv",
    "read_table_file",
    "calibrate",
    "spectrum",
    "chain_response",
    "apply_calibration",
    "read_calibration",
    "write_calibration",
    "read_description",
    "implausible",
    "write_run",
    "write_table_file",
    "write_csv",
    "run_path",
    "table_kind",
    "figure_panels",
    "frame_plan",
    "default_body_m",
    "leaves_plane",
    "OrientationFilter",
    "ecompass",
    "quaternion_distance",
    "simulate_text",
    "simulate_dict",
    "simulation_shape",
    "animation_scene",
    "points_enu",
    "poses_enu",
    "truth_from_expressions",
    "truth_from_samples",
    "ideal_imu",
    "tangent_euler",
    "nav_to_body",
    "at_lever_arm",
    "euler_to_quaternion",
    "quaternion_to_euler",
    "euler_to_dcm",
    "dcm_to_euler",
    "quaternion_to_dcm",
    "dcm_to_quaternion",
    "ImuSensor",
    "allan_deviation",
    "identify",
    "convert",
    "preset_names",
    "preset_toml",
    "preset_kalibr_yaml",
    "load_params_toml",
    "planar_dead_reckon",
    "read_planar",
    "strapdown",
    "compare",
    "fuse",
    "truth_from_body_rates",
    "truth_from_waypoints",
    "builtin_names",
    "builtin_toml",
    "example_list",
    "write_examples",
]

DEFAULT_GRAVITY_M_S2: float

class ImuError(ValueError):
    field: Optional[str]
    file: Optional[str]
    row: Optional[int]
    column: Optional[str]

def simulate_text(
    text: str,
    *,
    format: str = "toml",
    origin: str = "scenario",
    base_dir: str = ".",
    run: Optional[int] = None,
    threads: Optional[int] = None,
    truth: bool = True,
    imu_out: Optional[npt.NDArray[np.float64]] = None,
) -> _Simulation: ...
def simulate_dict(
    scenario: dict[str, Any],
    *,
    origin: str = "scenario dict",
    base_dir: str = ".",
    run: Optional[int] = None,
    threads: Optional[int] = None,
    truth: bool = True,
    imu_out: Optional[npt.NDArray[np.float64]] = None,
) -> _Simulation: ...
def simulation_shape(
    scenario: Union[str, dict[str, Any]], *, format: str, origin: str, base_dir: str
) -> tuple[int, list[str], list[str]]: ...
def truth_from_expressions(
    t_s: npt.NDArray[np.float64],
    position_m: Sequence[str],
    *,
    attitude: Optional[str] = None,
    yaw_rad: Optional[str] = None,
    pitch_rad: Optional[str] = None,
    roll_rad: Optional[str] = None,
    constants: Optional[dict[str, float]] = None,
    nav_frame: str = ...,
    min_speed_m_s: Optional[float] = None,
) -> _Table: ...
def truth_from_samples(
    t_s: npt.NDArray[np.float64],
    position_m: npt.NDArray[np.float64],
    *,
    euler_rad: Optional[npt.NDArray[np.float64]] = None,
    quaternion: Optional[npt.NDArray[np.float64]] = None,
    attitude: Optional[str] = None,
    order: int = 6,
    nav_frame: str = ...,
    min_speed_m_s: Optional[float] = None,
) -> _Table: ...
def ideal_imu(
    columns: Sequence[str],
    values: npt.NDArray[np.float64],
    *,
    lever_arm_m: Sequence[float] = ...,
    accel_sign: str = ...,
    gravity_m_s2: float = ...,
    magnetic_field_ut: Optional[Sequence[float]] = None,
    nav_frame: str = ...,
    kind: str = ...,
) -> _Table: ...
def tangent_euler(velocity_m_s: npt.NDArray[np.float64], *, min_speed_m_s: float = ...) -> npt.NDArray[np.float64]: ...
def nav_to_body(euler_rad: npt.NDArray[np.float64], v_n: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def at_lever_arm(
    a: npt.NDArray[np.float64],
    omega: npt.NDArray[np.float64],
    alpha: npt.NDArray[np.float64],
    r: Sequence[float],
) -> npt.NDArray[np.float64]: ...
def euler_to_quaternion(euler_rad: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def quaternion_to_euler(quaternion: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def euler_to_dcm(euler_rad: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def dcm_to_euler(dcm: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def quaternion_to_dcm(quaternion: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def dcm_to_quaternion(dcm: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def builtin_names() -> list[str]: ...
def builtin_toml(name: str) -> str: ...
def example_list() -> list[tuple[str, str]]: ...
def write_examples(names: list[str], folder: str) -> list[tuple[str, bool]]: ...

@final
class ImuSensor:
    def __new__(
        cls,
        imu_type: Optional[str] = None,
        *,
        reference_frame: Optional[str] = None,
        sample_rate: Optional[float] = None,
        temperature: Optional[float] = None,
        magnetic_field: Optional[Sequence[float]] = None,
        accelerometer: Optional[dict[str, Any]] = None,
        gyroscope: Optional[dict[str, Any]] = None,
        magnetometer: Optional[dict[str, Any]] = None,
        preset: Optional[str] = None,
        seed: int = 0,
        profile: Optional[str] = None,
        accel_sign: Optional[str] = None,
    ) -> ImuSensor: ...
    def step(
        self,
        acceleration: npt.NDArray[np.float64],
        angular_velocity: npt.NDArray[np.float64],
        *,
        quaternion: Optional[npt.NDArray[np.float64]] = None,
        dcm: Optional[npt.NDArray[np.float64]] = None,
        out: Optional[npt.NDArray[np.float64]] = None,
    ) -> npt.NDArray[np.float64]: ...
    def reset(self) -> None: ...
    @property
    def imu_type(self) -> str: ...
    @property
    def temperature(self) -> float: ...
    @temperature.setter
    def temperature(self, t: float) -> None: ...

def allan_deviation(
    x: npt.NDArray[np.float64], sample_rate_hz: float
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def identify(
    x: npt.NDArray[np.float64],
    sample_rate_hz: float,
    names: list[str],
    source: str,
    *,
    kalibr_inflation: float = ...,
    kalibr_topic: str = ...,
) -> dict[str, Any]: ...
def preset_names() -> list[str]: ...
def preset_toml(name: str) -> str: ...
def preset_kalibr_yaml(name: str, *, rate_hz: float = ..., topic: str = ...) -> str: ...
def load_params_toml(path: str, *, part: Optional[str] = None) -> tuple[str, list[str]]: ...
def convert(value: float, unit: str) -> tuple[float, str, str]: ...
def planar_dead_reckon(
    t_s: npt.NDArray[np.float64],
    accel_x_m_s2: npt.NDArray[np.float64],
    accel_y_m_s2: npt.NDArray[np.float64],
    gyro_z_rad_s: npt.NDArray[np.float64],
    *,
    scheme: str = ...,
    position0_m: Sequence[float] = ...,
    heading0_rad: float = 0.0,
    velocity0_m_s: Sequence[float] = ...,
) -> _Table: ...
def read_planar(path: str) -> _Table: ...
def strapdown(
    columns: Sequence[str],
    values: npt.NDArray[np.float64],
    *,
    initial_columns: Optional[Sequence[str]] = None,
    initial_values: Optional[npt.NDArray[np.float64]] = None,
    position0_m: Optional[Sequence[float]] = None,
    velocity0_m_s: Optional[Sequence[float]] = None,
    quaternion0: Optional[Sequence[float]] = None,
    euler0_rad: Optional[Sequence[float]] = None,
    nav_frame: Optional[str] = None,
    gravity_m_s2: Optional[float] = None,
    coning: bool = True,
    sculling: bool = True,
    accel_sign: Optional[str] = None,
    scheme: str = ...,
    substeps: int = ...,
    earth: Optional[str] = None,
    vertical: str = ...,
    baro_time_constant_s: float = ...,
    earth_gravity: Optional[str] = None,
    lat0_deg: Optional[float] = None,
    lon0_deg: Optional[float] = None,
    height0_m: Optional[float] = None,
    baro_columns: Optional[Sequence[str]] = None,
    baro_values: Optional[npt.NDArray[np.float64]] = None,
    described: _DescribedIn = ...,
) -> tuple[_Described, list[str]]: ...
def fuse(
    imu_columns: Sequence[str],
    imu_values: npt.NDArray[np.float64],
    gnss_columns: Sequence[str],
    gnss_values: npt.NDArray[np.float64],
    initial_columns: Optional[Sequence[str]],
    initial_values: Optional[npt.NDArray[np.float64]],
    scenario: Any,
    *,
    format: str = "dict",
    base_dir: str = ".",
    gate: bool = True,
    align: Optional[str] = None,
    odometer_columns: Optional[Sequence[str]] = None,
    odometer_values: Optional[npt.NDArray[np.float64]] = None,
    baro_columns: Optional[Sequence[str]] = None,
    baro_values: Optional[npt.NDArray[np.float64]] = None,
    nhc_sigma_m_s: Optional[float] = None,
    covariance_interval_s: Optional[float] = None,
    sensor_errors: Optional[bool] = None,
    rest_s: Optional[float] = None,
    smooth: bool = False,
    zupt: bool = False,
    gnss_adaptive: bool = False,
    imu_model: Optional[str] = None,
    part: Optional[str] = None,
    gnss_horizontal_accuracy_m: Optional[float] = None,
    gnss_vertical_accuracy_m: Optional[float] = None,
    gnss_velocity_accuracy_m_s: Optional[float] = None,
    gnss_lever_arm_m: Optional[Sequence[float]] = None,
    gnss_decay_factor: Optional[float] = None,
    gnss_correlation_time_s: Optional[float] = None,
    gnss_latency_s: Optional[float] = None,
    gnss_uere_m: Optional[float] = None,
    nav_frame: Optional[str] = None,
    earth: Optional[str] = None,
    earth_gravity: Optional[str] = None,
    accel_sign: Optional[str] = None,
    gravity_m_s2: Optional[float] = None,
    described: _DescribedIn = ...,
) -> tuple[_Described, int, int, list[str]]: ...
def compare(
    truth_columns: Sequence[str],
    truth: npt.NDArray[np.float64],
    estimate_columns: Sequence[str],
    estimate: npt.NDArray[np.float64],
    described: _DescribedIn = ...,
    align_heading: bool = False,
) -> tuple[_Table, dict[str, float]]: ...
def truth_from_body_rates(
    t_s: npt.NDArray[np.float64],
    accel_body_m_s2: npt.NDArray[np.float64],
    omega_body_rad_s: npt.NDArray[np.float64],
    *,
    position0_m: Sequence[float] = ...,
    velocity0_m_s: Sequence[float] = ...,
    euler0_rad: Sequence[float] = ...,
    nav_frame: str = ...,
) -> _Table: ...
def truth_from_waypoints(
    t_s: npt.NDArray[np.float64],
    time_s: npt.NDArray[np.float64],
    position_m: npt.NDArray[np.float64],
    *,
    velocity_m_s: Optional[npt.NDArray[np.float64]] = None,
    euler_rad: Optional[npt.NDArray[np.float64]] = None,
    nav_frame: str = ...,
) -> _Table: ...
def cli_main(argv: Sequence[str]) -> int: ...
def read_table_file(path: str, map_path: Optional[str] = None, map_json: Optional[str] = None, topic: Optional[str] = None, receive_time: bool = False, calibration_path: Optional[str] = None) -> _Described: ...
def calibrate(columns: Sequence[str], values: npt.NDArray[np.float64], gravity_m_s2: float, source: str) -> tuple[str, list[tuple[int, int]], list[str], Optional[tuple[float, float]], list[tuple[str, list[float]]]]: ...
def chain_response(chain: Mapping[str, Any], rate_hz: float, frequencies_hz: Sequence[float]) -> _Table: ...
def spectrum(columns: Sequence[str], values: npt.NDArray[np.float64], names: Sequence[str], segment_s: float, source: str) -> _Table: ...
def apply_calibration(columns: Sequence[str], values: npt.NDArray[np.float64], text: str, origin: str) -> _Table: ...
def read_calibration(path: str) -> str: ...
def write_calibration(path: str, text: str) -> None: ...
def read_description(path: str) -> Optional[dict[str, Union[str, float]]]: ...
def implausible(columns: Sequence[str], values: npt.NDArray[np.float64], source: str) -> list[str]: ...
def write_run(
    path: str,
    columns: Sequence[str],
    values: npt.NDArray[np.float64],
    scenario: Union[str, dict[str, Any]],
    *,
    format: str,
    origin: str,
    base_dir: str,
) -> None: ...
def write_table_file(path: str, columns: Sequence[str], values: npt.NDArray[np.float64], description: Optional[dict[str, Union[str, float]]] = None) -> None: ...
def read_csv(path: str) -> _Described: ...
def table_kind(columns: list[str]) -> Optional[str]: ...
def figure_panels(kind: str) -> list[tuple[str, str, float, list[tuple[str, str]], list[tuple[str, int]]]]: ...
def frame_plan(t_s: npt.NDArray[np.float64], fps: float, speed: Optional[float] = None) -> tuple[list[int], float]: ...
def default_body_m(extent_m: float) -> list[float]: ...
def leaves_plane(points: npt.NDArray[np.float64]) -> bool: ...
def animation_scene(
    body_m: Sequence[float],
) -> tuple[npt.NDArray[np.float64], list[tuple[int, int]], list[int]]: ...
def points_enu(points: npt.NDArray[np.float64], nav_frame: str) -> npt.NDArray[np.float64]: ...
def poses_enu(
    position_m: npt.NDArray[np.float64], quaternion: npt.NDArray[np.float64], nav_frame: str
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def write_csv(path: str, columns: list[str], values: npt.NDArray[np.float64]) -> None: ...
def run_path(out: str, run: int, runs: int) -> str: ...
@final
class OrientationFilter:
    def __new__(
        cls,
        kind: str,
        *,
        sample_rate: float,
        conventions: Optional[str] = None,
        reference_frame: Optional[str] = None,
        accel_sign: Optional[str] = None,
        magnetometer: bool = False,
        settings: Sequence[tuple[str, float]] = ...,
        initial_process_noise: Optional[Sequence[float]] = None,
        smooth: bool = False,
    ) -> OrientationFilter: ...
    def step(
        self,
        accel: npt.NDArray[np.float64],
        gyro: Optional[npt.NDArray[np.float64]] = None,
        mag: Optional[npt.NDArray[np.float64]] = None,
        t_s: Optional[npt.NDArray[np.float64]] = None,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def reset(self) -> None: ...
    def status(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def reference_frame(self) -> str: ...
    @property
    def gyroscope_offset(self) -> Optional[list[float]]: ...

def ecompass(
    accel: npt.NDArray[np.float64],
    mag: npt.NDArray[np.float64],
    *,
    conventions: Optional[str] = None,
    reference_frame: Optional[str] = None,
    accel_sign: Optional[str] = None,
) -> npt.NDArray[np.float64]: ...
def quaternion_distance(q1: npt.NDArray[np.float64], q2: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def study_plan(path: str) -> tuple[list[str], int]: ...
def study_undescribed(path: str) -> list[str]: ...
def study_run(
    path: str, case: int, run: int
) -> tuple[
    Optional[npt.NDArray[np.float64]],
    Optional[npt.NDArray[np.float64]],
    Optional[npt.NDArray[np.float64]],
    Optional[str],
    int,
    Optional[npt.NDArray[np.float64]],
]: ...
def study_summarise(
    path: str,
    outcomes: Sequence[
        Sequence[
            tuple[
                Optional[Sequence[float]],
                Optional[Sequence[float]],
                Optional[Sequence[float]],
                Optional[str],
                int,
                Optional[Sequence[float]],
            ]
        ]
    ],
) -> tuple[
    _Table,
    list[tuple[str, int, int, Optional[float], Optional[float], float, int, Optional[tuple[float, float]]]],
]: ...
