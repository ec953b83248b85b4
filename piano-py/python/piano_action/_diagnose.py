"""Diagnoses: one dataset, or many on this machine or mapped over a Dask cluster."""

from __future__ import annotations

import json
import os
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

from . import _core
from ._errors import InputError, PianoError
from ._sweep import Progress, _cores, _progress_reporter

PathLike = Union[str, "os.PathLike[str]"]


def diagnose(dataset: PathLike, out: PathLike, params: Optional[_core.Params] = None,
             library: Optional[str] = None, write_params: Optional[PathLike] = None,
             force: bool = False) -> Dict[str, Any]:
    """Diagnoses the dataset in the folder ``dataset`` as ``piano diagnose`` does and
    returns its report (``report.json``, which it writes into ``out`` with ``report.md``
    and ``report.html``): the decision (``named``, ``ambiguous``, ``partly_explained``,
    ``none`` or ``unexplained``), the gap before and after, the noise check a name must
    pass, the candidates and the calibrated values.
    The key ``"written"`` lists the files written, and ``"params_refused"`` says why a
    ``write_params`` file was not written (a model that does not explain the data or explains it only in part, a value
    at the edge of its search range), when it was not. ``library`` names the effects to try
    (comma-separated ids, all by default); ``write_params`` asks for the corrected
    parameter file (swing tests only); ``out`` is not replaced unless ``force``."""
    written, refused = _core.diagnose_to_disk(
        os.fspath(dataset), os.fspath(out), params, library,
        None if write_params is None else os.fspath(write_params), force)
    report = json.loads((Path(out) / "report.json").read_text())
    report["written"] = written
    if refused is not None:
        report["params_refused"] = refused
    return report


#: The columns of :class:`DiagnosisTable`.
COLUMNS = ("dataset", "out", "experiment", "decision", "effect", "fit_before_um",
           "fit_after_um", "heldout_before_um", "heldout_after_um", "noise_floor_um", "error")


class DiagnosisTable:
    """One row per dataset, in the order given: where its report went, the decision, the
    effect named (if one), the gaps (µm, RMS per coordinate) and, for a dataset whose
    diagnosis failed, why (``error``). ``reports`` holds each ``report.json`` (None for a
    failed row)."""

    def __init__(self, rows: List[Dict[str, Any]], reports: List[Optional[Dict[str, Any]]]):
        self.rows = rows
        self.reports = reports

    def __len__(self) -> int:
        return len(self.rows)

    def __repr__(self) -> str:
        return f"DiagnosisTable({len(self)} datasets, {len(self.errors())} failed)"

    def errors(self) -> List[tuple]:
        """The datasets whose diagnosis failed: (row index, why)."""
        return [(i, r["error"]) for i, r in enumerate(self.rows) if r["error"]]

    def to_csv(self) -> str:
        """The rows as CSV (empty cells where a value does not apply)."""
        def cell(v: Any) -> str:
            if v is None:
                return ""
            text = _core.format_number(v) if isinstance(v, float) else str(v)
            return text.replace(",", ";").replace("\n", " ")

        lines = [",".join(COLUMNS)]
        lines += [",".join(cell(r[c]) for c in COLUMNS) for r in self.rows]
        return "\n".join(lines) + "\n"

    def to_pandas(self):
        """The rows as a pandas DataFrame (pandas must be installed)."""
        import pandas as pd

        return pd.DataFrame.from_records(self.rows, columns=list(COLUMNS))


def _um(x: Optional[float]) -> Optional[float]:
    return None if x is None else x * 1e6


def _row(dataset: str, out: str, report: Optional[Dict[str, Any]], error: Optional[str],
         experiment: Optional[str]) -> Dict[str, Any]:
    row: Dict[str, Any] = dict.fromkeys(COLUMNS)
    row.update(dataset=dataset, out=out, error=error)
    if report is None:
        return row
    gap = report.get("gap", report)  # a swing test's gaps are under "gap", a key drive's not
    effects = [e.get("id") for e in report.get("effects") or [] if isinstance(e, dict)]
    row.update(
        experiment=experiment,
        decision=report.get("decision"),
        effect="+".join(effects) or None,
        fit_before_um=_um(gap.get("before_rms_m")),
        fit_after_um=_um(gap.get("after_rms_m")),
        heldout_before_um=_um(gap.get("heldout_before_rms_m")),
        heldout_after_um=_um(gap.get("heldout_after_rms_m")),
        noise_floor_um=_um(gap.get("noise_floor_m")),
    )
    return row


def _diagnose_task(dataset: str, out: str, params: Optional[_core.Params],
                   library: Optional[str], force: bool) -> Dict[str, Any]:
    """One diagnosis (what a worker runs): its report, or the error as a string."""
    try:
        report = diagnose(dataset, out, params, library, None, force)
    except (PianoError, _core.PanicException) as e:
        return {"error": f"{e}" if isinstance(e, PianoError) else f"{type(e).__name__}: {e}"}
    try:
        experiment = json.loads((Path(dataset) / "dataset.json").read_text())["experiment"]
    except (OSError, ValueError, KeyError, TypeError):
        experiment = None
    return {"report": report, "experiment": experiment}


def diagnose_many(datasets: Sequence[PathLike], out: PathLike, client: Any = None,
                  params: Optional[_core.Params] = None, library: Optional[str] = None,
                  force: bool = False, progress: Progress = True,
                  workers: Optional[int] = None) -> DiagnosisTable:
    """Diagnoses every dataset folder in ``datasets``, each report into ``out/<name>``
    (``<name>`` the dataset folder's name; names must differ), and returns one row per
    dataset in the order given.

    With ``client`` (a ``dask.distributed.Client``), each diagnosis is one task on the
    cluster, whose workers must see the same files (a shared file system, as on Slurm or
    PBS clusters); without it they run on this machine's threads (``workers``). A diagnosis
    that fails (a dataset that does not pass its data check, a task the cluster loses)
    fails its own row, the ``error`` column saying why; the others go on. Each report equals
    what ``piano diagnose DATASET --out out/<name>`` writes. ``out`` holding earlier
    reports is refused row by row unless ``force``.
    """
    if isinstance(datasets, (str, bytes, os.PathLike)):
        raise InputError("diagnose_many: 'datasets' is a list of dataset folders, got one "
                         f"path ({os.fspath(datasets)!r}); pass [it]", field="datasets",
                         kind="argument")
    datasets = [os.fspath(d) for d in datasets]
    if not datasets:
        raise InputError("diagnose_many: no datasets given", field="datasets", kind="argument")
    names = [Path(d).resolve().name for d in datasets]
    if "" in names:
        raise InputError("diagnose_many: a dataset is a folder with a name (not the root)",
                         field="datasets", kind="argument")
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise InputError(f"diagnose_many: two datasets share the folder name {dupes[0]!r}, "
                         "so their reports would share a folder; rename one",
                         field="datasets", kind="argument")
    outs = [os.fspath(Path(out) / n) for n in names]
    total = len(datasets)
    results: List[Optional[Dict[str, Any]]] = [None] * total
    report = _progress_reporter(progress, total, "diagnoses")

    def finish(i: int, get: Callable[[], Dict[str, Any]]) -> None:
        try:
            results[i] = get()
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as e:  # a lost worker, a cancelled task: this row fails
            results[i] = {"error": f"{type(e).__name__}: {e}"}

    if client is None:
        with ThreadPoolExecutor(max_workers=workers or _cores()) as pool:
            futures = {pool.submit(_diagnose_task, d, o, params, library, force): i
                       for i, (d, o) in enumerate(zip(datasets, outs))}
            for k, fut in enumerate(as_completed(futures), 1):
                finish(futures[fut], fut.result)
                report(k)
    else:
        from distributed import as_completed as dask_completed

        futures = client.map(_diagnose_task, datasets, outs, [params] * total,
                             [library] * total, [force] * total, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        for k, fut in enumerate(dask_completed(futures), 1):
            finish(index[fut.key], fut.result)
            report(k)
    rows, reports = [], []
    for d, o, r in zip(datasets, outs, results):
        r = r or {"error": "no result"}
        reports.append(r.get("report"))
        rows.append(_row(d, o, r.get("report"), r.get("error"), r.get("experiment")))
    return DiagnosisTable(rows, reports)
