"""``python -m piano_action``: the command line's main commands from Python.

    python -m piano_action simulate SCENARIO.toml [--params FILE] [--json]
    python -m piano_action sweep --touch pressed --from 1 --to 40 --runs 20 --out sweep.csv
        [--duration 0.3] [--model double] [--params FILE] [--scheduler ADDRESS] [--force]
    python -m piano_action touchweight | regulate | validate [--model M] [--params FILE]
    python -m piano_action diagnose DATASET... --out DIR [--library IDS] [--params FILE]
        [--scheduler ADDRESS] [--force]

``sweep`` writes the CSV that ``piano sweep`` writes for the same options; ``touchweight``,
``regulate`` and ``validate`` print the JSON of ``piano ... --json``; ``diagnose`` writes
each dataset's report into DIR/<dataset folder name> and prints one line per dataset.
With ``--scheduler`` sweeps and diagnoses run on that Dask cluster. Errors print one line
naming the file, line and field, and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import List, Optional

from . import (MechanismRun, Params, PianoError, Swing, diagnose_many, regulate, simulate, sweep,
               touchweight, validate)


def _params(path: Optional[str]) -> Optional[Params]:
    return Params.load(path) if path else None


def _simulate(a: argparse.Namespace) -> int:
    run = simulate(a.scenario, _params(a.params))
    if a.json:
        print(json.dumps(run.summary(), indent=2))
        return 0
    if isinstance(run, Swing):
        print(f"hammer swing: {len(run.turns)} turning points in {run.t[-1]:g} s")
        return 0
    if isinstance(run, MechanismRun):
        print(f"{run.mechanism}: {len(run.t)} output points")
        for name, value, unit in run.metrics:
            print(f"  {name}: {'-' if value is None else f'{value:.4g} {unit}'}")
        return 0
    print(f"{run.model} action, {len(run.t)} output points")
    for s in run.strikes:
        print(f"strike at {s.time_s * 1e3:.2f} ms: hammer {s.hammer_velocity_m_s:.3f} m/s")
    if not run.strikes:
        print("no strike")
    for name, t in (("let-off", run.let_off_time_s), ("check", run.check_time_s),
                    ("key bottom", run.key_bottom_time_s)):
        if t is not None:
            print(f"{name} at {t * 1e3:.2f} ms")
    return 0


def _sweep(a: argparse.Namespace) -> int:
    out = Path(a.out)
    if out.exists() and not a.force:
        raise PianoError(f"{out}: exists; choose another --out, or pass --force to replace it")
    if not out.parent.is_dir():
        raise PianoError(f"{out}: its folder {out.parent} does not exist")
    grid = {"touch": a.touch, "runs": a.runs, "linear": a.linear, "duration_s": a.duration,
            "model": a.model}
    if a.start is not None:
        grid["start"] = a.start
    if a.stop is not None:
        grid["stop"] = a.stop
    if a.params:
        grid["params"] = Params.load(a.params)
    client = _client(a.scheduler)
    try:
        table = sweep(grid, client=client)
    finally:
        if client is not None:
            client.close()
    out.write_text(table.to_csv())
    print(f"{len(table)} runs, {len(table.errors())} failed; table: {out}")
    return 0


def _client(address: Optional[str]):
    if not address:
        return None
    from distributed import Client

    return Client(address)


def _analysis(a: argparse.Namespace) -> int:
    run = {"touchweight": touchweight, "regulate": regulate, "validate": validate}[a.command]
    result = run(_params(a.params), a.model)
    result.pop("params", None)  # regulate's Params object (the command line's JSON has none)
    print(json.dumps(result, indent=2))
    return 0


def _diagnose(a: argparse.Namespace) -> int:
    client = _client(a.scheduler)
    try:
        table = diagnose_many(a.datasets, a.out, client=client, params=_params(a.params),
                              library=a.library, force=a.force, progress=len(a.datasets) > 1)
    finally:
        if client is not None:
            client.close()
    for row in table.rows:
        if row["error"]:
            print(f"{row['dataset']}: failed: {row['error']}")
        else:
            effect = f" ({row['effect']})" if row["effect"] else ""
            print(f"{row['dataset']}: {row['decision']}{effect}; report in {row['out']}")
    return 0 if not table.errors() else 1


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m piano_action", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("simulate", help="run a scenario file and print its strikes and times")
    s.add_argument("scenario")
    s.add_argument("--params", help="a parameter file (the reference by default)")
    s.add_argument("--json", action="store_true", help="print the summary as JSON")
    w = sub.add_parser("sweep", help="one keystroke per touch level, into a CSV file")
    w.add_argument("--touch", default="struck", choices=["force", "pressed", "struck"])
    w.add_argument("--from", dest="start", type=float)
    w.add_argument("--to", dest="stop", type=float)
    w.add_argument("--runs", type=int, default=100)
    w.add_argument("--linear", action="store_true")
    w.add_argument("--duration", type=float, default=0.3)
    w.add_argument("--model", default="double")
    w.add_argument("--params")
    w.add_argument("--scheduler", help="a Dask scheduler's address (tcp://host:8786)")
    w.add_argument("--out", required=True)
    w.add_argument("--force", action="store_true", help="replace an existing --out")
    for name, what in (("touchweight", "the static touchweight (gf)"),
                       ("regulate", "regulate the action into the literature's bands"),
                       ("validate", "the validation experiments against the literature")):
        c = sub.add_parser(name, help=what)
        c.add_argument("--model", default="double")
        c.add_argument("--params")
    d = sub.add_parser("diagnose", help="diagnose datasets (swing test or key drive)")
    d.add_argument("datasets", nargs="+")
    d.add_argument("--out", required=True, help="reports go to OUT/<dataset folder name>")
    d.add_argument("--library", help="the effects to try (comma-separated ids)")
    d.add_argument("--params")
    d.add_argument("--scheduler", help="a Dask scheduler's address (tcp://host:8786)")
    d.add_argument("--force", action="store_true", help="replace earlier reports")
    a = parser.parse_args(argv)
    commands = {"simulate": _simulate, "sweep": _sweep, "touchweight": _analysis,
                "regulate": _analysis, "validate": _analysis, "diagnose": _diagnose}
    try:
        return commands[a.command](a)
    except PianoError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # a Dask scheduler that does not answer, a file system error
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
