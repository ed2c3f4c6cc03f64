"""The compiled clock against time.perf_counter (the clock of every reported time)."""

import time

from vnrrt.planners import clock


def test_the_compiled_clock_is_perf_counters():
    """monotonic() read between two perf_counter() reads lies between them (same clock)."""
    clock.monotonic()
    for _ in range(100):
        a = time.perf_counter()
        b = clock.monotonic()
        c = time.perf_counter()
        assert a <= b <= c
