"""Process-pool map with a progress bar that behaves in terminals and in plain logs, and
that stops cleanly on Ctrl-C.

Interrupts: pool workers ignore SIGINT (a terminal's Ctrl-C reaches the whole process group),
so only the parent reacts. On SIGINT or SIGTERM the parent cancels the pending work, kills
the workers and waits for them, then raises ``KeyboardInterrupt``; nothing is left running
and no worker is orphaned. A signal that arrives while the workers are being started is acted
on once they all are (a worker forked but not yet recorded by the pool would otherwise be
left running, and the interpreter's exit would wait for it). Results already written by a
stage stay (atomic writes).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager, nullcontext
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


def _ignore_sigint() -> None:
    """Pool worker initializer: leave Ctrl-C to the parent; SIGTERM ends the worker (it was
    forked while the parent deferred it, :func:`_deferred_signals`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextmanager
def _deferred_signals() -> Iterator[None]:
    """SIGINT and SIGTERM received inside the block are acted on (by the handlers in place
    before it) when it ends, the first one only. Main thread only."""
    got: list[int] = []
    old = {s: signal.signal(s, lambda signum, frame: got.append(signum))
           for s in (signal.SIGINT, signal.SIGTERM)}  # fmt: skip
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        if got:
            signal.raise_signal(got[0])


def _start_workers(pool: ProcessPoolExecutor, workers: int) -> None:
    """Start every worker of ``pool`` now (a no-op task each: with 'fork' the first submit
    starts them all, with 'spawn'/'forkserver' each submit starts one while none is idle)."""
    for _ in range(workers):
        pool.submit(int)


def _terminate(pool: ProcessPoolExecutor) -> None:
    """Cancel pending work, kill the workers and reap them, and let the pool's manager
    thread end (the interpreter's exit joins it): it must not wait for the call queue's
    feeder (which may block on a pipe no worker reads) nor for the rest of a result that a
    killed worker was sending."""
    # shutdown() drops the pool's references to these: take them first
    procs = list((getattr(pool, "_processes", None) or {}).values())
    calls = getattr(pool, "_call_queue", None)
    results = getattr(pool, "_result_queue", None)
    if calls is not None:
        calls.cancel_join_thread()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        p.kill()
    for p in procs:
        p.join(timeout=5)
    if results is not None:  # a worker killed while sending leaves a partial message that
        results._writer.close()  # the manager thread waits on: with no writer left, EOF


def parallel_map(
    fn: Callable[[T], R], items: list[T], workers: int = 0, desc: str = "", chunksize: int = 1
) -> list[R]:
    """``[fn(x) for x in items]`` in order, over a process pool of :func:`n_workers` workers.

    ``fn`` must be a picklable top-level function. With one worker (or one item) it runs
    in this process, which keeps tracebacks simple and avoids fork costs. SIGINT/SIGTERM:
    module doc.
    """
    workers = min(n_workers(workers), max(1, len(items)))
    if workers == 1:
        return list(progress(map(fn, items), len(items), desc))
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint)

    def stop(signum, frame):
        raise KeyboardInterrupt(f"signal {signum}")

    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, stop) if main else None
    try:
        with _deferred_signals() if main else nullcontext():
            _start_workers(pool, workers)
        results = list(progress(pool.map(fn, items, chunksize=chunksize), len(items), desc))
    except BaseException:
        _terminate(pool)
        raise
    finally:
        if main:
            signal.signal(signal.SIGTERM, previous)
    pool.shutdown(wait=True)
    return results
