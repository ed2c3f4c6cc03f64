"""The ``bench_maps`` settings (``conf/bench_maps/default.yaml``) and where the maps' files
are: what stage ``validate`` checks before any work (no planner or search code here)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from vnrrt.config import check, conf_defaults
from vnrrt.maps.movingai import MovingAIError

REPORT = "benchmark_maps"  # the one name of stage bench_maps@<name> (bench_maps.report)
IDEAS = ("path", "vertex")  # the oracle families whose envelope this study can plan


@dataclass
@conf_defaults("bench_maps")
class BenchMapsConfig:
    """The ``bench_maps`` section (``conf/bench_maps/default.yaml``): ``maps`` (map name ->
    its buckets), ``per_bucket`` queries per bucket, ``trials`` per query and configuration,
    the oracle ``ideas`` whose envelopes run, and ``report`` (``[benchmark_maps]`` where
    ``maps`` is set, ``[]`` where it is not: DVC makes no stage of a foreach over ``[]``)."""

    maps: dict[str, list[int]]
    per_bucket: int
    trials: int
    ideas: list[str]
    report: list[str]

    def validate(self) -> None:
        for name, buckets in self.maps.items():
            ok = bool(buckets) and all(isinstance(b, int) and b >= 0 for b in buckets)
            check(
                ok and len(set(buckets)) == len(buckets),
                f"bench_maps.maps.{name}",
                buckets,
                "distinct bucket numbers >= 0, at least one",
            )
        check(self.per_bucket >= 1, "bench_maps.per_bucket", self.per_bucket, "must be >= 1")
        check(
            self.trials >= 2,
            "bench_maps.trials",
            self.trials,
            "must be >= 2 (paired trials within a query)",
        )
        ok = len(set(self.ideas)) == len(self.ideas) and set(self.ideas) <= set(IDEAS)
        check(ok, "bench_maps.ideas", self.ideas, f"distinct families of {list(IDEAS)}")
        want = [REPORT] if self.maps else []
        check(
            self.report == want,
            "bench_maps.report",
            self.report,
            f"must be {want} where bench_maps.maps is {dict(self.maps)}",
        )


def map_files(folder: str | Path, name: str) -> tuple[Path, Path]:
    """``(<folder>/<name>.map, <folder>/<name>.map.scen)``; :class:`MovingAIError` naming the
    one that is missing."""
    files = (Path(folder) / f"{name}.map", Path(folder) / f"{name}.map.scen")
    for f in files:
        if not f.is_file():
            raise MovingAIError(f"{f}: no such file (map {name!r} of bench_maps.maps)")
    return files
