"""Hammer speed at the string against key force, for pressed touches and constant forces.

    pip install "./piano-py[dask]" matplotlib
    python examples/python/sweep_touches.py [--scheduler tcp://host:8786] [--out touches.png]

Without --scheduler it starts a Dask LocalCluster of two workers on this machine; with it,
it uses that cluster (one started by dask-jobqueue on Slurm, say). Either way each
keystroke is one task, and the table equals `piano sweep`'s.
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

import piano_action as pa  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scheduler", help="a Dask scheduler's address")
    ap.add_argument("--runs", type=int, default=24, help="levels per touch (24)")
    ap.add_argument("--out", default="touches.png")
    a = ap.parse_args()
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        client = Client(LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None))
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for touch, label, marker in (("pressed", "pressed touch (peak finger force)", "o"),
                                 ("force", "constant key-front force", "s")):
        table = pa.sweep({"touch": touch, "start": 1.0, "stop": 40.0, "runs": a.runs,
                          "duration_s": 0.3}, client=client)
        ax.plot(table.column("value"), table.column("hammer_velocity_m_s"), marker=marker,
                ms=4, label=label)
        for i, why in table.errors():
            print(f"{touch} row {i} failed: {why}")
    ax.set_xscale("log")
    ax.set_xlabel("key force (N)")
    ax.set_ylabel("hammer speed at the string (m/s)")
    ax.set_title("Double-escapement grand action, reference regulation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print(f"figure: {a.out}")
    client.close()


if __name__ == "__main__":
    main()
