"""Sweeps: one keystroke per touch level (and per parameter set), on this machine's cores or
mapped over a Dask cluster, into one table that equals ``piano sweep``'s CSV."""

from __future__ import annotations

import itertools
import math
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

from . import _core
from ._errors import InputError

#: What fails one row rather than the whole sweep: an error, or a panic of the Rust code
#: (which Python sees as a BaseException).
FAILURES = (Exception, _core.PanicException)

#: What a grid may hold (see :func:`sweep`).
GRID_KEYS = ("touch", "values", "start", "stop", "runs", "linear", "duration_s", "model",
             "params", "set")

Progress = Union[bool, Callable[[int, int], None]]


class SweepTable:
    """The rows of a sweep, in the order of the grid (not of completion).

    ``header`` is the list of column names: the parameter paths of the grid's ``set``, if
    any, then ``piano sweep``'s columns. ``to_csv()`` gives the text ``piano sweep`` writes
    for the same levels (with the parameter columns in front when ``set`` was given).
    """

    def __init__(self, header: List[str], lines: List[str]):
        self.header = header
        self._lines = lines

    def __len__(self) -> int:
        return len(self._lines)

    def __repr__(self) -> str:
        failed = len(self.errors())
        return f"SweepTable({len(self)} rows, {failed} failed)"

    def to_csv(self) -> str:
        """The table as CSV text, header first, one line per run, ending in a newline."""
        return ",".join(self.header) + "\n" + "".join(line + "\n" for line in self._lines)

    def records(self) -> List[Dict[str, Any]]:
        """One dict per row: numbers as floats (``strikes`` an int), empty cells as None,
        ``touch``, ``unit`` and ``error`` as strings (``error`` None for a run that
        worked)."""
        out = []
        for line in self._lines:
            cells = line.split(",", len(self.header) - 1)
            out.append({name: _cell(name, cell) for name, cell in zip(self.header, cells)})
        return out

    def column(self, name: str):
        """A column as a numpy array of floats (NaN where empty); ``touch``, ``unit`` and
        ``error`` as a list of strings."""
        import numpy as np

        if name not in self.header:
            raise InputError(f"no column '{name}' (columns: {', '.join(self.header)})",
                             field=name, kind="argument")
        values = [r[name] for r in self.records()]
        if name in ("touch", "unit", "error"):
            return values
        return np.array([math.nan if v is None else float(v) for v in values])

    def errors(self) -> List[Tuple[int, str]]:
        """The rows whose run failed: (row index, why)."""
        return [(i, r["error"]) for i, r in enumerate(self.records()) if r["error"]]

    def to_pandas(self):
        """The table as a pandas DataFrame (pandas must be installed)."""
        import pandas as pd

        return pd.DataFrame.from_records(self.records(), columns=self.header)


def _cell(name: str, cell: str) -> Any:
    if name in ("touch", "unit"):
        return cell
    if name == "error":
        return cell or None
    if cell == "":
        return None
    if name == "strikes":
        return int(cell)
    return float(cell)


def _task(touch: str, value: float, duration_s: float, model: str,
          params: Optional[_core.Params]) -> str:
    """One row (module-level, so it pickles by reference)."""
    return _core.sweep_row(touch, value, duration_s, model, params)


def _batch(items: Sequence[Tuple[Any, ...]], task: Callable[..., str]) -> List[str]:
    """The rows of one cluster task: several keystrokes, so that the cluster's own cost per
    task (a millisecond or more) stays small beside them (about 12 ms each)."""
    rows = []
    for item in items:
        try:
            rows.append(task(*item))
        except InputError:
            raise  # a wrong argument is the caller's, not this row's
        except FAILURES as e:  # this keystroke's row fails, not the batch
            touch, value = item[0], item[1]
            rows.append(_core.sweep_failed_row(touch, value, f"{type(e).__name__}: {e}"))
    return rows


def _expand(grid: Mapping[str, Any]):
    """The grid's tasks: (parameter values, touch, level, duration, model, params)."""
    if not isinstance(grid, Mapping):
        raise InputError(f"a sweep grid is a dict, got {type(grid).__name__}", field="grid",
                         kind="argument")
    unknown = sorted(set(grid) - set(GRID_KEYS))
    if unknown:
        raise InputError(f"unknown grid key(s) {', '.join(unknown)} "
                         f"(known: {', '.join(GRID_KEYS)})", field=unknown[0], kind="argument")
    touch = grid.get("touch", "struck")
    if "values" in grid:
        for k in ("start", "stop", "runs", "linear"):
            if k in grid:
                raise InputError(f"give either 'values' or '{k}', not both", field=k,
                                 kind="argument")
        given = grid["values"]
        if isinstance(given, (str, bytes)) or not hasattr(given, "__iter__"):
            raise InputError(f"'values' is a list of levels, got {given!r}", field="values",
                             kind="argument")
        values = []
        for i, v in enumerate(given):
            try:
                values.append(float(v))
            except (TypeError, ValueError):
                raise InputError(f"values[{i}]: {v!r} is not a number", field=f"values[{i}]",
                                 kind="argument") from None
            try:
                _core.check_sweep_levels(touch, [values[-1]])
            except InputError as e:
                if e.field == "touch":
                    raise
                raise InputError(f"values[{i}]: {e.message}", field=f"values[{i}]",
                                 kind="argument") from None
        if not values:
            raise InputError("'values' is empty: a sweep needs at least one level",
                             field="values", kind="argument")
    else:
        runs = grid.get("runs", 100)
        if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
            raise InputError(f"'runs' is a whole number of runs, at least 1, got {runs!r}",
                             field="runs", kind="argument")
        values = _core.sweep_levels(touch, grid.get("start"), grid.get("stop"), runs,
                                    bool(grid.get("linear", False)))
    duration_s = float(grid.get("duration_s", 0.3))
    model = grid.get("model", "double")
    _core.check_sweep(model, duration_s)  # before any run, on any cluster
    base = grid.get("params") or _core.Params()
    if not isinstance(base, _core.Params):
        raise InputError(f"'params' is a piano_action.Params, got {type(base).__name__}",
                         field="params", kind="argument")
    settings: Mapping[str, Sequence[float]] = grid.get("set") or {}
    if not isinstance(settings, Mapping):
        raise InputError("'set' maps parameter paths to lists of values, "
                         f"got {type(settings).__name__}", field="set", kind="argument")
    for p, vs in settings.items():
        if isinstance(vs, (str, bytes)) or not hasattr(vs, "__iter__"):
            raise InputError(f"'set': the values of {p} are a list, got {vs!r}",
                             field=f"set.{p}", kind="argument")
        if len(list(vs)) == 0:
            raise InputError(f"'set': no values for {p}", field=f"set.{p}", kind="argument")
    paths = list(settings)
    combos: Iterable[Tuple[float, ...]] = itertools.product(
        *[[float(v) for v in settings[p]] for p in paths]) if paths else [()]
    tasks = []
    for combo in combos:
        params = base
        if paths:
            params = base.copy()
            for p, v in zip(paths, combo):
                params.set(p, v)  # raises InputError naming the path or the value
        for value in values:
            tasks.append((combo, touch, value, duration_s, model, params))
    return paths, tasks


def sweep(grid: Mapping[str, Any], client: Any = None, progress: Progress = True,
          workers: Optional[int] = None, batch: Optional[int] = None) -> SweepTable:
    """Runs one keystroke per point of ``grid`` and returns the table.

    ``grid`` is a dict:

    - ``touch``: ``"force"`` (constant key-front force, N), ``"pressed"`` (peak force of a
      pressed touch, N) or ``"struck"`` (finger speed, m/s); ``"struck"`` by default;
    - the levels: ``values`` (a list), or ``start``, ``stop``, ``runs`` and ``linear`` as
      ``piano sweep``'s ``--from``, ``--to``, ``--runs`` and ``--linear`` (same defaults);
    - ``duration_s`` (0.3 s by default) and ``model`` (``"double"`` by default);
    - ``params``: a :class:`Params` (the reference by default);
    - ``set``: ``{parameter path: [values]}``; every combination is run at every level
      (parameter sets outer, levels inner), its values in the first columns.

    With ``client`` (a ``dask.distributed.Client``: a ``LocalCluster`` on a laptop, or a
    Slurm or PBS cluster from ``dask-jobqueue``), the keystrokes run as tasks on the
    cluster (``batch`` of them per task); without it, on this machine's threads
    (``workers``, one per core this process may use by default). A wrong grid (a model, a
    duration, a level, a parameter path or value) raises :class:`InputError` before any
    run. Rows come back as they finish (``progress``: True prints a progress
    line to stderr, a callable gets ``(done, total)``, False nothing) and are put in the
    grid's order. A run that fails fails its own row (the ``error`` column says why), and a
    task the cluster loses fails the rows it held; the others go on. The numbers equal
    ``piano sweep``'s to the bit.

    ``batch`` keystrokes make one cluster task; by default about four tasks per worker
    thread, so that the cluster's own cost (about a millisecond per task, on its scheduler)
    stays small beside the keystrokes (about 12 ms each) while the load still balances.
    """
    paths, tasks = _expand(grid)
    total = len(tasks)
    lines: List[Optional[str]] = [None] * total
    report = _progress_reporter(progress, total)

    def done(i: int, line: str) -> None:
        combo = tasks[i][0]
        prefix = "".join(f"{_fmt(v)}," for v in combo)
        lines[i] = prefix + line

    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise InputError(f"'workers' is a number of threads, at least 1, got {workers!r}",
                         field="workers", kind="argument")
    if client is None:
        n = workers or _cores()
        with ThreadPoolExecutor(max_workers=n) as pool:
            futures = {pool.submit(_task, *t[1:]): i for i, t in enumerate(tasks)}
            from concurrent.futures import as_completed

            for k, fut in enumerate(as_completed(futures), 1):
                i = futures[fut]
                done(i, _line_or_failure(tasks[i], fut.result))
                report(k)
    else:
        from distributed import as_completed

        if batch is None:
            threads = sum(client.nthreads().values()) or 1
            batch = max(1, -(-total // (4 * threads)))
        if not isinstance(batch, int) or batch < 1:
            raise InputError(f"batch: a task holds at least one keystroke, got {batch!r}",
                             field="batch", kind="argument")
        chunks = [list(range(i, min(i + batch, total))) for i in range(0, total, batch)]
        futures = client.map(_batch, [[tasks[i][1:] for i in c] for c in chunks],
                             task=_task, pure=False)
        index = {f.key: c for f, c in zip(futures, chunks)}
        k = 0
        for fut in as_completed(futures):
            chunk = index[fut.key]
            try:
                rows = fut.result()
            except InputError:
                raise
            except (KeyboardInterrupt, SystemExit):
                raise
            except BaseException as e:  # a lost worker, a cancelled task: its rows fail
                rows = [_failed(tasks[i], e) for i in chunk]
            for i, line in zip(chunk, rows):
                done(i, line)
            k += len(chunk)
            report(k)
    header = paths + _core.sweep_header().split(",")
    return SweepTable(header, [line for line in lines if line is not None])


def _line_or_failure(task, result: Callable[[], str]) -> str:
    """The task's row, or a failed row saying why (a wrong argument raises)."""
    try:
        return result()
    except InputError:
        raise
    except FAILURES as e:
        return _failed(task, e)


def _failed(task, e: BaseException) -> str:
    """The row of a task that raised `e`: this row fails, not the sweep."""
    _, touch, value, _, _, _ = task
    return _core.sweep_failed_row(touch, value, f"{type(e).__name__}: {e}")


def _cores() -> int:
    """The cores this process may run on (a Slurm or cgroup allocation, not the machine's)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _fmt(v: float) -> str:
    return _core.format_number(v)


def _progress_reporter(progress: Progress, total: int,
                       what: str = "runs") -> Callable[[int], None]:
    """What `progress` asks for, called with the number done: a callable gets
    ``(done, total)``; True draws a bar on stderr when it is a terminal, and otherwise
    writes a line at every tenth (a log stays readable); False nothing."""
    if callable(progress):
        return lambda k: progress(k, total)
    if not progress:
        return lambda k: None
    terminal = sys.stderr.isatty()
    step = max(1, total // (50 if terminal else 10))
    shown = [0]

    def report(k: int) -> None:
        if k - shown[0] >= step or k == total:
            shown[0] = k
            if terminal:
                width = 30
                filled = width * k // total
                sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {k}/{total} {what}")
                if k == total:
                    sys.stderr.write("\n")
            else:
                sys.stderr.write(f"{k}/{total} {what} done\n")
            sys.stderr.flush()

    return report
