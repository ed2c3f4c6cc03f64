"""MovingAI grid benchmark files (Sturtevant 2012; https://movingai.com/benchmarks/formats.html):
``.map`` maps and ``.scen`` scenario lists, read and written.

``.map``: the lines ``type octile``, ``height H``, ``width W``, ``map``, then ``H`` rows of
``W`` terrain characters. ``.``, ``G`` (ground) and ``S`` (swamp) are passable; ``@``, ``O``
(out of bounds), ``T`` (trees) and ``W`` (water) are not (:data:`PASSABLE`,
:data:`BLOCKED`). Row ``y`` of the file is row ``y`` of the grid, character ``x`` its column
``x``, so a MovingAI cell ``(x, y)`` is the vnrrt cell ``(x, y)`` (:mod:`vnrrt.grid`:
``grid[y, x]``, ``(0, 0)`` at the top left, 0 free, 1 obstacle).

``.scen``: a first line ``version 1`` (or ``version 1.0`` in older files), then one line per
query: bucket, map file, map width, map height, start x, start y, goal x, goal y, optimal
length (tab-separated; older files separate by spaces). The optimal length is that of an
8-connected path (costs 1 and sqrt(2)) that does not cut corners, as
:func:`vnrrt.search.astar` computes, rounded in the file (``version 1`` files: 6 significant
digits).

Every malformed file raises :class:`MovingAIError` (a :class:`~vnrrt.grid.GridError`) naming
the file and the line (1-based).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vnrrt.grid import FREE, OBSTACLE, GridError, as_occupancy

PASSABLE = frozenset(".GS")
BLOCKED = frozenset("@OTW")
VERSIONS = ("1", "1.0")


class MovingAIError(GridError):
    """A MovingAI ``.map`` or ``.scen`` file is malformed; the message names file and line."""


@dataclass(frozen=True)
class Scenario:
    """One query of a ``.scen`` file: cells ``(x, y)`` (:mod:`vnrrt.grid`), the optimal
    8-connected no-corner-cutting length in pixels as published, and the file line."""

    bucket: int
    map_name: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal: float
    line: int = field(default=0, compare=False)

    @property
    def start_point(self) -> tuple[float, float]:
        """The start cell's centre ``(x + 0.5, y + 0.5)``, a continuous point in pixels."""
        return self.start[0] + 0.5, self.start[1] + 0.5

    @property
    def goal_point(self) -> tuple[float, float]:
        """The goal cell's centre ``(x + 0.5, y + 0.5)``, a continuous point in pixels."""
        return self.goal[0] + 0.5, self.goal[1] + 0.5


def _lines(path: Path) -> list[str]:
    try:
        text = Path(path).read_text(encoding="ascii")
    except UnicodeDecodeError as err:
        raise MovingAIError(f"{path}: not an ASCII text file ({err.reason})") from None
    return text.replace("\r\n", "\n").split("\n")


def _header(path: Path, lines: list[str]) -> tuple[int, int]:
    """``(height, width)`` of the four header lines, each checked in order."""
    expected = ("type octile", "height N", "width N", "map")
    for i, want in enumerate(expected):
        got = lines[i] if i < len(lines) else None
        words = got.split() if got else []
        ok = words[:1] == [want.split()[0]] and len(words) == len(want.split())
        if ok and i == 0:
            ok = words[1] == "octile"
        elif ok and i in (1, 2):
            ok = words[1].isdigit() and int(words[1]) >= 1
        if not ok:
            what = "end of file" if got is None else repr(got)
            note = " (N a positive integer)" if "N" in want else ""
            raise MovingAIError(f"{path}, line {i + 1}: expected '{want}'{note}, got {what}")
    return int(lines[1].split()[1]), int(lines[2].split()[1])


def read_terrain(path: str | Path) -> np.ndarray:
    """The terrain characters of a ``.map`` file, ``(H, W)`` array of dtype ``<U1``,
    indexed ``[y, x]``. Raises :class:`MovingAIError` naming the line of any problem."""
    path = Path(path)
    lines = _lines(path)
    height, width = _header(path, lines)
    rows = lines[4:]
    while rows and rows[-1] == "":
        rows.pop()
    if len(rows) != height:
        where = (
            f"line {5 + height}: more rows follow"
            if len(rows) > height
            else (f"line {5 + len(rows)}: the file ends after {len(rows)} map rows")
        )
        raise MovingAIError(f"{path}, {where}, but 'height {height}'")
    allowed = PASSABLE | BLOCKED
    for y, row in enumerate(rows):
        if len(row) != width:
            raise MovingAIError(f"{path}, line {y + 5}: 'width {width}' but the row has "
                                f"{len(row)} characters")  # fmt: skip
        bad = set(row) - allowed
        if bad:
            x = min(row.index(c) for c in bad)
            raise MovingAIError(f"{path}, line {y + 5}: unknown terrain {row[x]!r} at x={x} "
                                f"(passable {''.join(sorted(PASSABLE))}, blocked "
                                f"{''.join(sorted(BLOCKED))})")  # fmt: skip
    return np.array([list(r) for r in rows], dtype="<U1").reshape(height, width)


def terrain_to_grid(terrain: np.ndarray) -> np.ndarray:
    """Occupancy ``(H, W)`` uint8 (:data:`~vnrrt.grid.OBSTACLE` where the terrain is not
    passable, :data:`~vnrrt.grid.FREE` where it is) of a terrain array ``(H, W)`` ``<U1``."""
    passable = np.isin(terrain, sorted(PASSABLE))
    return np.where(passable, FREE, OBSTACLE).astype(np.uint8)


def read_map(path: str | Path) -> np.ndarray:
    """A ``.map`` file as an occupancy grid ``(H, W)`` uint8, 0 free, 1 obstacle."""
    return terrain_to_grid(read_terrain(path))


def write_map(path: str | Path, grid: np.ndarray) -> None:
    """Write a ``.map`` file (atomically). ``grid``: an occupancy ``(H, W)`` (bool or integer,
    nonzero = obstacle, written ``@``; free written ``.``) or a terrain array of ``<U1``
    characters (written as given)."""
    from vnrrt.infra.io import write_text

    arr = np.asarray(grid)
    if arr.dtype.kind == "U":
        if arr.ndim != 2 or not set(np.unique(arr)) <= PASSABLE | BLOCKED:
            raise GridError("terrain must be a 2-D array of MovingAI terrain characters")
        terrain = arr
    else:
        terrain = np.where(as_occupancy(arr) != 0, "@", ".")
    h, w = terrain.shape
    rows = ["".join(r) for r in terrain]
    write_text(Path(path), "\n".join([f"type octile\nheight {h}\nwidth {w}\nmap", *rows]) + "\n")


def _scen_fields(path: Path, lineno: int, line: str) -> Scenario:
    words = line.split("\t") if "\t" in line else line.split()
    if len(words) != 9:
        raise MovingAIError(f"{path}, line {lineno}: expected 9 fields (bucket, map, width, "
                            f"height, start x, start y, goal x, goal y, optimal length), got "
                            f"{len(words)}")  # fmt: skip
    ints = []
    for name, word in zip(("bucket", "width", "height", "start x", "start y", "goal x",
                           "goal y"), words[:1] + words[2:8]):  # fmt: skip
        if not word.strip().isdigit():
            raise MovingAIError(f"{path}, line {lineno}: {name} must be a non-negative integer, "
                                f"got {word!r}")  # fmt: skip
        ints.append(int(word))
    try:
        optimal = float(words[8])
    except ValueError:
        optimal = math.nan
    if not (math.isfinite(optimal) and optimal >= 0):
        raise MovingAIError(f"{path}, line {lineno}: optimal length must be a finite number "
                            f">= 0, got {words[8]!r}")  # fmt: skip
    bucket, width, height, sx, sy, gx, gy = ints
    for name, (x, y) in (("start", (sx, sy)), ("goal", (gx, gy))):
        if not (x < width and y < height):
            raise MovingAIError(f"{path}, line {lineno}: {name} {(x, y)} is outside the "
                                f"{width}x{height} map the line declares")  # fmt: skip
    return Scenario(bucket, words[1], width, height, (sx, sy), (gx, gy), optimal, lineno)


def read_scen(path: str | Path) -> list[Scenario]:
    """The queries of a ``.scen`` file in file order (blank lines skipped). Raises
    :class:`MovingAIError` naming the line of any problem."""
    path = Path(path)
    lines = _lines(path)
    words = lines[0].split()
    if len(words) != 2 or words[0] != "version" or words[1] not in VERSIONS:
        raise MovingAIError(f"{path}, line 1: expected 'version 1' or 'version 1.0', got "
                            f"{lines[0]!r}")  # fmt: skip
    return [_scen_fields(path, i + 1, line) for i, line in enumerate(lines) if i and line.strip()]


def _length(value: float, length_format: str | None) -> str:
    return repr(float(value)) if length_format is None else format(value, length_format)


def write_scen(
    path: str | Path,
    scenarios: Iterable[Scenario],
    version: str = "1",
    length_format: str | None = "g",
) -> None:
    """Write a ``.scen`` file (atomically): ``version`` ``'1'`` tab-separated, ``'1.0'``
    space-separated as the older files are; lengths with ``format(length, length_format)``
    (``'g'``, 6 significant digits, as the ``version 1`` files; ``'.2f'`` as ``version 1.0``;
    None: the shortest text that reads back as the same float)."""
    from vnrrt.infra.io import write_text

    if version not in VERSIONS:
        raise ValueError(f"version must be one of {VERSIONS}, got {version!r}")
    sep = "\t" if version == "1" else " "
    rows = [sep.join(str(v) for v in (s.bucket, s.map_name, s.width, s.height, *s.start,
                                      *s.goal, _length(s.optimal, length_format)))
            for s in scenarios]  # fmt: skip
    write_text(Path(path), "\n".join([f"version {version}", *rows]) + "\n")


def check_scenarios(grid: np.ndarray, scenarios: Iterable[Scenario], source: str) -> None:
    """Refuse scenarios made for another map size than ``grid`` ``(H, W)``
    (:class:`MovingAIError` naming ``source`` and the line)."""
    h, w = grid.shape
    for s in scenarios:
        if (s.width, s.height) != (w, h):
            raise MovingAIError(f"{source}, line {s.line}: scenario for a {s.width}x{s.height} "
                                f"map, but the map is {w}x{h}")  # fmt: skip


def blocked_endpoint(grid: np.ndarray, scenario: Scenario) -> str | None:
    """Why ``scenario`` cannot be planned on ``grid`` ``(H, W)`` (an endpoint on an
    obstacle, e.g. in an older file made for another version of the map), or None."""
    for name, (x, y) in (("start", scenario.start), ("goal", scenario.goal)):
        if grid[y, x]:
            return f"line {scenario.line}: {name} {(x, y)} lies on an obstacle of the map"
    return None
