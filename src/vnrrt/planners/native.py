"""The C answer to a free straight segment (:mod:`vnrrt.planners._straight`, built by
``setup.py`` where a C compiler is found), bound to the numba-compiled segment test.

:func:`answerer` returns that C function, or :func:`vnrrt.planners.run.free_answer` (the
same answer in Python) where the extension is not built or cannot be bound. Both give the
same result field by field (tested); the C one makes a ``plan()`` call on a free segment
~1.6 us shorter (~2 us instead of ~3.6 us): the kernel is called through its C address,
without numba's dispatch, and the result is built without the interpreter. Its
``time_to_stop`` is the kernel call's own time; the Python one's also holds the dispatch
(~0.5 us). :func:`built` says which is in use.

:data:`planned` is ``plan()``'s whole call in C for its common form of arguments (RRT*, a
validated config with ``straight_first``, ...: see its comment), :data:`solved`
``Planner.solve``'s: the arguments recognised and the answer made without the interpreter
(~1 us a call instead of ~2 us; cold, after a 64 MB flush, ~10x a bare Python call's cold
time instead of ~19x: ``bench_cold_call.py``). Any
other form, and any call before :func:`answerer` has bound the kernel, gets None: the caller
then checks the arguments in Python, as before.
"""

from __future__ import annotations

import functools
import logging

from numba import cfunc, types

from vnrrt.planners import core, run
from vnrrt.planners.config import PlannerConfig
from vnrrt.planners.result import PlanResult

log = logging.getLogger(__name__)

SIGNATURE = types.float64(types.CPointer(types.uint8), types.intp, types.intp, types.float64,
                          types.float64, types.float64, types.float64)  # fmt: skip
KERNELS = []  # the compiled C function bound to the extension, kept alive with the process


@functools.cache
def answerer():
    """The free straight segment's answer function, ``answer(occ, sx, sy, gx, gy, target,
    planner, reference_length, setup_time, fallback) -> PlanResult | (d, seconds)``
    (:func:`vnrrt.planners.run.free_answer`): the C one when built and bound, else the
    Python one (a warning logged when binding fails)."""
    try:
        from vnrrt.planners import _straight
    except ImportError as error:
        log.info("the C straight answer is not built (%s): using the Python one", error)
        return run.free_answer
    try:
        from vnrrt.planners.api import Planner  # (api imports this module)

        kernel = cfunc(SIGNATURE, cache=True)(core.query_test_at)
        _straight.bind(kernel.address, PlanResult, run.STRAIGHT, PlannerConfig, Planner)
    except Exception as error:  # any failure: the Python answer, and a warning
        log.warning("the C straight answer could not be bound (%r): using the Python one", error)
        return run.free_answer
    KERNELS.append(kernel)
    return _straight.answer


def _not_built(*args) -> None:
    """:data:`planned` and :data:`solved` where the extension is not built: never an answer."""
    return None


# planned(grid, start, goal, planner, heatmap, config, sampler, stop, reference_length, seed,
# milestones, keep_tree): plan()'s answer made in C when its arguments have the common form
# and the C answer is bound (answerer()): the straight answer's PlanResult, or the (d, seconds)
# of a segment tested that does not answer; else None (plan() then checks them in Python).
# solved(planner, start, goal, stop, reference_length, seed, milestones, keep_tree): the same
# for Planner.solve (the Planner first).
try:
    from vnrrt.planners._straight import plan as planned
    from vnrrt.planners._straight import solve as solved
except ImportError:
    planned = solved = _not_built


def built() -> bool:
    """Whether free straight segments are answered in C (:func:`answerer`)."""
    return answerer() is not run.free_answer


def described() -> str:
    """One line saying which answer is in use, for the benchmarks' output."""
    return f"free straight segments answered in {'C' if built() else 'Python'} ({__name__})"
