"""One place for each default: Python states no default of its own for an option the library
has. Every literal default in the package's signatures is listed here with why it is Python's
own (an output format, a name, a start of zero); any other default is taken from the library
(``imukit._core.DEFAULTS``), so a change there reaches Python."""
import ast
import pathlib

import imukit

PACKAGE = pathlib.Path(imukit.__file__).parent

# (function, parameter): why the literal is Python's own.
OWN = {
    ("Table.of", "name"): "a label for messages",
    ("example", "folder"): "where the files are written, like the command's --out-dir default",
    ("monte_carlo", "first_run"): "the first run's number, as the command's --first-run",
    ("ImuSensor.__init__", "seed"): "MATLAB's call shape: a seed, 0 unless given",
    ("ideal_imu", "lever_arm_m"): "no lever arm",
    ("animate", "lever_arm_m"): "no lever arm",
    ("kind", "source"): "a label for messages",
    ("sympy_to_formula", "name"): "a label for messages",
    ("my_lin", "order"): "the course's own function's (MATLAB gradient's second order)",
    ("my_ang", "order"): "the course's own function's (MATLAB gradient's second order)",
    ("my_ang", "frame"): "the course's own function's",
    ("planar_dead_reckon", "heading0_rad"): "a start heading of zero",
    ("planar_dead_reckon", "velocity0_m_s"): "a start at rest",
    ("truth_from_body_rates", "position0_m"): "a start at the origin",
    ("truth_from_body_rates", "velocity0_m_s"): "a start at rest",
    ("truth_from_body_rates", "euler0_rad"): "a level start",
}
# Options of the Python API alone: the output's format, not a setting of the library.
OWN_PARAMETERS = {"orientation_format"}


def literal(node):
    """The value of a default written as a literal (a number, a string, a tuple of them)."""
    if isinstance(node, ast.Constant) and node.value is not None and not isinstance(node.value, bool):
        return node.value
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        v = literal(node.operand)
        return None if v is None else -v
    if isinstance(node, ast.Tuple) and node.elts and all(literal(e) is not None for e in node.elts):
        return tuple(literal(e) for e in node.elts)
    return None


def literal_defaults():
    found = {}
    for path in sorted(PACKAGE.glob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for parent in ast.walk(tree):
            for node in ast.iter_child_nodes(parent):
                if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    continue
                if node.name.startswith("_") and not node.name.startswith("__"):
                    continue  # a private helper: no option of the API
                name = f"{parent.name}.{node.name}" if isinstance(parent, ast.ClassDef) else node.name
                a = node.args
                positional = a.posonlyargs + a.args
                pairs = list(zip(positional[len(positional) - len(a.defaults):], a.defaults))
                pairs += [(p, d) for p, d in zip(a.kwonlyargs, a.kw_defaults) if d is not None]
                for param, default in pairs:
                    value = literal(default)
                    if value is not None and param.arg not in OWN_PARAMETERS:
                        found[(name, param.arg)] = (value, path.name)
    return found


def test_python_states_no_default_of_its_own_for_a_library_option():
    found = literal_defaults()
    theirs = {k: v for k, v in found.items() if k not in OWN}
    assert not theirs, (
        "literal defaults in Python for options the library has (take them from "
        f"imukit._core.DEFAULTS, or say in OWN why they are Python's): {theirs}"
    )
    stale = set(OWN) - set(found)
    assert not stale, f"listed as Python's own but no longer literal: {stale}"


def test_the_filters_defaults_are_the_librarys():
    import inspect

    filters = imukit._core.DEFAULTS["filters"]
    imu = inspect.signature(imukit.ImuFilter).parameters
    assert imu["accelerometer_noise"].default == filters["imufilter"]["AccelerometerNoise"] == 0.00019247
    assert imu["sample_rate"].default == filters["imufilter"]["SampleRate"] == 100.0
    mahony = inspect.signature(imukit.MahonyFilter).parameters
    assert (mahony["kp"].default, mahony["ki"].default) == (filters["mahony"]["Kp"], filters["mahony"]["Ki"])
    # Every setting the library takes has its default there, robust filter's too.
    assert set(filters["robust"]) >= {"AccelerationThreshold", "AccelerationSustainedTime", "SampleRate"}
    sensor = inspect.signature(imukit.ImuSensor).parameters
    assert sensor["profile"].default == imukit._core.DEFAULTS["imu_sensor"]["profile"] == "matlab"
    assert sensor["reference_frame"].default == "NED"
