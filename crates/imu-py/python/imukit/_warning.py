"""``ImuWarning``: what a run tells its user without refusing anything (figures implausible for
their unit, angles that look like degrees, readings clipped at a sensor's range, sampling too
coarse for the motion). Filter it with the standard ``warnings`` module."""
from __future__ import annotations

import warnings
from typing import Iterable


class ImuWarning(UserWarning):
    """A slip imukit noticed in a scenario or a run; the numbers are as asked."""


def _emit(notes: Iterable[str], stacklevel: int = 3) -> None:
    for note in notes:
        warnings.warn(note, ImuWarning, stacklevel=stacklevel)
