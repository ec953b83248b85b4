"""Shared fixtures: the repository's paths and the `piano` command line to compare with."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "piano-action" / "scenarios"


@pytest.fixture(scope="session")
def piano_bin() -> Path:
    """The `piano` binary: `PIANO_BIN` if set, else built by cargo (debug, as `cargo test`
    builds it; the numbers do not depend on the profile)."""
    given = os.environ.get("PIANO_BIN")
    if given:
        return Path(given)
    subprocess.run(["cargo", "build", "-q", "-p", "piano-action", "--bin", "piano"], cwd=ROOT,
                   check=True)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "debug" / "piano"


@pytest.fixture(scope="session")
def piano(piano_bin):
    """Runs `piano ARGS...`; returns the completed process (check its returncode)."""

    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
        done = subprocess.run([str(piano_bin), *map(str, args)], cwd=ROOT, capture_output=True,
                              text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"piano {' '.join(map(str, args))} failed:\n{done.stderr}")
        return done

    return run


def without_timing(report):
    """A diagnosis report without what the clock measured (`throughput`'s wall times and
    rates), which differs from run to run; the work counts stay."""
    out = dict(report)
    out.pop("written", None)
    out["throughput"] = [{k: v for k, v in stage.items()
                          if not (k.endswith("_per_s") or k == "wall_s")}
                         for stage in report.get("throughput", [])]
    return out
