"""Keystrokes per second on this machine: in-process, and on a Dask LocalCluster of 1 and 2
single-threaded worker processes; and the cluster's own cost per task.

    pip install "./piano-py[dask]"
    python piano-py/bench/cluster_throughput.py [--runs 60] [--duration 0.3] [--repeat 3]

Each sweep is a pressed touch from 1 to 40 N (`--runs` levels, `--duration` s each). The
cluster's cost per task is measured with tasks that do nothing (`client.map` of a no-op,
results gathered as they finish, as `piano_action.sweep` does). Best of `--repeat` rounds.
"""

from __future__ import annotations

import argparse
import os
import time

import piano_action as pa


def noop(x):
    return x


def best(f, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=60)
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    from distributed import Client, LocalCluster, as_completed

    grid = {"touch": "pressed", "start": 1.0, "stop": 40.0, "runs": a.runs,
            "duration_s": a.duration}
    print(f"{a.runs} pressed keystrokes of {a.duration} s; {os.cpu_count()} cores; "
          f"load {os.getloadavg()[0]:.2f}")
    levels = pa.sweep_levels("pressed", 1.0, 40.0, a.runs)
    serial = best(lambda: [pa.sweep_row("pressed", v, a.duration) for v in levels], a.repeat)
    print(f"in-process, one thread:  {a.runs / serial:7.1f} runs/s ({1e3 * serial / a.runs:.1f} ms per run)")
    threads = best(lambda: pa.sweep(grid, progress=False), a.repeat)
    print(f"in-process, all threads: {a.runs / threads:7.1f} runs/s")
    reference = None
    for n in (1, 2):
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.run(lambda: __import__("piano_action"))  # imports outside the timing
            pa.sweep({**grid, "runs": 2}, client=client, progress=False)  # warm up
            table = None

            def run():
                nonlocal table
                table = pa.sweep(grid, client=client, progress=False)

            wall = best(run, a.repeat)
            reference = reference or table.to_csv()
            assert table.to_csv() == reference
            tasks = 2000

            def empty():
                for _ in as_completed(client.map(noop, range(tasks), pure=False)):
                    pass

            over = best(empty, a.repeat)
            print(f"LocalCluster, {n} worker(s): {a.runs / wall:7.1f} runs/s; "
                  f"an empty task costs {1e3 * over / tasks:.2f} ms of wall time "
                  f"({tasks / over:.0f} tasks/s)")


if __name__ == "__main__":
    main()
