"""The configuration key: the planner, mask threshold, heatmap source and sampling mode that a
row of a trial table belongs to, as one typed value with one way to write it
(:attr:`ConfigKey.text`) and one way to read it (:meth:`ConfigKey.parse`). Trials, tables,
statistics, reports, figures and MLflow runs all go through it.

Text form (the ``key`` column of the trial tables)::

    planner[@tau][{mask variant}][~mix][[source]][+free][+informed]

* ``rrt_star``, ``vnrrt_star``, ``m_vnrrt_star@0.5``: a configuration of the protocol; a
  learned planner samples the source the configuration assigns it (``eval.sources``), which
  the text leaves out;
* ``vnrrt_star[oracle_vertex]``, ``nrrt_star[oracle_path@q0.1]``: the source is named (an
  oracle, :mod:`vnrrt.evaluation.sources`, or another network);
* ``m_vnrrt_star@0.5{max}``, ``{noends}``: M-VNRRT*'s mask applied another way
  (:data:`MASK_VARIANTS`: tau on the max-normalised heatmap; start/goal disks left out);
* ``vnrrt_star~0.25[oracle_vertex@s4]``: the heatmap drawn with probability 0.25 instead of
  ``planner.mix`` (the oracle families);
* ``+free``: samples drawn from free cells only (the other obstacle rule than the
  configuration's default; :func:`vnrrt.evaluation.sources.allowed_cells`);
* ``+informed``: the same configuration with informed sampling (Gammell et al. 2014).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from vnrrt.config import ConfigError
from vnrrt.names import PLANNER_NAMES, PLANNERS

INFORMED = "+informed"  # text suffix of a configuration with informed sampling
FREE = "+free"  # text suffix of a configuration sampling free cells only
MASK_VARIANTS = {  # M-VNRRT*'s mask, other than on the raw probabilities (the paper's reading)
    "max": "max-normalised",  # tau applied to heatmap / max(heatmap), as for the oracles
    "noends": "without start/goal",  # the start and goal disks zeroed before the mask
}
SHORT = {"rrt_star": "rrt", "nrrt_star": "nrrt", "vnrrt_star": "vnrrt", "m_vnrrt_star": "m"}


@dataclass(frozen=True)
class ConfigKey:
    """One evaluated configuration.

    ``tau`` is M-VNRRT*'s mask threshold (only M-VNRRT* has one); ``source`` the heatmap a
    learned planner samples (a network name or an oracle source; None for RRT*, or for a
    protocol configuration not yet resolved against ``eval.sources``); ``named_source``
    whether the text names the source (else it is the protocol's).
    """

    planner: str
    tau: float | None = None
    source: str | None = None
    informed: bool = False
    named_source: bool = False
    mask: str = ""  # a key of MASK_VARIANTS ("": the raw probabilities, the paper's)
    mix: float | None = None  # the probability of a heatmap draw (None: planner.mix)
    free: bool = False  # samples from free cells only (the obstacle rule, flipped)

    def __post_init__(self) -> None:
        if self.planner not in PLANNERS:
            raise ConfigError(f"unknown planner {self.planner!r}; known: {PLANNERS}")
        if self.planner == "rrt_star" and self.source is not None:
            raise ConfigError("rrt_star samples uniformly: it takes no heatmap source")
        if (self.planner == "m_vnrrt_star") != (self.tau is not None):
            raise ConfigError(f"{self.planner}: M-VNRRT* and only M-VNRRT* takes tau")
        if self.tau is not None and not math.isfinite(self.tau):
            raise ConfigError(f"{self.planner}: tau must be finite, got {self.tau!r}")
        if self.named_source and self.source is None:
            raise ConfigError(f"{self.planner}: a named source needs a source")
        if self.mix is not None and (self.planner == "rrt_star" or not 0 <= self.mix <= 1):
            raise ConfigError(
                f"{self.planner}: a heatmap planner's mix in [0, 1], got {self.mix!r}"
            )
        if self.mask and (self.mask not in MASK_VARIANTS or self.tau is None):
            raise ConfigError(
                f"mask variant {self.mask!r}: M-VNRRT* only, one of {list(MASK_VARIANTS)}"
            )

    @property
    def text(self) -> str:
        """The key's one written form (module doc)."""
        out = self.planner if self.tau is None else f"{self.planner}@{self.tau:g}"
        out += f"{{{self.mask}}}" if self.mask else ""
        out += "" if self.mix is None else f"~{self.mix:g}"
        if self.named_source:
            out += f"[{self.source}]"
        return out + (FREE if self.free else "") + (INFORMED if self.informed else "")

    def __str__(self) -> str:
        return self.text

    @classmethod
    def parse(cls, text: str, sources: Mapping[str, str] | None = None) -> ConfigKey:
        """The key ``text`` writes; a learned planner without a named source samples its
        source in ``sources`` (``eval.sources``; left unresolved when None).
        :class:`ConfigError` naming ``text`` if it is not a key."""
        body = text.removesuffix(INFORMED)
        informed = body != text
        body, free = body.removesuffix(FREE), body.endswith(FREE)
        base, bracket, rest = body.partition("[")
        if bracket and (not rest.endswith("]") or len(rest) < 2 or "[" in rest):
            raise ConfigError(f"bad configuration {text!r}: expected planner[@tau][[source]]")
        base, tilde, mix = base.partition("~")
        base, brace, mask = base.partition("{")
        if brace and not mask.endswith("}"):
            raise ConfigError(f"bad configuration {text!r}: expected planner@tau{{variant}}")
        planner, at, tau = base.partition("@")
        try:
            value = float(tau) if at else None
            mix_value = float(mix) if tilde else None
        except ValueError:
            raise ConfigError(f"bad configuration {text!r}: not a number") from None
        named = rest[:-1] if bracket else None
        source = named if named else (sources or {}).get(planner)
        if planner == "rrt_star" and not named:
            source = None
        try:
            fields = (planner, value, source, informed, bool(named), mask[:-1], mix_value, free)
            return cls(*fields)
        except ConfigError as err:
            raise ConfigError(f"bad configuration {text!r}: {err}") from None

    def with_source(self, source: str) -> ConfigKey:
        """This configuration sampling ``source`` instead (named in the text)."""
        return dataclasses.replace(self, source=source, named_source=True)

    def with_mask(self, mask: str) -> ConfigKey:
        """This M-VNRRT* configuration with mask variant ``mask`` (:data:`MASK_VARIANTS`)."""
        return dataclasses.replace(self, mask=mask)

    def with_mix(self, mix: float | None) -> ConfigKey:
        """This configuration drawing its heatmap with probability ``mix``."""
        return dataclasses.replace(self, mix=mix)

    def with_free(self, free: bool = True) -> ConfigKey:
        """This configuration sampling free cells only (or not)."""
        return dataclasses.replace(self, free=free)

    def with_informed(self, informed: bool = True) -> ConfigKey:
        """This configuration with (or without) informed sampling."""
        return dataclasses.replace(self, informed=informed)

    @property
    def label(self) -> str:
        """The display name: ``M-VNRRT* τ=0.5``, ``VNRRT* [oracle_vertex]``,
        ``Informed RRT*``, ``informed NRRT*``."""
        name = PLANNER_NAMES[self.planner] + ("" if self.tau is None else f" τ={self.tau:g}")
        name += f" ({MASK_VARIANTS[self.mask]})" if self.mask else ""
        name += "" if self.mix is None else f" mix {self.mix:g}"
        name += f" [{self.source}]" if self.named_source else ""
        name += " (free cells)" if self.free else ""
        if not self.informed:
            return name
        return "Informed RRT*" if name == "RRT*" else f"informed {name}"

    @property
    def short(self) -> str:
        """A short name for metric keys (MLflow's characters only): ``rrt``, ``m0.5``,
        ``m0.5_max``, ``m0.5_nrrtnet``, ``nrrt_informed``."""
        out = SHORT[self.planner] + ("" if self.tau is None else f"{self.tau:g}")
        out += f"_{self.mask}" if self.mask else ""
        out += "" if self.mix is None else f"_mix{self.mix:g}"
        out += f"_{self.source}" if self.named_source else ""
        out += "_free" if self.free else ""
        return out + ("_informed" if self.informed else "")

    def rank(self) -> tuple:
        """Sort order: not informed first, then the paper's planner order, tau, source."""
        return (
            self.informed,
            PLANNERS.index(self.planner),
            -1.0 if self.tau is None else self.tau,
            self.source if self.named_source else "",
            self.mask,
            -1.0 if self.mix is None else self.mix,
            self.free,
        )


def label(text: str) -> str:
    """The display name of a key's text (:attr:`ConfigKey.label`)."""
    return ConfigKey.parse(text).label


def sort_texts(texts: Iterable[str]) -> list[str]:
    """Key texts in the paper's order (:meth:`ConfigKey.rank`)."""
    return sorted(texts, key=lambda t: ConfigKey.parse(t).rank())


def is_informed(text: str) -> bool:
    """Whether a key's text names an informed configuration."""
    return ConfigKey.parse(text).informed
