"""The ``imukit`` command that the wheel installs (``_imukit_cli``, also ``python -m imukit``) is the
Rust command line run inside Python: the same text, the same exit statuses, the same clean-up on
Ctrl-C, and it starts without importing NumPy."""
import signal
import subprocess
import sys
import time

import pytest

import imukit

PYTHON_M = [sys.executable, "-m", "imukit"]


def run(args, **kw):
    return subprocess.run([*PYTHON_M, *args], capture_output=True, text=True, timeout=120, **kw)


def test_version_is_the_package_version():
    done = run(["--version"])
    assert done.returncode == 0
    assert done.stdout.strip() == f"imukit {imukit.__version__}"


def test_a_usage_error_exits_2_with_clap_text():
    done = run(["simulate"])
    assert done.returncode == 2
    assert "required arguments were not provided" in done.stderr
    assert "--out <OUT>" in done.stderr


def test_bad_input_exits_65_naming_the_file_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('rate_hz = "fast"\nduration_s = 1.0\n[trajectory]\ntype = "builtin"\nname = "figure8"\n')
    done = run(["simulate", str(bad), "--out", str(tmp_path / "o.csv")])
    assert done.returncode == 65, done.stderr
    assert str(bad) in done.stderr and "rate_hz" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_output_reaches_stdout_whole_when_piped(tmp_path):
    # Rust's buffered standard output is flushed before Python exits.
    done = run(["scenario", "figure8"])
    assert done.returncode == 0
    assert done.stdout == imukit.builtin_scenario_toml("figure8")


def test_the_console_script_does_not_import_numpy():
    _imukit_cli = pytest.importorskip("_imukit_cli")
    code = ("import sys, _imukit_cli; core = _imukit_cli._load_core(); "
            "assert 'numpy' not in sys.modules, 'numpy imported'; assert callable(core.cli_main); print(core.__version__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == imukit.__version__
    assert _imukit_cli.__file__


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_exits_130_and_leaves_no_file(tmp_path):
    scenario = tmp_path / "long.toml"
    scenario.write_text('rate_hz = 1000.0\nduration_s = 100000.0\n[trajectory]\ntype = "builtin"\nname = "figure8"\n')
    out = tmp_path / "o.csv"
    proc = subprocess.Popen([*PYTHON_M, "simulate", str(scenario), "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    # Interrupted once the command is writing (its temporary file is unnamed, so wait on time).
    time.sleep(2.0)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.toml"]
