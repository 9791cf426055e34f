"""The shipped examples: :func:`example` writes one (scenario files, data, Python scripts) where
the guides' commands read it, from the installed package alone; :func:`examples` lists them."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Union

from . import _core

ALL = "all"


def examples() -> dict[str, str]:
    """The shipped examples: name → what it shows (``imukit example`` on the command line).

    >>> "car_tunnel" in examples() and "study/tunnel" in examples()
    True
    """
    return dict(_core.example_list())


def example(name: str, folder: Union[str, "os.PathLike[str]"] = "examples") -> Path:
    """Writes the example ``name`` (with the files it reads) under ``folder`` and returns the
    path of its main file; ``"all"`` writes every file and returns the folder. Files keep their
    places in the folder (``study/tunnel.toml`` reads ``../car_tunnel.toml``), so
    ``imukit.simulate(imukit.example("car_tunnel"))`` and the guides' commands
    (``imukit simulate examples/car_tunnel.toml``) run as written. A file already there with
    the shipped text is left alone; one that differs (a copy you edited) is never overwritten:
    the call is refused (:class:`imukit.ImuError`) before anything is written.

    >>> import tempfile, imukit
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = imukit.example("track", folder=d)
    ...     sim = imukit.simulate(path)
    >>> path.name, sim.imu.values.shape[1]
    ('track.toml', 7)
    """
    folder = os.fspath(folder)
    done = _core.write_examples([name], folder)
    # The files come back in order, the named example's main file first.
    return Path(folder) if name == ALL else Path(done[0][0])
