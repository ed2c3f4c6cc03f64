"""The clock of :func:`time.perf_counter`, read from compiled code, so that a planner run
can time itself without returning to Python (:func:`vnrrt.planners.loop.drive`).

On 64-bit Linux ``time.perf_counter()`` is ``clock_gettime(CLOCK_MONOTONIC)`` in seconds;
:func:`monotonic` reads the same clock from inside a numba function (about 40 ns a read,
through libc's vDSO call). Elsewhere (:data:`IN_KERNEL` False) the planners keep their
timing in Python and never compile this.
"""

from __future__ import annotations

import sys

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

CLOCK_MONOTONIC = 1  # Linux's clock id (every architecture)
IN_KERNEL = sys.platform.startswith("linux") and sys.maxsize > 2**32  # 64-bit time_t, long


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


@njit(cache=True)
def monotonic() -> float:
    """Seconds on the clock of ``time.perf_counter()`` (64-bit Linux only: :data:`IN_KERNEL`)."""
    return _monotonic_ns() / 1e9  # as perf_counter converts: (double) ns / 1e9
