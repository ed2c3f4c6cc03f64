"""A bucket grid (spatial hash) for the nearest and near queries of the RRT* core.

The map ``[0, W) x [0, H)`` is cut into square buckets of side ``bucket`` pixels.
``head[by, bx]`` holds the last node inserted in a bucket and ``nxt[i]`` the node
inserted before ``i`` in the same bucket (-1 ends a list), so inserting is O(1) and all
storage is preallocated. Node positions are ``pts`` ``(N, 2)`` float64 (x, y).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def new_buckets(shape: tuple[int, int], bucket: float) -> np.ndarray:
    """Empty bucket heads ``(ceil(H / bucket), ceil(W / bucket))`` int64 (all -1)."""
    h, w = shape
    return np.full((math.ceil(h / bucket), math.ceil(w / bucket)), -1, dtype=np.int64)


@njit(cache=True, inline="always")
def _bucket_of(v, bucket, n):
    return min(max(int(v / bucket), 0), n - 1)


@njit(cache=True, inline="always")
def insert(head, nxt, bucket, i, x, y):
    """Add node ``i`` at ``(x, y)`` to the bucket grid."""
    by = _bucket_of(y, bucket, head.shape[0])
    bx = _bucket_of(x, bucket, head.shape[1])
    nxt[i] = head[by, bx]
    head[by, bx] = i


@njit(cache=True, inline="always")
def _scan(head, nxt, pts, by, bx, x, y, best, best_d2):
    i = head[by, bx]
    while i >= 0:
        d2 = (pts[i, 0] - x) ** 2 + (pts[i, 1] - y) ** 2
        if d2 < best_d2:
            best, best_d2 = i, d2
        i = nxt[i]
    return best, best_d2


@njit(cache=True, inline="always")
def nearest(head, nxt, pts, bucket, x, y):
    """Index of the node nearest to ``(x, y)`` (Euclidean), or -1 if the grid is empty.

    Rings of buckets at growing Chebyshev distance ``k`` are scanned; points beyond ring
    ``k`` are at least ``k * bucket`` away, which ends the search.
    """
    nby, nbx = head.shape
    by, bx = _bucket_of(y, bucket, nby), _bucket_of(x, bucket, nbx)
    best, best_d2 = -1, np.inf
    for k in range(max(nby, nbx)):
        for j in range(max(by - k, 0), min(by + k, nby - 1) + 1):
            edge_row = abs(j - by) == k
            step = 1 if edge_row or k == 0 else 2 * k
            for i in range(bx - k, bx + k + 1, step):
                if 0 <= i < nbx:
                    best, best_d2 = _scan(head, nxt, pts, j, i, x, y, best, best_d2)
        if best >= 0 and best_d2 <= (k * bucket) ** 2:
            break
    return best


@njit(cache=True, inline="always")
def near(head, nxt, pts, bucket, x, y, r, out_idx, out_d):
    """Nodes within distance ``r`` of ``(x, y)``: fills ``out_idx``/``out_d``, returns count."""
    nby, nbx = head.shape
    r2 = r * r
    k = 0
    for j in range(_bucket_of(y - r, bucket, nby), _bucket_of(y + r, bucket, nby) + 1):
        for b in range(_bucket_of(x - r, bucket, nbx), _bucket_of(x + r, bucket, nbx) + 1):
            i = head[j, b]
            while i >= 0:
                d2 = (pts[i, 0] - x) ** 2 + (pts[i, 1] - y) ** 2
                if d2 <= r2:
                    out_idx[k] = i
                    out_d[k] = math.sqrt(d2)
                    k += 1
                i = nxt[i]
    return k
