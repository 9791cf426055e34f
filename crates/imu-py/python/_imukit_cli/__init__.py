"""The ``imukit`` command that the wheel installs: the Rust command line of ``imu-cli``, run by the
extension module in this process, so that ``pip install imukit`` gives the command without a Rust
toolchain.

The console script loads the extension module directly, without the package's ``__init__`` (which
imports NumPy and the Python layers): the command starts in tens of milliseconds instead of a
fifth of a second. Where that cannot be done it imports the package as usual.
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import signal
import sys
from pathlib import Path
from types import ModuleType


def _load_core() -> ModuleType:
    already = sys.modules.get("imukit._core")
    if already is not None:
        return already
    here = Path(__file__).resolve().parent.parent / "imukit"
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = here / f"_core{suffix}"
        if path.is_file():
            loader = importlib.machinery.ExtensionFileLoader("imukit._core", str(path))
            spec = importlib.util.spec_from_file_location("imukit._core", path, loader=loader)
            if spec is not None:
                module = importlib.util.module_from_spec(spec)
                loader.exec_module(module)
                return module
    from imukit import _core

    return _core


def main() -> None:
    """Runs ``imukit`` with this process's arguments and exits with its status."""
    # Until the command line installs its own handlers, Ctrl-C ends the process as it would end
    # the binary (no traceback); nothing has been written yet.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    core = _load_core()
    sys.exit(core.cli_main(["imukit", *sys.argv[1:]]))
