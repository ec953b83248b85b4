"""The exceptions of piano_action (raised by the extension, `piano_action._core`)."""

from __future__ import annotations

from typing import Optional


class PianoError(Exception):
    """Every error of piano_action.

    Attributes (None where they do not apply): ``kind`` (what kind of input: "parameter
    file", "scenario", "option", ...), ``file``, ``line`` (1-based), ``field`` (the field's
    path, ``hammer.mass_g`` or ``input.peak_force_n``) and ``message`` (what is wrong).
    ``str(error)`` says all of it in one line, as the command line prints it.
    """

    kind: Optional[str] = None
    file: Optional[str] = None
    line: Optional[int] = None
    field: Optional[str] = None
    message: Optional[str] = None

    def __init__(self, message: str = "", *, field: Optional[str] = None,
                 kind: Optional[str] = None) -> None:
        super().__init__(message)
        self.message = message
        self.field = field
        self.kind = kind


class InputError(PianoError, ValueError):
    """A wrong value in an input: a parameter file, a scenario, a sweep's levels or an
    argument."""


class PianoFileError(PianoError, OSError):
    """A file or folder that cannot be read or written (``file`` names it)."""


class SimulationError(PianoError, RuntimeError):
    """A simulation that could not be done; the message says when and why."""
