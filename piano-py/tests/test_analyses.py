"""touchweight, regulate, validate, synth and diagnose give the command line's results."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import piano_action as pa
from conftest import ROOT, without_timing


def cli_json(piano, *args):
    return json.loads(piano(*args).stdout)


def test_touchweight_equals_the_command_line(piano):
    w = pa.touchweight()
    assert w == cli_json(piano, "touchweight", "--json")
    # The physics: the key goes down under more than it comes up with (friction), and the
    # balance weight sits in the grand's usual range.
    assert w["down_weight_gf"] > w["up_weight_gf"] > 0
    assert 30 < w["balance_weight_gf"] < 50


def test_regulate_equals_the_command_line(piano):
    r = pa.regulate()
    regulated = r.pop("params")
    assert r == cli_json(piano, "regulate", "--json")
    assert r["in_band"] and r["out_of_band"] == []
    settings = r["settings"]
    assert regulated.get("regulation.let_off_button_y_mm") == settings["let_off_button_y_mm"]


def test_validate_equals_the_command_line(piano):
    v = pa.validate()
    assert v == cli_json(piano, "validate", "--json")
    assert v["model"] == "double" and len(v["rows"]) >= 10


def test_synth_writes_the_command_lines_dataset(piano, tmp_path):
    a, b = tmp_path / "py", tmp_path / "cli"
    done = pa.synth(a, tmp_path / "py.truth.json", effect="air_drag", seed=5,
                    duration_s=1.0)
    assert done["runs"] == 2 and done["duration_s"] == 1.0
    piano("synth", "--effect", "air_drag", "--seed", "5", "--duration", "1", "--out", b,
          "--truth", tmp_path / "cli.truth.json")
    files = sorted(p.name for p in a.iterdir())
    assert files == sorted(p.name for p in b.iterdir()) and "dataset.json" in files
    for name in files:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert (tmp_path / "py.truth.json").read_bytes() == (tmp_path / "cli.truth.json").read_bytes()
    # Nothing is overwritten unless asked.
    with pytest.raises(pa.PianoError):
        pa.synth(a, tmp_path / "py.truth.json", seed=6)
    with pytest.raises(pa.InputError) as info:
        pa.synth(tmp_path / "x", tmp_path / "x.json", experiment="trampoline")
    assert "pendulum" in str(info.value)


def test_diagnose_equals_the_command_line(piano, tmp_path):
    dataset = ROOT / "examples" / "data" / "pendulum_viscous"
    r = pa.diagnose(dataset, tmp_path / "py")
    piano("diagnose", dataset, "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "report.json").read_text())
    written = r["written"]
    assert without_timing(r) == without_timing(cli)
    assert sorted(Path(p).name for p in written) == ["report.html", "report.json", "report.md"]
    # The hidden viscous flange is found, and its value is within its interval of the truth.
    truth = json.loads((ROOT / "examples" / "data" / "pendulum_viscous.truth.json").read_text())
    assert r["decision"] == "named" and r["effects"][0]["id"] == "pivot_viscous"
    found, c_true = r["effects"][0]["params"]["c_n_m_s"], truth["effect"]["c_n_m_s"]
    assert abs(found / c_true - 1) < 0.1
    with pytest.raises(pa.PianoError):  # the earlier report is not replaced
        pa.diagnose(dataset, tmp_path / "py")



def test_a_corrected_parameter_file_keeps_the_callers_changes(tmp_path):
    dataset = ROOT / "examples" / "data" / "pendulum_viscous"
    p = pa.Params()
    p.set("hammer.mass_g", p.get("hammer.mass_g") * 1.01)
    r = pa.diagnose(dataset, tmp_path / "out", params=p, write_params=tmp_path / "fixed.toml")
    if "params_refused" in r:
        pytest.fail(f"no corrected file: {r['params_refused']}")
    fixed = pa.Params.load(tmp_path / "fixed.toml")
    assert fixed.get("hammer.mass_g") == p.get("hammer.mass_g")
    assert str(tmp_path / "fixed.toml") in r["written"]
