"""The sampler's generator state from a seed: numpy's ``SeedSequence(seed).generate_state(4,
uint64)``, bit for bit, in a compiled kernel (~1 us instead of numpy's ~30 us a call).

numpy's algorithm (``numpy/random/bit_generator.pyx``, O'Neill's seed_seq hashing): the seed
(an int, or a sequence of ints, each >= 0) becomes 32-bit words, least significant first (0
is one word ``0``; a sequence concatenates its items' words); a pool of 4 words is filled by
hashing them (and zeros, when fewer), then every pool word is mixed with every other and with
the words beyond the pool; the state is 8 words hashed out of the pool in turn, read as 4
little-endian ``uint64``. Seeds of other types go to numpy itself.
"""

from __future__ import annotations

import numbers

import numpy as np
from numba import njit

POOL = 4
INIT_A, MULT_A = 0x43B0D7E5, 0x931E8875
INIT_B, MULT_B = 0x8B51F9DD, 0x58F38DED
MIX_L, MIX_R = 0xCA01F9DD, 0x4973F715
MASK32 = 0xFFFFFFFF


@njit(cache=True, inline="always")
def _hashmix(value, hc):
    """numpy's ``hashmix``: returns the hashed value and the next hash constant."""
    value ^= hc
    hc = (hc * np.uint64(MULT_A)) & np.uint64(MASK32)
    value = (value * hc) & np.uint64(MASK32)
    return value ^ (value >> np.uint64(16)), hc


@njit(cache=True, inline="always")
def _mix(x, y):
    r = (np.uint64(MIX_L) * x - np.uint64(MIX_R) * y) & np.uint64(MASK32)
    return r ^ (r >> np.uint64(16))


@njit(cache=True)
def _state(words):
    """The (4,) uint64 state from the seed's 32-bit ``words`` (uint64 array, each < 2^32)."""
    pool = np.zeros(POOL, np.uint64)
    hc = np.uint64(INIT_A)
    for i in range(POOL):
        pool[i], hc = _hashmix(words[i] if i < len(words) else np.uint64(0), hc)
    for src in range(POOL):
        for dst in range(POOL):
            if src != dst:
                h, hc = _hashmix(pool[src], hc)
                pool[dst] = _mix(pool[dst], h)
    for src in range(POOL, len(words)):
        for dst in range(POOL):
            h, hc = _hashmix(words[src], hc)
            pool[dst] = _mix(pool[dst], h)
    out = np.zeros(POOL, np.uint64)
    hb = np.uint64(INIT_B)
    for i in range(2 * POOL):
        v = pool[i % POOL] ^ hb
        hb = (hb * np.uint64(MULT_B)) & np.uint64(MASK32)
        v = (v * hb) & np.uint64(MASK32)
        v ^= v >> np.uint64(16)
        out[i // 2] |= v << np.uint64(32 * (i % 2))
    if not out.any():  # the all-zero state is the one invalid xoshiro state
        out[0] = 1
    return out


def _words(seed) -> list[int] | None:
    """The seed's 32-bit words as numpy assembles them, or None for a seed of another type."""
    items = seed if isinstance(seed, tuple | list) else (seed,)
    words = []
    for n in items:
        if (type(n) is not int and not isinstance(n, numbers.Integral)) or n < 0:
            return None
        n = int(n)
        words.append(n & MASK32)
        n >>= 32
        while n:
            words.append(n & MASK32)
            n >>= 32
    return words


def rng_state(seed) -> np.ndarray:
    """Fresh xoshiro256** state ``(4,)`` uint64 derived from ``seed`` (int or int tuple):
    ``SeedSequence(seed).generate_state(4, np.uint64)``; the all-zero state (the one invalid
    xoshiro state) becomes ``[1, 0, 0, 0]``."""
    words = _words(seed)
    if words is not None:
        return _state(np.array(words, np.uint64))
    state = np.random.SeedSequence(seed).generate_state(4, dtype=np.uint64)
    if not state.any():
        state[0] = 1
    return state
