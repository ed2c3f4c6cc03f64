"""Native OMPL (C++) as a planner baseline: build the harness of ``harness.cpp`` against the
system's OMPL (Debian: ``apt-get install -y libompl-dev g++``, OMPL 1.5.2) and run it.

The harness runs in its own process and answers one query at a time over a pipe, so a
benchmark alternates it with our planners in the same run; its times are measured inside it,
in C++, from the start of OMPL's ``solve()`` (OMPL's setup apart, reported as ``setup``).

    with Harness(build(), seed=1) as native:
        native.set_map(grid)
        run = native.solve("BITstar", start, goal, bound=1.01 * exact, limit=2.0)
"""

from __future__ import annotations

import glob
import hashlib
import math
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "harness.cpp"
BUILD = HERE / "build"  # git ignores it (.gitignore beside this file)
INSTALL = "apt-get install -y libompl-dev g++  (Debian/Ubuntu, as root)"
PLANNERS = ("RRTstar", "InformedRRTstar", "BITstar", "ABITstar", "AITstar")
RRT_CONNECT = "RRTConnect"  # also answered: not an optimizer, it stops at its first solution


class HarnessError(RuntimeError):
    """The native OMPL harness cannot be built or answered badly; the message says why."""


def _flags() -> list[str]:
    """Compiler flags for OMPL: pkg-config's include paths, else Debian's known locations."""
    include = sorted(glob.glob("/usr/include/ompl-*"))
    try:
        out = subprocess.run(["pkg-config", "--cflags", "ompl"], capture_output=True,
                             text=True, check=True).stdout.split()  # fmt: skip
        include = [f[2:] for f in out if f.startswith("-I")]
    except (OSError, subprocess.CalledProcessError):
        include += ["/usr/include/eigen3"]
    if not any(Path(d, "ompl", "base", "Planner.h").is_file() for d in include):
        raise HarnessError(f"OMPL headers not found (looked in {include}); install: {INSTALL}")
    return [f"-I{d}" for d in include]


def build(out_dir: Path = BUILD) -> Path:
    """The harness binary, compiled when missing or when ``harness.cpp`` changed (the binary is
    named after the source's hash; written to a temporary name, then renamed). Raises
    :class:`HarnessError` naming the missing piece and how to install it."""
    digest = hashlib.sha256(SOURCE.read_bytes()).hexdigest()[:12]
    binary = Path(out_dir) / f"harness-{digest}"
    if binary.is_file():
        return binary
    cxx = shutil.which("g++") or shutil.which("c++")
    if cxx is None:
        raise HarnessError(f"no C++ compiler (g++) on PATH; install: {INSTALL}")
    binary.parent.mkdir(parents=True, exist_ok=True)
    tmp = binary.with_name(f"{binary.name}.tmp-{os.getpid()}")
    cmd = [cxx, "-O2", "-std=c++17", str(SOURCE), "-o", str(tmp), *_flags(), "-lompl"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        tmp.unlink(missing_ok=True)
        tail = "\n".join(done.stderr.strip().splitlines()[-5:])
        raise HarnessError(f"building the OMPL harness failed ({INSTALL}?):\n{tail}")
    tmp.replace(binary)
    for old in binary.parent.glob("harness-*"):  # builds of earlier sources
        if old != binary and ".tmp-" not in old.name:
            old.unlink(missing_ok=True)
    return binary


def build_or_explain() -> Path | None:
    """:func:`build`, or None after saying on stderr why it failed and how to install what
    is missing (a benchmark then exits 2)."""
    try:
        return build()
    except HarnessError as err:
        print(f"cannot build the native OMPL harness: {err}", file=sys.stderr)
        return None


@dataclass(frozen=True)
class NativeRun:
    """One native OMPL solve: seconds from the start of ``solve()`` to the first solution and
    to the stop bound (NaN: not reached), seconds of setup (space, problem, planner,
    ``setup()``), the final path ``(K, 2)`` (x, y) px (``(0, 2)``: none) and its length."""

    first: float
    stop: float
    setup: float
    cost: float
    path: np.ndarray


class Harness:
    """A running harness process (a context manager); ``seed`` seeds OMPL's RNG once."""

    def __init__(self, binary: Path, seed: int = 1):
        self._proc = subprocess.Popen([str(binary), str(int(seed))], stdin=subprocess.PIPE,
                                      stdout=subprocess.PIPE, text=True, bufsize=1)  # fmt: skip

    def __enter__(self) -> Harness:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self._proc.poll() is None:
            self._proc.stdin.write("quit\n")
            self._proc.stdin.close()
            self._proc.wait(timeout=30)

    def set_map(self, grid: np.ndarray) -> None:
        """The ``(H, W)`` occupancy (nonzero = obstacle, ``grid[y, x]``) of the next solves."""
        g = np.asarray(grid) != 0
        cells = "".join(np.where(g.ravel(), "1", "0"))
        self._proc.stdin.write(f"map {g.shape[0]} {g.shape[1]} {cells}\n")
        self._answer("mapped", "a map")

    def flush(self, nbytes: int) -> None:
        """Write and read ``nbytes`` bytes of a buffer in the harness process (evicting the
        CPU caches its next solve would find warm), and wait for its answer."""
        self._proc.stdin.write(f"flush {int(nbytes)}\n")
        self._answer("flushed", "a flush")

    def _answer(self, expected: str, what: str) -> None:
        """Read the harness's one answer line to a command, which must start with
        ``expected``; raise :class:`HarnessError` quoting it otherwise."""
        answer = self._proc.stdout.readline().strip()
        if not answer.startswith(expected):
            raise HarnessError(f"the harness answered {answer!r} to {what}")

    def solve(self, planner: str, start, goal, bound: float, limit: float,
              step: float = 0.0) -> NativeRun:  # fmt: skip
        """Run ``planner`` (one of :data:`PLANNERS`, or :data:`RRT_CONNECT`) until its cost
        reaches ``bound`` px or ``limit`` s (RRT-Connect: until its first solution);
        ``step``: the Steer range of the RRT planners (0: OMPL's default)."""
        numbers = (step, *start, *goal, bound, limit)
        line = f"solve {planner} " + " ".join(repr(float(v)) for v in numbers) + "\n"
        self._proc.stdin.write(line)
        answer = self._proc.stdout.readline().strip()
        if not answer or answer.startswith("error"):
            raise HarnessError(f"the harness answered {answer!r} to {line.strip()!r}")
        fields = dict(kv.split("=", 1) for kv in answer.split(" "))
        pts = [p.split(",") for p in fields["path"].split(";") if p]
        path = np.array(pts, dtype=np.float64).reshape(-1, 2)
        return NativeRun(float(fields["first"]), float(fields["stop"]), float(fields["setup"]),
                         float(fields["cost"]) if path.size else math.inf, path)  # fmt: skip
