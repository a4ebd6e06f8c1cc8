"""Running a study's designs: in this process, or on Dask.

On Dask the designs go out in chunks (a few per worker, so that a slow chunk does not
hold the others up); each worker process loads each FMU once and reuses it
(:func:`dyadfmu.sweep.runs.slave`). With no scheduler address a local cluster of
``workers`` processes (one thread each: an FMU instance is not shared between threads)
is started and closed around the study. Every run is independent of the others and
starts from a reset FMU, so the table is the same whatever the number of workers.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from typing import TextIO

import numpy as np

from .runs import run_rows

__all__ = ["run_serial", "run_dask", "Progress"]


class Progress:
    """A progress bar on a terminal (a line at the end elsewhere): designs done, rate."""

    def __init__(self, total: int, stream: TextIO | None = None, width: int = 30):
        self.total, self.done, self.width = total, 0, width
        self.stream = stream if stream is not None else sys.stderr
        self.started = time.perf_counter()
        self.live = hasattr(self.stream, "isatty") and self.stream.isatty()

    def restart(self) -> None:
        """Time the rate from now."""
        self.started = time.perf_counter()

    def seconds(self) -> float:
        """Seconds since the start (or the restart)."""
        return time.perf_counter() - self.started

    def advance(self, count: int) -> None:
        """``count`` more designs done."""
        self.done += count
        if self.live:
            self.stream.write("\r" + self.line())
            self.stream.flush()

    def line(self) -> str:
        """The bar as text."""
        filled = self.width * self.done // max(self.total, 1)
        rate = self.done / max(time.perf_counter() - self.started, 1e-9)
        return (
            f"[{'#' * filled}{'.' * (self.width - filled)}] {self.done}/{self.total} "
            f"designs, {rate:.1f} runs/s"
        )

    def close(self) -> None:
        """The final line."""
        self.stream.write(("\r" if self.live else "") + self.line() + "\n")
        self.stream.flush()


def _chunks(designs: np.ndarray, size: int) -> list:
    rows = [(k, tuple(map(float, row))) for k, row in enumerate(designs)]
    return [rows[k : k + size] for k in range(0, len(rows), size)]


def run_serial(run: Callable, designs: np.ndarray, progress: Progress | None = None) -> list:
    """[(index, Outcome)] of every design, one after another in this process."""
    out = []
    for chunk in _chunks(designs, 64):
        out += run_rows(run, chunk)
        if progress is not None:
            progress.advance(len(chunk))
    return out


def _client(scheduler: str | None, workers: int):
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        return Client(scheduler), None
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,  # the progress bar says how it goes
    )
    return Client(cluster), cluster


def run_dask(
    run: Callable,
    designs: np.ndarray,
    workers: int,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> list:
    """[(index, Outcome)] of every design, on a Dask cluster (a local one of ``workers``
    processes unless ``scheduler`` gives an address)."""
    from dask.distributed import as_completed

    client, cluster = _client(scheduler, workers)
    try:
        slots = max(workers if scheduler is None else len(client.scheduler_info()["workers"]), 1)
        size = max(1, min(512, -(-len(designs) // (4 * slots))))
        client.wait_for_workers(slots)
        if progress is not None:
            progress.restart()  # the cluster's start is not the runs' time
        remote = client.scatter(run, broadcast=True)
        futures = [
            client.submit(run_rows, remote, chunk, pure=False) for chunk in _chunks(designs, size)
        ]
        out = []
        for future in as_completed(futures):
            rows = future.result()
            out += rows
            if progress is not None:
                progress.advance(len(rows))
        return sorted(out, key=lambda r: r[0])
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
