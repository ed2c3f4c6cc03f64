"""A numba binary min-heap over parallel arrays (keys float64, values int64).

The heap lives in two preallocated arrays plus a size counter held in a 1-element
array, so the functions below can be called from other ``@njit`` code with no
Python objects. Duplicate values are allowed (lazy deletion is the caller's job).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def heap_new(capacity: int):
    """Return ``(keys, values, size)`` for an empty heap able to hold ``capacity`` items."""
    return np.empty(capacity, np.float64), np.empty(capacity, np.int64), np.zeros(1, np.int64)


@njit(cache=True)
def heap_push(keys, values, size, key, value):
    """Insert ``(key, value)``; grows nothing, so ``capacity`` must bound the pushes alive."""
    i = size[0]
    size[0] += 1
    while i > 0:
        parent = (i - 1) >> 1
        if keys[parent] <= key:
            break
        keys[i] = keys[parent]
        values[i] = values[parent]
        i = parent
    keys[i] = key
    values[i] = value


@njit(cache=True)
def heap_pop(keys, values, size):
    """Remove and return ``(key, value)`` with the smallest key. The heap must not be empty."""
    top_key = keys[0]
    top_value = values[0]
    size[0] -= 1
    n = size[0]
    key = keys[n]
    value = values[n]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= n:
            break
        if child + 1 < n and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= key:
            break
        keys[i] = keys[child]
        values[i] = values[child]
        i = child
    if n > 0:
        keys[i] = key
        values[i] = value
    return top_key, top_value
