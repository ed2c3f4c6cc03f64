"""The C answer to a free straight segment (:mod:`vnrrt.planners._straight`, built by
``setup.py`` where a C compiler is found), bound to the numba-compiled segment test.

:func:`answerer` returns that C function, or :func:`vnrrt.planners.run.free_answer` (the
same answer in Python) where the extension is not built. Both give the same result field by
field, times apart (tested); the C one makes the call ~1.3 us shorter (a ~3.7 us ``plan()``
call on a free segment), the C-level kernel call saving numba's dispatch and the result
built without the interpreter. Its ``time_to_stop`` is the kernel's own time (Python's
includes the dispatch).
"""

from __future__ import annotations

import functools
import logging

from numba import carray, cfunc, types

from vnrrt.planners import core, run
from vnrrt.planners.result import PlanResult

log = logging.getLogger(__name__)

SIGNATURE = types.float64(types.CPointer(types.uint8), types.intp, types.intp, types.float64,
                          types.float64, types.float64, types.float64)  # fmt: skip


def query_test(ptr, h, w, sx, sy, gx, gy):
    """:func:`vnrrt.planners.core.query_test` with the straight segment tested, on the
    ``(h, w)`` C-order uint8 grid at ``ptr``; compiled as a C function by :func:`answerer`
    (not at import: numba's first load costs ~0.6 s)."""
    return core.query_test(carray(ptr, (h, w)), sx, sy, gx, gy, True)


@functools.cache
def answerer():
    """The free straight segment's answer function, ``answer(occ, sx, sy, gx, gy, target,
    planner, reference_length, setup_time, fallback) -> PlanResult | (d, seconds)``
    (:func:`vnrrt.planners.run.free_answer`): the C one when built, else the Python one."""
    try:
        from vnrrt.planners import _straight
    except ImportError as error:
        log.debug("the C straight answer is not built (%s): using the Python one", error)
        return run.free_answer
    kernel = cfunc(SIGNATURE, cache=True)(query_test)
    _straight.bind(kernel.address, PlanResult, run.STRAIGHT)
    return _straight.answer
