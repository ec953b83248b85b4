"""The grand piano action simulator from Python.

Keystrokes come back as numpy arrays; sweeps run on one machine or on a Dask cluster::

    import piano_action as pa

    run = pa.simulate({"model": "double", "duration_s": 0.2,
                       "input": {"kind": "touch", "style": "pressed", "peak_force_n": 10.0}})
    run.t, run.q, run.v            # numpy arrays on the output grid
    run.strikes[0].hammer_velocity_m_s

    table = pa.sweep({"touch": "pressed", "start": 1.0, "stop": 40.0, "runs": 20})
    table.column("hammer_velocity_m_s")

The numbers are those of the ``piano`` command line, to the bit: both run the same Rust
code (``piano_action._core``). Errors raise :class:`InputError` (a ``ValueError`` that
names the file, line and field), :class:`PianoFileError` (an ``OSError``) or
:class:`SimulationError` (a ``RuntimeError``), all :class:`PianoError`.
"""

from __future__ import annotations

from ._core import (
    Event,
    Mechanism,
    MechanismRun,
    Params,
    Run,
    Scenario,
    Strike,
    Swing,
    __version__,
    regulate,
    simulate,
    sweep_header,
    sweep_levels,
    sweep_row,
    synth,
    touchweight,
    validate,
)
from ._diagnose import DiagnosisTable, diagnose, diagnose_many
from ._errors import InputError, PianoError, PianoFileError, SimulationError
from ._sweep import SweepTable, sweep

__all__ = [
    "DiagnosisTable",
    "Event",
    "InputError",
    "Mechanism",
    "MechanismRun",
    "Params",
    "PianoError",
    "PianoFileError",
    "Run",
    "Scenario",
    "SimulationError",
    "Strike",
    "SweepTable",
    "Swing",
    "__version__",
    "diagnose",
    "diagnose_many",
    "regulate",
    "simulate",
    "sweep",
    "sweep_header",
    "sweep_levels",
    "sweep_row",
    "synth",
    "touchweight",
    "validate",
]
