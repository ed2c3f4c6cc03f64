"""The claims in ``paper_comparison.md``: the claims table with our verdicts and the note on
how they were tested, what the masked claims test, and the second tables: each claim under
the four readings with its robustness, judged against the paper's data by the interval of
the difference (with the paper's pairing sensitivity), and per turning-point stratum with
each map set's instance mix. A renderer only: every number comes from the summary
(:func:`vnrrt.studies.paper_comparison.claims.claims`)."""

from __future__ import annotations

from vnrrt.names import level_name, percent
from vnrrt.studies.paper_comparison.claims import CONTRADICTS, improvement, verdict_text
from vnrrt.studies.paper_comparison.disclosure import mask_section
from vnrrt.studies.paper_comparison.headline import VERDICT_GROUPS
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


def claims_table(claims: dict) -> str:
    """The paper's quoted claims: the paper's value and its interval from its own data, ours
    read on time (the verdict), on time with the network's inference, and on iterations, the
    compatibility with the paper's data and whether a masked claim tests its mask."""
    head = (
        "| claim | paper | paper's interval (its data) | ours: time, gm ratio of medians "
        "[CI] | ours: ratio of means [CI] | ours: planning + inference [CI] | ours: iterations "
        "[CI] | verdict | the paper's data | tests the mask? |"
    )
    lines = [head, "|" + " --- |" * 10]
    for r in claims["rows"]:
        p = r["paper"]
        paper_iv = f"[{p['low']:+.1%}, {p['high']:+.1%}]" + ("" if p["significant"] else " (n.s.)")
        t, it, total = r["time_to_stop"], r["iterations"], r.get("time_total")
        if t is None:
            cells = ["no data"] * 4 + ["no data", "—"]
        else:
            cells = [improvement(t), improvement(t, "rom_ci_low", "rom_ci_high", "ratio_of_means"),
                     improvement(total) if total else "—", improvement(it), verdict_text(r),
                     r["paper_data"]]  # fmt: skip
        tm = r["testability"]
        cells.append(
            "yes" if tm["testable"] else f"no: not testable with this network ({tm['why']})"
        )
        lines.append(
            f"| {r['text']} | {r['quoted']:+.2%} | {paper_iv} | " + " | ".join(cells) + " |"
        )
    return "\n".join(lines)


def masked_claims_section(summary: dict) -> list[str]:
    """What each masked claim tests: where the heatmap samplers put their mass after the
    mask, and the rule that marks a claim untestable."""
    table = mask_section(summary)
    if not table:
        return []
    rule = summary["claims"]["testability_rule"]
    return [
        "### What the masked claims test",
        "",
        "Where each heatmap sampler's weights lie (after M-VNRRT*'s mask), averaged over the "
        "random instances, to within "
        f"{percent(summary['eps'])} of A*, and how often the sampler falls back to uniform "
        "sampling (nothing above tau). The M-VNRRT* variants apply the mask to the "
        "max-normalised heatmap (as for the oracles) or leave out the start/goal disks; the "
        "masked NRRT* control is M-VNRRT*'s sampler on the path network's heatmap, so the "
        "mask's effect is separated from the target's.",
        "",
        *table,
        "",
        f"A masked claim is 'not testable with this network' when {rule}.",
        "",
    ]


def multiple_note(claims: dict) -> str:
    """How the claims were tested: the corrected level, the resamples and their tail count,
    and which claims are significant in the paper's own data."""
    rows = [r for r in claims["rows"] if r["time_to_stop"]]
    testable = [r for r in rows if r["testability"]["testable"]]
    contra = sum(r["paper_data"] == CONTRADICTS for r in testable)
    slow = sum(r["quoted"] < 0 for r in claims["rows"])
    sig = [r["text"] for r in claims["rows"] if r["paper"]["significant"]]
    return (
        f"{len(claims['rows'])} quoted claims ({len(claims['rows']) - slow} improvements, "
        f"{slow} slow-downs), {claims['claims']} with data here. One verdict per claim, on "
        "time (its metric); iterations and planning + inference are second readings. Every "
        f"interval of this table is at {claims['corrected_level']:.3%} (Bonferroni over the "
        f"{claims['claims']} claims: family-wise {level_name(claims['level'])}), ours from "
        f"{claims['bootstrap']:,} bootstrap resamples ({claims['tail_draws']:.0f} in each tail). "
        "The paper's interval comes from its own means, standard deviations and trial counts "
        "(the delta method on the log of a ratio of independent means: it assumes its planners "
        "unpaired, as its tables report them; its sensitivity to pairing is below); '(n.s.)' "
        "marks a claim whose interval contains zero, not significant in the paper's own data. "
        "Our ratio of means (the paper's estimand) is 'compatible with the paper's data' when "
        "the interval of the difference between ours and the paper's contains no difference, "
        "and 'contradicts' it when it does not. "
        f"Significant in the paper's own data: {len(sig)} of {len(claims['rows'])}"
        + (f" ({'; '.join(sig)})." if sig else ".")
        + f" Verdicts of the {len(testable)} testable claims: "
        f"{_counts([r['verdict'] for r in testable])}; {len(rows) - len(testable)} untestable "
        f"(no verdict counted); {contra} testable claims contradict the paper's data."
    )


def _counts(verdicts: list[str]) -> str:
    groups = {g: sum(v.startswith(g) for v in verdicts) for g in VERDICT_GROUPS}
    return ", ".join(f"{n} {g}" for g, n in groups.items())
