"""Errors are Python exceptions that name the file, the line and the field."""

from __future__ import annotations

import numpy as np
import pytest

import piano_action as pa
from conftest import ROOT, SCENARIOS


def test_a_wrong_scenario_file_names_file_line_and_field(tmp_path, piano):
    bad = tmp_path / "bad.toml"
    bad.write_text('model = "double"\nduration_s = 0.2\n\n[input]\nkind = "force"\n'
                   'force_n = -5.0\n')
    with pytest.raises(pa.InputError) as info:
        pa.simulate(bad)
    e = info.value
    assert isinstance(e, ValueError) and isinstance(e, pa.PianoError)
    assert e.file == str(bad) and e.line == 6 and e.field == "input.force_n"
    assert e.kind == "scenario"
    # The same words as the command line's.
    cli = piano("simulate", bad, "--out", tmp_path / "out", check=False)
    assert cli.returncode != 0 and str(e) in cli.stderr


def test_a_wrong_parameter_file(tmp_path):
    text = pa.Params().to_toml().replace("mass_g = ", "mass_g = -", 1)
    bad = tmp_path / "params.toml"
    bad.write_text(text)
    with pytest.raises(pa.InputError) as info:
        pa.Params.load(bad)
    e = info.value
    assert e.file == str(bad) and e.line is not None and e.field.endswith("mass_g")
    assert text.splitlines()[e.line - 1].lstrip().startswith("mass_g = -")


def test_a_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(pa.PianoFileError) as info:
        pa.simulate(tmp_path / "nowhere.toml")
    assert isinstance(info.value, OSError)
    assert info.value.file == str(tmp_path / "nowhere.toml")


def test_a_wrong_dict_names_the_field_without_a_line():
    with pytest.raises(pa.InputError) as info:
        pa.simulate({"model": "double", "duration_s": 0.2,
                     "input": {"kind": "touch", "style": "pressed", "peak_force_nn": 3.0}})
    e = info.value
    assert e.line is None and "peak_force_nn" in str(e)
    with pytest.raises(pa.InputError) as info:
        pa.simulate({"model": "upright", "duration_s": 0.2,
                     "input": {"kind": "force", "force_n": 3.0}})
    assert info.value.field == "model"
    with pytest.raises(pa.InputError):
        pa.simulate(42)


def test_parameters_refuse_what_the_file_would():
    p = pa.Params()
    with pytest.raises(pa.InputError) as info:
        p.set("hammer.mass_gg", 10.0)
    assert "hammer.mass_g" in str(info.value)  # the suggestion
    before = p.get("hammer.mass_g")
    with pytest.raises(pa.InputError) as info:
        p.set("hammer.mass_g", -1.0)
    assert info.value.field == "hammer.mass_g"
    assert p.get("hammer.mass_g") == before  # unchanged


def test_absurd_durations_and_levels():
    with pytest.raises(pa.InputError) as info:
        pa.simulate({"model": "double", "duration_s": 1e9,
                     "input": {"kind": "force", "force_n": 3.0}})
    assert info.value.field == "duration_s"
    with pytest.raises(pa.InputError):
        pa.sweep_row("struck", float("nan"))
    with pytest.raises(pa.InputError) as info:
        pa.sweep_row("tickled", 1.0)
    assert "force, pressed or struck" in str(info.value)
    with pytest.raises(pa.InputError):
        pa.sweep({"touch": "pressed", "values": [1.0, -3.0]})


def test_a_wrong_mechanism_description_names_its_file_and_field(tmp_path):
    text = (ROOT / "examples" / "mechanisms" / "glockenspiel.toml").read_text()
    bad = tmp_path / "bad.toml"
    changed = text.replace("\nmass = ", "\nmass = -", 1)
    bad.write_text(changed)
    line = changed[:changed.index("\nmass = -") + 1].count("\n") + 1
    with pytest.raises(pa.InputError) as info:
        pa.Mechanism.load(bad)
    e = info.value
    assert e.kind == "mechanism description" and e.file == str(bad)
    assert e.line == line and e.field.endswith("mass")


def test_a_wrong_sweep_grid_raises_before_any_run():
    for grid in ({"touch": "force", "values": [5.0], "model": "quad"},
                 {"touch": "force", "values": [5.0], "duration_s": -1.0},
                 {"touch": "force", "values": [5.0], "set": {"hammer.mass_g": 11.0}},
                 {"touch": "force", "values": [5.0], "set": {"hammer.mass_gg": [11.0]}}):
        with pytest.raises(pa.InputError):
            pa.sweep(grid, progress=False)


def test_wrong_sweep_arguments_name_the_argument():
    cases = [({"touch": "pressed", "values": [1.0, float("nan")]}, "values[1]"),
             ({"touch": "pressed", "values": [1.0, "a"]}, "values[1]"),
             ({"touch": "pressed", "values": 5}, "values"),
             ({"touch": "pressed", "runs": -5}, "runs"),
             ({"touch": "pressed", "runs": 2.7}, "runs"),
             ({"touch": "pressed", "velocity": 3}, "velocity")]
    for grid, field in cases:
        with pytest.raises(pa.InputError) as info:
            pa.sweep(grid, progress=False)
        assert info.value.field == field, (grid, str(info.value))
        assert info.value.message and isinstance(info.value, ValueError)
    with pytest.raises(pa.InputError) as info:
        pa.diagnose_many(str(SCENARIOS), "out")
    assert info.value.field == "datasets"


def test_a_scenario_reads_back_what_it_writes():
    s = pa.Scenario.load(SCENARIOS / "key_motion_csv.toml")
    again = pa.Scenario.from_toml(s.to_toml(), base=SCENARIOS)
    assert np.array_equal(pa.simulate(s).q, pa.simulate(again).q)
    assert pa.Params() == pa.Params() and pa.Params() != 3
    p = pa.Params()
    p.set("hammer.mass_g", 12.0)
    assert p != pa.Params()
