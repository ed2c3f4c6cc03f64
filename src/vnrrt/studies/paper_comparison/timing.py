"""The report's timing-noise section: RRT* read against itself (:mod:`vnrrt.evaluation.noise`)
and, in an ablation, each claim's time reading against the user's default run, with the
changes that lie within the noise flagged."""

from __future__ import annotations

from vnrrt.names import level_name, map_set_title, stop_title


def _x(v: float) -> str:
    return f"{v:.3f}x"


def noise_table(noise: dict, eps: float) -> list[str]:
    """One row per (stop rule, map set) timed twice: RRT* against itself with its interval,
    the noise band, the trials."""
    lines = ["| stop rule | map set | RRT* against itself [CI] | noise band | trials |",
             "| --- | --- | --- | --- | --- |"]  # fmt: skip
    for stop, per_set in noise.items():
        for map_set, r in per_set.items():
            lines.append(
                f"| {stop_title(stop, eps)} | {map_set_title(map_set)} | {_x(r['speedup'])} "
                f"[{_x(r['ci_low'])}, {_x(r['ci_high'])}] | {_x(r['band_low'])} to "
                f"{_x(r['band_high'])} | {r['trials']} |"
            )
    return lines


def _flag(c: dict) -> str:
    moved = c["verdict_now"] != c["verdict_before"]
    if c["within_noise"] is None:
        return "no band (not measured here)"
    if c["within_noise"]:
        return "**verdict moved within timing noise**" if moved else "yes"
    return "no: beyond the noise"


def changes_table(changes: list[dict]) -> list[str]:
    """Each claim's time speed-up in the default run and in this one, the change, the
    verdicts and the flag."""
    lines = ["| claim | default run | this run | change | verdict: default, this run | "
             "within timing noise? | iterations |", "|" + " --- |" * 7]  # fmt: skip
    for c in changes:
        same = "identical: re-timing only" if c["iterations_same"] else "changed"
        lines.append(
            f"| {c['text']} | {_x(c['before'])} | {_x(c['now'])} | {c['ratio'] - 1:+.1%} | "
            f"{c['verdict_before']}; {c['verdict_now']} | {_flag(c)} | {same} |"
        )
    return lines


def timing_section(summary: dict, changes: list[dict] | None, overrides: str) -> list[str]:
    """The section (``[]`` where the run did not time RRT* twice); ``changes``:
    :func:`vnrrt.evaluation.noise.changes` against the default run (None: this run is the
    default, or there is none), ``overrides``: what this run changed."""
    noise = summary.get("timing_noise")
    if not noise:
        return []
    level = summary["claims"]["corrected_level"]
    out = [
        "## The machine's timing noise",
        "",
        "The protocol's RRT* ran twice (`eval.timing_noise`): the same seeds, so the same "
        "iterations and costs, the second runs spread over the stage. Read against itself as "
        f"a claim is read (paired, clustered; intervals at {level:.3%}), it differs from 1 "
        "only by the machine's timing noise. The band is that interval made symmetric: a "
        "time speed-up on these instances moves that much when nothing but the timing changes.",
        "",
        *noise_table(noise, summary["eps"]),
        "",
        "A claim whose time and iteration verdicts differ says so in the claims table ('on "
        "iterations: ...'): the iteration reading does not depend on the machine.",
        "",
    ]
    if changes:
        out += [
            f"### Against your default run ({overrides})",
            "",
            "Each claim's time speed-up beside the one of this scale's default run on this "
            "machine (kept by `make repro` / `dvc repro` at `paths.baseline`). A change "
            "inside the claim's noise band is flagged: it can come from re-timing alone "
            f"({level_name(summary['level'])} family-wise).",
            "",
            *changes_table(changes),
            "",
        ]
    return out
