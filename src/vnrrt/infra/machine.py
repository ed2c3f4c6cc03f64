"""The machine a run's timings were made on, in a few words (the CPU model, the cores this
process may use, whether the CPU has native bf16): the committed metrics and the benchmark
files name it, since timings and bf16 trainings differ from one CPU to another."""

from __future__ import annotations

import os
import platform
import re
from pathlib import Path


def describe(cpuinfo: str | Path = "/proc/cpuinfo") -> str:
    """``'AMD EPYC 9R14, 2 cores, avx512_bf16'``: the CPU model without trademarks, clock
    and core count (``platform.processor()`` where ``cpuinfo`` is unreadable), the usable
    cores, ``avx512_bf16`` or ``avx2`` or nothing."""
    try:
        text = Path(cpuinfo).read_text()
    except OSError:
        text = ""
    model = _field(text, "model name") or platform.processor() or "unknown CPU"
    model = re.sub(r"\((R|TM|tm)\)|\bCPU\b|@ *[\d.]+ *GHz|\b\d+-Core Processor", "", model)
    flags = set(_field(text, "flags").split())
    simd = next((f for f in ("avx512_bf16", "avx2") if f in flags), "")
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return ", ".join(p for p in (" ".join(model.split()), f"{cores} cores", simd) if p)


def _field(cpuinfo: str, name: str) -> str:
    """The first CPU's value of field ``name`` in ``/proc/cpuinfo``'s text; ``""`` if none."""
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        if key.strip() == name:
            return value.strip()
    return ""
