"""The clock of :func:`time.perf_counter`, read from compiled code, so that a planner run
times itself inside its one compiled call (:func:`vnrrt.planners.run.grow_tree`).

:func:`monotonic` returns seconds. On 64-bit Linux ``time.perf_counter()`` is
``clock_gettime(CLOCK_MONOTONIC)``, read here directly (about 40 ns a read, through libc's
vDSO call); elsewhere it calls ``time.perf_counter`` in numba's object mode (about a
microsecond a read).
"""

from __future__ import annotations

import sys
import time

from llvmlite import ir
from numba import njit, objmode, types
from numba.core import cgutils
from numba.extending import intrinsic

CLOCK_MONOTONIC = 1  # Linux's clock id (every architecture)
LINUX_64 = sys.platform.startswith("linux") and sys.maxsize > 2**32  # 64-bit time_t, long


@intrinsic
def _monotonic_ns(typingctx):
    """``clock_gettime(CLOCK_MONOTONIC)`` as int64 nanoseconds (a ``struct timespec`` of two
    64-bit fields on the stack)."""

    def codegen(context, builder, signature, args):
        i32, i64 = ir.IntType(32), ir.IntType(64)
        timespec = ir.LiteralStructType([i64, i64])
        fnty = ir.FunctionType(i32, [i32, timespec.as_pointer()])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
        ts = cgutils.alloca_once(builder, timespec)
        builder.call(fn, [ir.Constant(i32, CLOCK_MONOTONIC), ts])
        sec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 0))
        nsec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 1))
        return builder.add(builder.mul(sec, ir.Constant(i64, 1_000_000_000)), nsec)

    return types.int64(), codegen


if LINUX_64:

    @njit(cache=True)
    def monotonic() -> float:
        """Seconds on the clock of ``time.perf_counter()``."""
        return _monotonic_ns() / 1e9  # as perf_counter converts: (double) ns / 1e9

else:

    @njit(cache=True)
    def monotonic() -> float:
        """Seconds on the clock of ``time.perf_counter()`` (read in object mode)."""
        with objmode(t="float64"):
            t = time.perf_counter()
        return t
