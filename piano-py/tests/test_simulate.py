"""`simulate` gives the command line's numbers, to the bit, as numpy arrays and objects."""

from __future__ import annotations

import csv
import json
import sys
import threading
import time

import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10 and older
    import tomli as tomllib

import piano_action as pa
from conftest import ROOT, SCENARIOS


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return header, np.array([[float(x) for x in r] for r in body])


@pytest.mark.parametrize("name", ["struck_forte", "pressed_piano", "mass_drop_1kg",
                                  "key_motion_csv", "force_ramp_release"])
def test_simulate_equals_the_command_line(name, piano, tmp_path):
    path = SCENARIOS / f"{name}.toml"
    out = tmp_path / "run"
    piano("simulate", path, "--out", out)
    run = pa.simulate(path)

    header, traj = read_csv(out / "trajectory.csv")
    names = run.coordinate_names
    assert header[0] == "time_s"
    assert header[1:1 + 2 * len(names)] == [f"{n}_q" for n in names] + [f"{n}_v" for n in names]
    assert run.t.shape == (traj.shape[0],)
    assert run.q.shape == run.v.shape == (traj.shape[0], len(names))
    # Identical, not close: both are the same Rust code, and the CSV writes every digit.
    assert np.array_equal(run.t, traj[:, 0])
    assert np.array_equal(run.q, traj[:, 1:1 + len(names)])
    assert np.array_equal(run.v, traj[:, 1 + len(names):1 + 2 * len(names)])
    if "key_drive_force_n" in header:
        assert np.array_equal(run.key_drive_force_n, traj[:, header.index("key_drive_force_n")])
    assert np.array_equal(run.states[:, :len(names)], run.q)

    summary = json.loads((out / "summary.json").read_text())
    assert run.summary() == summary
    events = json.loads((out / "events.json").read_text())
    assert [(e.name, e.time_s) for e in run.events] == [(e["name"], e["time_s"]) for e in events]
    assert [s.hammer_velocity_m_s for s in run.strikes] == \
        [s["hammer_velocity_m_s"] for s in summary["strikes"]]
    assert run.let_off_time_s == summary["let_off_time_s"]
    assert run.check_time_s == summary["check_time_s"]


def test_contacts_equal_the_command_lines(piano, tmp_path):
    path = SCENARIOS / "struck_forte.toml"
    out = tmp_path / "run"
    piano("simulate", path, "--out", out)
    header, table = read_csv(out / "contacts.csv")
    contacts = pa.simulate(path).contacts()
    assert len(contacts) * 7 == len(header) - 1
    for name, cols in contacts.items():
        for key in ("gap_mm", "force_n", "px_mm", "py_mm", "nx", "ny"):
            column = table[:, header.index(f"{name}_{key}")]
            assert np.array_equal(cols[key], column), (name, key)
        assert np.array_equal(cols["active"], table[:, header.index(f"{name}_active")] == 1)
    # The physics, not only the plumbing: the hammer presses the string at the strike.
    run = pa.simulate(path)
    strike = run.strikes[0].time_s
    i = int(np.searchsorted(run.t, strike + 0.5e-3))
    assert contacts["hammer_string"]["force_n"][i] > 10.0


def test_a_dict_is_the_same_scenario_as_its_file():
    path = SCENARIOS / "pressed_piano.toml"
    as_dict = tomllib.loads(path.read_text())
    a, b = pa.simulate(path), pa.simulate(as_dict)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.v, b.v)
    c = pa.simulate(pa.Scenario.from_toml(path.read_text()))
    assert np.array_equal(a.q, c.q)
    assert pa.Scenario.load(path).duration_s == as_dict["duration_s"]


def test_a_harder_touch_strikes_faster():
    def speed(force):
        run = pa.simulate({"model": "double", "duration_s": 0.15,
                           "input": {"kind": "force", "force_n": force}})
        return run.strikes[0].hammer_velocity_m_s

    slow, fast = speed(5.0), speed(30.0)
    assert 0.5 < slow < fast < 10.0


def test_params_change_the_run_and_travel_to_workers():
    import pickle

    p = pa.Params()
    mass = p.get("hammer.mass_g")
    heavy = p.copy()
    heavy.set("hammer.mass_g", mass * 1.3)
    assert p.get("hammer.mass_g") == mass and heavy.get("hammer.mass_g") == mass * 1.3
    scen = {"model": "double", "duration_s": 0.1, "input": {"kind": "force", "force_n": 20.0}}
    v_ref = pa.simulate(scen).strikes[0].hammer_velocity_m_s
    v_heavy = pa.simulate(scen, heavy).strikes[0].hammer_velocity_m_s
    assert v_heavy < v_ref
    back = pickle.loads(pickle.dumps(heavy))
    assert back.get("hammer.mass_g") == heavy.get("hammer.mass_g")
    assert back.to_toml() == heavy.to_toml()
    paths = {path: (value, unit, tags) for path, value, unit, tags in p.paths()}
    assert paths["hammer.mass_g"][0] == mass and paths["hammer.mass_g"][1] == "g"
    assert pa.Params.from_toml(p.to_toml()).get("hammer.mass_g") == mass


def test_the_gil_is_released_while_simulating():
    # While one thread is inside `simulate`, another runs Python. With no forced switches
    # (a switch interval of 1000 s) a thread holding the GIL keeps it until it blocks or
    # lets it go: had `simulate` held it, this thread would run again only once the other
    # had finished, and would count nothing. (Counts iterations, not time; the other thread
    # simulates again, up to 20 times, until this one has been scheduled.)
    scen = {"model": "double", "duration_s": 0.3,
            "input": {"kind": "touch", "style": "pressed", "peak_force_n": 2.0}}
    inside = threading.Event()
    finished = threading.Event()
    seen = [0]

    def work():
        try:
            inside.set()
            for _ in range(20):
                pa.simulate(scen)
                if seen[0] > 0:
                    break
        finally:
            finished.set()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=work)
        t.start()
        inside.wait()
        while not finished.is_set():
            seen[0] += 1
            time.sleep(0)  # lets the other thread take the GIL back when it returns
        t.join(timeout=60)
    finally:
        sys.setswitchinterval(interval)
    assert seen[0] > 0


def test_the_swing_test_equals_the_command_line(piano, tmp_path):
    path = SCENARIOS / "pendulum.toml"
    out = tmp_path / "run"
    piano("simulate", path, "--out", out)
    swing = pa.simulate(path)
    assert isinstance(swing, pa.Swing)
    header, traj = read_csv(out / "trajectory.csv")
    assert header == ["time_s", "hammer_q", "hammer_v"]
    assert np.array_equal(swing.t, traj[:, 0])
    assert np.array_equal(swing.angle_rad, traj[:, 1])
    assert np.array_equal(swing.rate_rad_s, traj[:, 2])
    assert swing.summary() == json.loads((out / "summary.json").read_text())
    # Coulomb friction at the flange: the amplitude falls by the same step every half swing.
    amplitudes = [abs(a) for _, a in swing.turns]
    steps = np.diff(amplitudes)
    assert len(amplitudes) >= 3 and np.all(steps < 0)
    assert np.ptp(steps) < 0.05 * abs(steps.mean())


def test_a_mechanism_scenario_equals_the_command_line(piano, tmp_path):
    mechanism = ROOT / "examples" / "mechanisms" / "upright.toml"
    m = pa.Mechanism.load(mechanism)
    assert m.name and "hammer" in " ".join(m.bodies)
    scenario = tmp_path / "upright.toml"
    scenario.write_text(f'mechanism = "{mechanism}"\nduration_s = 0.1\n\n'
                        '[input]\nkind = "force"\nforce_n = 10.0\n')
    out = tmp_path / "run"
    piano("simulate", scenario, "--out", out)
    run = pa.simulate(scenario)
    assert isinstance(run, pa.MechanismRun)
    header, traj = read_csv(out / "trajectory.csv")
    n = len(run.coordinate_names)
    assert header[1:1 + n] == [f"{c}_q" for c in run.coordinate_names]
    assert np.array_equal(run.t, traj[:, 0])
    assert np.array_equal(run.q, traj[:, 1:1 + n])
    assert np.array_equal(run.v, traj[:, 1 + n:1 + 2 * n])
    assert run.summary() == json.loads((out / "summary.json").read_text())
    header, table = read_csv(out / "contacts.csv")
    contacts = run.contacts()
    assert len(contacts) * 6 == len(header) - 1
    for name, cols in contacts.items():
        for key in ("gap_mm", "force_n", "px_mm", "py_mm", "nx", "ny"):
            assert np.array_equal(cols[key], table[:, header.index(f"{name}_{key}")]), name
    # The hammer reaches its string within the 0.1 s of a 10 N push.
    assert max(cols["force_n"].max() for name, cols in contacts.items() if "string" in name) > 1
    # The same as a dict, its description's path relative to the working folder.
    as_dict = {"mechanism": str(mechanism), "duration_s": 0.1,
               "input": {"kind": "force", "force_n": 10.0}}
    assert np.array_equal(pa.simulate(as_dict).q, run.q)


def test_dict_values_as_python_and_numpy_give_them():
    base = {"model": "double", "duration_s": 0.1, "input": {"kind": "force", "force_n": 20.0}}
    numpy_typed = {"model": "double", "duration_s": np.float64(0.1),
                   "input": {"kind": "force", "force_n": np.float32(20.0)}}
    assert np.array_equal(pa.simulate(base).q, pa.simulate(numpy_typed).q)
    with pytest.raises(pa.InputError) as info:
        pa.simulate({**base, "input": {"kind": "force", "force_n": None}})
    assert info.value.field == "input.force_n" and "None" in str(info.value)
    with pytest.raises(pa.InputError) as info:
        pa.simulate({**base, "duration_s": float("nan")})
    assert info.value.field == "duration_s"
    with pytest.raises(pa.InputError) as info:
        pa.simulate({**base, "input": {"kind": "force", "force_n": object()}})
    assert info.value.field == "input.force_n"


def test_python_m_piano_action_simulates_every_kind_of_scenario():
    import subprocess

    for name in ("struck_forte", "pendulum"):
        done = subprocess.run([sys.executable, "-m", "piano_action", "simulate",
                               str(SCENARIOS / f"{name}.toml")], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert ("strike at" in done.stdout) if name == "struck_forte" else \
            ("turning points" in done.stdout)


def test_ctrl_c_stops_a_simulation():
    import _thread

    # A friction regularization this fine makes a keystroke take minutes (it then fails at
    # the step budget); Ctrl-C, simulated here, stops it at the next check.
    p = pa.Params()
    p.set("numerics.friction_regularization_m_s", 1e-12)
    p.set("numerics.pivot_friction_regularization_rad_s", 1e-12)
    # A shell's background job (`cmd &`) starts with SIGINT ignored, and Python then
    # installs no handler for it: Ctrl-C could not reach it, nor interrupt_main.
    import signal
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            pa.simulate({"model": "double", "duration_s": 0.3,
                         "input": {"kind": "touch", "style": "pressed", "peak_force_n": 10.0}},
                        p)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    # Nothing is left behind: the next run is as before.
    assert pa.simulate(SCENARIOS / "struck_forte.toml").strikes
