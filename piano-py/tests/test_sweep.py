"""`sweep` equals `piano sweep`, on this machine's threads and on a Dask LocalCluster."""

from __future__ import annotations

import json
import math
import sys

import cloudpickle
import numpy as np
import pytest

import piano_action as pa
import piano_action._sweep as sweep_module
from conftest import without_timing

ARGS = dict(touch="pressed", start=1.0, stop=30.0, runs=6)
DURATION = 0.15


@pytest.fixture(scope="module")
def cli_csv(piano, tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "sweep.csv"
    piano("sweep", "--touch", ARGS["touch"], "--from", ARGS["start"], "--to", ARGS["stop"],
          "--runs", ARGS["runs"], "--duration", DURATION, "--out", out)
    return out.read_text()


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def grid(**more):
    return {**ARGS, "duration_s": DURATION, **more}


def test_on_threads_equals_the_command_line(cli_csv):
    table = pa.sweep(grid(), progress=False)
    assert table.to_csv() == cli_csv
    assert len(table) == ARGS["runs"]
    speeds = table.column("hammer_velocity_m_s")
    # A harder touch, a faster hammer (every level strikes in 0.15 s).
    assert np.all(np.isfinite(speeds)) and np.all(np.diff(speeds) > 0)
    assert table.errors() == []


def test_on_a_local_cluster_of_two_workers_equals_the_command_line(cli_csv, client):
    seen = []
    table = pa.sweep(grid(), client=client, progress=lambda done, total: seen.append((done, total)))
    assert table.to_csv() == cli_csv
    assert seen == [(k, ARGS["runs"]) for k in range(1, ARGS["runs"] + 1)]
    # Several keystrokes per task: the same table.
    seen.clear()
    table = pa.sweep(grid(), client=client, batch=4,
                     progress=lambda done, total: seen.append(done))
    assert table.to_csv() == cli_csv
    assert seen == [4, 6] or seen == [2, 6]


def test_parameter_grid_on_the_cluster(client):
    mass = pa.Params().get("hammer.mass_g")
    table = pa.sweep({"touch": "force", "values": [10.0, 30.0], "duration_s": 0.1,
                      "set": {"hammer.mass_g": [mass, 1.5 * mass]}}, client=client,
                     progress=False)
    assert table.header[0] == "hammer.mass_g"
    rec = table.records()
    assert [r["hammer.mass_g"] for r in rec] == [mass, mass, 1.5 * mass, 1.5 * mass]
    assert [r["value"] for r in rec] == [10.0, 30.0, 10.0, 30.0]
    # The heavier hammer is slower at the same force.
    assert rec[2]["hammer_velocity_m_s"] < rec[0]["hammer_velocity_m_s"]
    assert rec[3]["hammer_velocity_m_s"] < rec[1]["hammer_velocity_m_s"]
    # Each row as a run of its own would give it.
    heavy = pa.Params()
    heavy.set("hammer.mass_g", 1.5 * mass)
    alone = pa.sweep_row("force", 30.0, 0.1, "double", heavy)
    assert table.to_csv().splitlines()[4] == f"{pa._core.format_number(1.5 * mass)},{alone}"


def _failing_task(touch, value, duration_s, model, params):
    if value == 2.0:
        raise RuntimeError("worker lost")
    return pa.sweep_row(touch, value, duration_s, model, params)


@pytest.fixture
def by_value():
    # This module's functions travel to the workers by value, so they run the ones here.
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    yield
    cloudpickle.unregister_pickle_by_value(sys.modules[__name__])


def _lost_batch(items, task):
    if any(item[1] == 2.0 for item in items):
        raise OSError("worker lost")
    return sweep_module._batch(items, task)


def test_a_lost_task_fails_the_rows_it_held(client, monkeypatch, by_value):
    monkeypatch.setattr(sweep_module, "_batch", _lost_batch)
    table = pa.sweep({"touch": "force", "values": [1.5, 2.0, 3.0, 4.0], "duration_s": 0.05},
                     client=client, progress=False, batch=2)
    assert [i for i, _ in table.errors()] == [0, 1]
    assert all(why == "OSError: worker lost" for _, why in table.errors())
    assert table.records()[2]["error"] is None and table.records()[3]["error"] is None


def test_a_failed_task_fails_its_own_row(client, monkeypatch, by_value):
    monkeypatch.setattr(sweep_module, "_task", _failing_task)
    for c, batch in ((None, None), (client, None), (client, 2), (client, 3)):
        table = pa.sweep({"touch": "force", "values": [1.5, 2.0, 3.0], "duration_s": 0.05},
                         client=c, progress=False, batch=batch)
        assert len(table) == 3
        assert table.errors() == [(1, "RuntimeError: worker lost")]
        rec = table.records()
        assert rec[1]["value"] == 2.0 and rec[1]["strikes"] == 0
        assert rec[0]["error"] is None and rec[2]["error"] is None
        assert math.isnan(table.column("key_start_s")[1])


def test_python_m_piano_action_sweep_writes_the_same_csv(cli_csv, tmp_path):
    import subprocess

    out = tmp_path / "sweep.csv"
    cmd = [sys.executable, "-m", "piano_action", "sweep", "--touch", ARGS["touch"],
           "--from", str(ARGS["start"]), "--to", str(ARGS["stop"]), "--runs", str(ARGS["runs"]),
           "--duration", str(DURATION), "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert out.read_text() == cli_csv
    # It does not overwrite what is there unless asked.
    again = subprocess.run(cmd, capture_output=True, text=True)
    assert again.returncode == 2 and "--force" in again.stderr
    assert out.read_text() == cli_csv
    bad = subprocess.run(cmd[:-2] + ["--out", str(tmp_path / "x.csv"), "--runs", "0"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "runs" in bad.stderr and "Traceback" not in bad.stderr


def test_diagnose_many_on_the_cluster(client, tmp_path, piano):
    # Three datasets: a viscous flange, a clean one, and one that fails its data check.
    data = tmp_path / "data"
    pa.synth(data / "viscous", tmp_path / "viscous.json", effect="pivot_viscous", seed=2,
             duration_s=2.0)
    pa.synth(data / "clean", tmp_path / "clean.json", seed=4, duration_s=2.0)
    pa.synth(data / "broken", tmp_path / "broken.json", seed=4, duration_s=2.0)
    spec = json.loads((data / "broken" / "dataset.json").read_text())
    spec["fps"] = spec["fps"] * 2  # the frames are no longer at the declared rate
    (data / "broken" / "dataset.json").write_text(json.dumps(spec))
    names = ["viscous", "clean", "broken"]
    seen = []
    table = pa.diagnose_many([data / n for n in names], tmp_path / "reports", client=client,
                             progress=lambda done, total: seen.append(done))
    assert seen == [1, 2, 3]
    assert [r["dataset"] for r in table.rows] == [str(data / n) for n in names]
    viscous, clean, broken = table.rows
    assert viscous["decision"] == "named" and viscous["effect"] == "pivot_viscous"
    assert viscous["fit_after_um"] < viscous["fit_before_um"]
    assert clean["decision"] == "none" and clean["effect"] is None
    assert broken["decision"] is None and "fps" in broken["error"]
    assert table.errors() == [(2, broken["error"])]
    # Each report is the command line's.
    piano("diagnose", data / "viscous", "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "report.json").read_text())
    assert without_timing(table.reports[0]) == without_timing(cli)
    assert table.to_csv().splitlines()[0].startswith("dataset,out,experiment,decision")


def test_the_progress_line_of_a_log_is_a_line_per_tenth(capsys):
    pa.sweep({"touch": "force", "values": [5.0, 10.0, 20.0], "duration_s": 0.05})
    err = capsys.readouterr().err
    assert "\r" not in err  # stderr is not a terminal here
    assert err.splitlines() == ["1/3 runs done", "2/3 runs done", "3/3 runs done"]
