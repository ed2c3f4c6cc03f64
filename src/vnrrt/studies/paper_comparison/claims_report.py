"""The claims' second tables in ``paper_comparison.md``: each claim under the four readings
with its robustness, judged against the paper's data by the interval of the difference
(with the paper's pairing sensitivity), and per turning-point stratum with each map set's
instance mix. A renderer only: every number comes from the summary
(:func:`vnrrt.studies.paper_comparison.claims.claims`)."""

from __future__ import annotations

from vnrrt.studies.paper_comparison.readings import ITERATIONS, PRIMARY, READINGS


def _imp(r: dict) -> str:
    """A reading (ratio with CI) as an improvement in percent: ``+12.3% [+1.0%, +25.0%]``."""
    return f"{r['estimate'] - 1:+.1%} [{r['ci_low'] - 1:+.1%}, {r['ci_high'] - 1:+.1%}]"


def estimand_table(claims: dict) -> str:
    """One row per claim: the four readings (improvement [CI]: verdict), the verdict (the
    primary reading's) and whether the other readings keep its category."""
    names = list(READINGS)
    head = "| claim | " + " | ".join(f"{n} [CI]: verdict" for n in names)
    lines = [head + " | verdict | robustness |", "|" + " --- |" * (len(names) + 3)]
    for r in claims["rows"]:
        read = r.get("readings") or {}
        cells = [f"{_imp(read[n])}: {read[n]['verdict']}" if n in read else "no data"
                 for n in names]  # fmt: skip
        lines.append(f"| {r['text']} | " + " | ".join(cells) + f" | {r['verdict']} | "
                     f"{r.get('robustness', 'no data')} |")  # fmt: skip
    return "\n".join(lines)


def difference_table(claims: dict) -> str:
    """One row per claim: the paper's interval (unpaired), our ratio of means, the ratio
    ours / paper with its interval and the compatibility, then the paper's interval and the
    compatibility had its planners been paired at each correlation of ``claims["pairing"]``."""
    rhos = [str(r) for r in claims.get("pairing", [])]
    head = ("| claim | paper's interval (unpaired) | ours: ratio of means [CI] | ours / paper "
            "[CI] | the paper's data |")  # fmt: skip
    head += "".join(f" paired, correlation {r}: paper's interval; the paper's data |" for r in rhos)
    lines = [head, "|" + " --- |" * (5 + len(rhos))]
    for r in claims["rows"]:
        p = r["paper"]
        ours = (r.get("readings") or {}).get("time, ratio of means")
        cells = [f"[{p['low']:+.1%}, {p['high']:+.1%}]"]
        if ours is None:
            cells += ["no data", "—", "—"]
        else:
            d = ours["difference"]
            cells += [_imp(ours), f"{d['ratio']:.2f} [{d['low']:.2f}, {d['high']:.2f}]",
                      r["paper_data"]]  # fmt: skip
        for rho in rhos:
            q = r["pairing"][rho]
            cells.append(f"[{q['low']:+.1%}, {q['high']:+.1%}]; {q['paper_data'] or 'no data'}")
        lines.append(f"| {r['text']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def mix_table(strata: dict, names: list[str], columns: list[str], titles: dict) -> str:
    """Instances per stratum (rows) and map set (columns ``columns`` in ``strata``)."""
    cols = [c for c in columns if c in strata]
    lines = ["| stratum | " + " | ".join(titles.get(c, c) for c in cols) + " |",
             "|" + " --- |" * (len(cols) + 1)]  # fmt: skip
    for n in names:
        lines.append(f"| {n} | " + " | ".join(str(strata[c][n]) for c in cols) + " |")
    return "\n".join(lines)


def strata_table(claims: dict) -> str:
    """One row per claim: the pooled primary reading and the same per stratum (improvement
    [CI]: verdict, over n instances); iterations below each as a second reading."""
    names = claims["strata"]
    lines = ["| claim | pooled | " + " | ".join(names) + " |", "|" + " --- |" * (len(names) + 2)]
    for r in claims["rows"]:
        cells = [_cell(r)]
        for n in names:
            s = r["strata"][n]
            cells.append(_cell(s) + f" (n={s['instances']})" if s["instances"] else "no instances")
        lines.append(f"| {r['text']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _cell(r: dict) -> str:
    read = r.get("readings") or {}
    t, it = read.get(PRIMARY), read.get(ITERATIONS)
    if t is None:
        return "no data"
    return f"time {_imp(t)}: {t['verdict']}; iterations {_imp(it)}: {it['verdict']}"


def strata_section(summary: dict, columns: list[str], titles: dict) -> list[str]:
    """The per-stratum claims and the instance mix (empty without strata)."""
    claims = summary["claims"]
    if not claims.get("strata"):
        return []
    return [
        "### The claims per turning-point stratum",
        "",
        "Instances grouped by the turning points of their exact continuous optimum (its "
        "interior vertices; `stats.strata`): on a line-of-sight instance there is nothing "
        "between start and goal for a vertex network to predict, so a pooled figure depends "
        "on the mix. Each map set's mix (instances per stratum; a named map is one instance):",
        "",
        mix_table(summary["strata"], claims["strata"], columns, titles),
        "",
        "The paper's mix is unknown for its random maps (it gives neither the maps nor their "
        "paths), so its random-map figures cannot be re-weighted to ours.",
        "",
        strata_table(claims),
        "",
        "Each stratum at the claims' corrected level, with the verdict rules of the pooled "
        "table; a stratum's claims are secondary readings (no verdict counted).",
        "",
    ]
