"""Process-pool map with a progress bar that behaves in terminals and in plain logs."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from typing import TypeVar

from tqdm.auto import tqdm

T = TypeVar("T")
R = TypeVar("R")


def n_workers(requested: int) -> int:
    """Workers to use: ``requested`` if positive, else all cores this process may use."""
    if requested > 0:
        return requested
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def progress(iterable: Iterable[T], total: int, desc: str) -> Iterable[T]:
    """tqdm bar: live on a TTY, one line every 30 s in non-TTY logs (CI, dvc repro > log)."""
    tty = sys.stderr.isatty()
    return tqdm(iterable, total=total, desc=desc, mininterval=0.2 if tty else 30.0, ascii=not tty)


def parallel_map(
    fn: Callable[[T], R], items: list[T], workers: int = 0, desc: str = "", chunksize: int = 1
) -> list[R]:
    """``[fn(x) for x in items]`` in order, over a process pool of :func:`n_workers` workers.

    ``fn`` must be a picklable top-level function. With one worker (or one item) it runs
    in this process, which keeps tracebacks simple and avoids fork costs.
    """
    workers = min(n_workers(workers), max(1, len(items)))
    if workers == 1:
        return list(progress(map(fn, items), len(items), desc))
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(progress(pool.map(fn, items, chunksize=chunksize), len(items), desc))
