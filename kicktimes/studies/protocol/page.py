"""``paper.md``: the paper's claims by its own protocol, and the choice that decides each."""

from __future__ import annotations

import datetime as _dt
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.ticker import MultipleLocator  # noqa: E402

from kicktimes import __version__  # noqa: E402
from kicktimes.fileio import atomic_write  # noqa: E402
from kicktimes.render.pages import markdown_table, write_results_page  # noqa: E402
from kicktimes.render.provenance import Source  # noqa: E402
from kicktimes.stats import format_interval, paired_ratio  # noqa: E402
from kicktimes.studies.protocol.claims import SMALL_RADIUS, SWITCHES, claims_table  # noqa: E402
from kicktimes.studies.protocol.compute import D0, EPS, panels  # noqa: E402
from kicktimes.studies.protocol.tables import (  # noqa: E402
    N_BOOT,
    PAPER_READING,
    Ratios,
    convergence_table,
    per_radius_table,
    r1_table,
    ratio_table,
    rr_table,
    shapley_table,
)

__all__ = ["FIGURE", "SOURCES", "build_page", "fig6_figure"]

FIGURE = "paper_fig06_ftle_both_readings.png"
#: the closing table of ``paper.md``: its five CSVs (the same at every scale and with or
#: without the paper study's findings), the columns the page quotes and their functions
SOURCES = (
    Source("paper_claims.csv", "claim, figure, paper_says, estimate, interval, verdict, "
           "other_estimate, other_interval, other_verdict, decided_by", claims_table),
    Source("paper_findings.csv", "control, estimate, ci_low, ci_high, verdict, robust, "
           "depends_on", ratio_table),
    Source("paper_findings.csv", "diagnostic, estimate, ci_low, ci_high, verdict", r1_table),
    Source("paper_findings.csv", "diagonal_share, lowest_radius_ratio, highest_radius_ratio",
           rr_table),
    Source("paper_by_radius.csv", "mean, sd, n, paper_bar", per_radius_table),
    Source("paper_by_radius.csv", "ratio, ratio_ci_low, ratio_ci_high", paired_ratio),
    Source("paper_shapley.csv", "choice, share, ci_low, ci_high, fraction_of_change, verdict, "
           "distance_from, distance_to", shapley_table),
    Source("paper_convergence.csv", "horizon, estimate, ci_low, ci_high, two_particle_mean",
           convergence_table),
)
_SYSTEMS = (("two_particle", "Two Particle", "k", "o"), ("poisson", "Poisson", "C0", "s"),
            ("actual", "Actual", "C3", "^"))
SWITCHES_NAMES = [name for name, _ in SWITCHES]
_COLUMNS = (("literal", "eq. (4) as printed (twin never renormalised)"),
            ("renormalised", "Benettin (twin renormalised every step)"))


def fig6_figure(by_radius: pd.DataFrame, panel_list):
    """The paper's Fig. 6, both panels (rows), each reading of eq. (4) (columns): mean FTLE
    over ICs against the radius, with the paper's error bars (±SD/10) and, shaded, the
    95 % normal interval of the mean.

    The Benettin column's y axis starts at 0. The eq.-(4)-as-printed column is zoomed on
    its data (bars and bands included): there the systems differ by about 1.5 % of a value
    near 37 (top) or 25 (bottom), which an axis from 0 flattens into one line; each zoomed
    axis says so in its corner, with the value it starts at.
    """
    fig, axes = plt.subplots(len(panel_list), 2, figsize=(10, 7.5), layout="constrained",
                             squeeze=False)
    for i, p in enumerate(panel_list):
        for j, (estimator, title) in enumerate(_COLUMNS):
            ax = axes[i, j]
            low, high = [], []
            for system, label, color, marker in _SYSTEMS:
                sel = by_radius[(by_radius["panel"] == p.name)
                                & (by_radius["system"] == system)
                                & (by_radius["estimator"] == estimator)
                                & (by_radius["measure"] == "paper")
                                & (by_radius["twin_kicks"] == "shared")
                                & (by_radius["kick_angle"] == "uniform")]
                half = 1.96 * sel["sd"] / sel["n"] ** 0.5
                reach = pd.concat([half, sel["paper_bar"]], axis=1).max(axis=1)
                low += list(sel["mean"] - reach)
                high += list(sel["mean"] + reach)
                ax.fill_between(sel["radius"], sel["mean"] - half, sel["mean"] + half,
                                color=color, alpha=0.2, lw=0)
                ax.errorbar(sel["radius"], sel["mean"], yerr=sel["paper_bar"], color=color,
                            marker=marker, ms=4, capsize=2, lw=1, label=label)
            ax.set_title(f"{p.figure} ({p.n_ics} ICs, n = {p.n_steps}, τ = {p.tau:g})\n{title}",
                         fontsize=9)
            ax.set_xlabel("disk radius r")
            ax.set_ylabel("λ_max(n)  [1 / time]" if estimator == "renormalised"
                          else "eq. (4) value  [1 / time]")
            if estimator == "renormalised":
                # from 0, as a reader sets it beside the paper's: equal gaps look equal
                ax.set_ylim(0.0, 1.15 * ax.get_ylim()[1])
            elif np.isfinite(low).any():
                # from 0 the systems' 1.5 % difference vanishes: zoom, and say so on the axes
                lo, hi = np.nanmin(low), np.nanmax(high)
                pad = 0.15 * (hi - lo)
                ax.set_ylim(lo - pad, hi + 3 * pad)  # room above for the legend
                ax.text(0.02, 0.03, f"zoomed: y axis starts at {lo - pad:.3g}, not 0",
                        transform=ax.transAxes, fontsize=8, ha="left", va="bottom",
                        bbox={"boxstyle": "round", "fc": "lightyellow", "ec": "0.6"})
            ax.xaxis.set_major_locator(MultipleLocator(0.005))
            ax.grid(alpha=0.3)
            if i == 0:
                ax.legend(fontsize=8, loc="upper right" if j == 0 else "upper left",
                          title="bars ±SD/10 (paper); band 95 % CI", title_fontsize=7)
    return fig


def _cell(row, prefix=""):
    return format_interval(row[f"{prefix}estimate"], row[f"{prefix}ci_low"],
                           row[f"{prefix}ci_high"])


def _span(frame, column="estimate"):
    values = frame if isinstance(frame, pd.Series) else frame[column]
    lo, hi = values.min(), values.max()
    return f"{lo:.3g}" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}–{hi:.3g}"


def _verdicts(frame, column="verdict"):
    return " / ".join(dict.fromkeys(frame[column]))


def _reproduces(frame, want="within 10 %") -> str:
    """"reproduces" when every row's verdict is ``want``, "undecided" when every one is
    inconclusive, "does not reproduce" when none is ``want`` or inconclusive, else
    "partly" (per-radius counts: their most frequent verdict)."""
    verdicts = [str(v).split(" at ")[0] for v in frame["verdict"]]
    if all(v == want for v in verdicts):
        return "reproduces"
    if all(v == "inconclusive" for v in verdicts):
        return "undecided"
    if not any(v in (want, "inconclusive") for v in verdicts):
        return "does not reproduce"
    return "partly"


def _first_screen(claims: pd.DataFrame, conv: pd.DataFrame, rr_tab: pd.DataFrame,
                  by_radius: pd.DataFrame) -> list[str]:
    """One line per claim: whether it reproduces by the paper's protocol, the numbers, and
    what decides it."""
    def rows(prefix):
        return claims[claims["claim"].str.startswith(prefix)]

    ftle, rr, balloon = rows("FTLE"), rows("RR, small"), rows("RR, larger")
    acf, closer, angles, counts = (rows("ACF"), rows("Poisson vs"), rows("N(0, 1)"),
                                   rows("Counts"))
    times = rows("Poisson collision")
    lit_end = conv[(conv["estimator"] == "literal") & (conv["horizon"] == conv["horizon"].max())]
    decisive = [name for name in SWITCHES_NAMES
                if all(name in d.split("; ") for d in ftle["decided_by"])]
    estimator = SWITCHES_NAMES[0] in decisive
    decided = ("Decided by the estimator" if estimator else
               f"Decided by {' and '.join(decisive)}" if decisive else
               "No single switch changes every panel's verdict")
    mechanism = ("the twins saturate and eq. (4) measures log(d_sat/d0)/τ "
                 "(two-disk {} at 8T)").format(_span(lit_end, "two_particle_mean"))
    r1 = by_radius[by_radius["diagnostic"] == "r1"]
    diagonal = rr_tab["diagonal_share"].dropna()
    out = [
        f"- **FTLE, Fig. 6** {_reproduces(ftle)}: eq. (4) as printed gives kicked/two-disk "
        f"{_span(ftle)} ({_verdicts(ftle)}); renormalised (Benettin) "
        f"{_span(ftle, 'other_estimate')} ({_verdicts(ftle, 'other_verdict')}). {decided}"
        f"{': ' + mechanism if estimator else ''}.",

        f"- **ACF, Fig. 8** {_reproduces(acf)}: R₁ ratio {_span(acf)} ({_verdicts(acf)}), "
        f"but R₁ is {_span(r1, 'mean')} everywhere; 1 − R₁ "
        f"{_span(acf, 'other_estimate')} ({_verdicts(acf, 'other_verdict')}).",
        f"- **Poisson vs actual** {_reproduces(closer, 'Poisson closer')}: "
        f"{_verdicts(closer)} (|log R| differs by {_span(-closer['estimate'])}; "
        f"renormalised, {_span(-closer['other_estimate'])}).",
        f"- **N(0, 1) angles** {_reproduces(angles)}: {_verdicts(angles)} (eq. (4)).",
    ]
    if not rr.empty and not balloon.empty:
        bulge = "a balloon" if (balloon["verdict"] == "lower").any() else "no balloon"
        out.insert(1, (
            f"- **RR, Fig. 7** {_reproduces(rr)} at small radii: with the diagonal (as "
            f"printed) {_span(rr)} ({_verdicts(rr)}; {bulge} at larger radii), but the "
            f"diagonal is {_span(100 * diagonal)} % of the two-disk RR; off it, "
            f"{_span(rr, 'other_estimate')} ({_verdicts(rr, 'other_verdict')})."))
    if counts.empty:
        return [*out, "- **Figs. 4–5**: not stated; they need the paper study's findings "
                "tables (`--findings`)."]
    return [*out, f"- **Figs. 4–5** {_reproduces(times, 'nominal')} / "
                  f"{_reproduces(counts)}: {_span(100 * times['estimate'])} % of runs reject "
                  f"Poisson times ({_verdicts(times)}); counts/kinetic theory {_span(counts)} "
                  f"({_verdicts(counts)})."]


def build_page(rows: pd.DataFrame, results_dir: str | os.PathLike, findings_dir: str |
               os.PathLike | None, *, command: str, scale: str = "paper", store: str = "",
               dpi: int = 110, panel_list=None) -> Path:
    """Write ``paper.md``, its CSVs and its figure into ``results_dir`` from the study's
    ``rows`` and the paper study's findings in ``findings_dir`` (or ``None``); the page
    closes with the table of `SOURCES`. The panels are those of ``scale``, or
    ``panel_list`` (two `Panel`). Returns the page."""
    out = Path(results_dir)
    out.mkdir(parents=True, exist_ok=True)
    panel_list = panels(scale) if panel_list is None else tuple(panel_list)
    ratios = Ratios(rows)
    ratio_tab = ratio_table(ratios, panel_list)
    r1_tab = r1_table(rows, panel_list)
    by_radius = per_radius_table(rows, ratios, panel_list)
    shapley = shapley_table(ratios, panel_list)
    conv = convergence_table(rows, panel_list)
    rr_tab = rr_table(rows, panel_list, SMALL_RADIUS)
    claims = claims_table(ratios, ratio_tab, r1_tab, rr_tab, findings_dir, panel_list)
    findings = pd.concat([ratio_tab, r1_tab, rr_tab], ignore_index=True)
    tables = {"paper_findings.csv": findings, "paper_by_radius.csv": by_radius,
              "paper_shapley.csv": shapley, "paper_convergence.csv": conv,
              "paper_claims.csv": claims}
    for name, frame in tables.items():
        atomic_write(out / name, lambda tmp, frame=frame: frame.to_csv(tmp, index=False))
    fig = fig6_figure(by_radius, panel_list)
    atomic_write(out / FIGURE, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))
    plt.close(fig)

    now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    n_rows = len(rows)
    also = " and the paper study's `family_*_findings.csv`" if findings_dir is not None else ""
    overshoot = ratio_tab[ratio_tab["control"] == "renormalised/paper/independent/uniform"]
    shared = ratio_tab[ratio_tab["control"] == "renormalised/paper/shared/uniform"]
    main_table = pd.DataFrame({
        "Claim": [f"{r.claim} ({r.family[-1].upper()})" for r in claims.itertuples()],
        "Fig.": claims["figure"],
        "Paper says": claims["paper_says"],
        "By its protocol": claims["interval"],
        "Verdict": claims["verdict"],
        "Other reading": [f"{r.other_interval} {r.other_verdict}" for r in claims.itertuples()],
        "Decided by": [r.decided_by or "no switch" for r in claims.itertuples()],
    })
    shares = pd.DataFrame({
        "Panel": shapley["family"], "System": shapley["system"],
        "Choice": [f"{c}: {a} → {b}" for c, a, b in
                   zip(shapley["choice"], shapley["from"], shapley["to"], strict=True)],
        "Share of Δ|log R|": [format_interval(r.share, r.ci_low, r.ci_high, edges=(0.0,))
                              for r in shapley.itertuples()],
        "Fraction": [f"{x:.0%}" for x in shapley["fraction_of_change"]],
        "Verdict": shapley["verdict"].map({"above": "away from 1", "below": "towards 1",
                                           "inconclusive": "inside noise"}),
    })
    conv_tab = conv.pivot_table(index=["family", "estimator", "system"], columns="horizon",
                                values="estimate", observed=True)
    conv_ci = conv.set_index(["family", "estimator", "system", "horizon"])
    conv_rows = []
    for (family, estimator, system), _ in conv_tab.iterrows():
        cells = {f"{h}T": _cell(conv_ci.loc[(family, estimator, system, h)])
                 for h in conv_tab.columns}
        conv_rows.append({"Panel": family, "Estimator": estimator, "System": system, **cells})
    conv_md = pd.DataFrame(conv_rows)
    p0 = panel_list[0]
    lines = [
        "# Ranković & Porter's claims by their own protocol (generated)", "",
        f"Generated {now} by kicktimes {__version__} (`{command}`) from {n_rows} rows"
        f"{' of ' + store if store else ''}{also}, by the paper's eq. (4).", "",
        *_first_screen(claims, conv, rr_tab, by_radius), "",
        *markdown_table(main_table), "",
        f"Verdicts: the 95 % CI of a ratio (bootstrap clustered on ICs, {N_BOOT} resamples) "
        "inside [0.9, 1.1] is *within 10 %*, an equivalence test; entirely above or below "
        "is *higher* / *lower*; otherwise *inconclusive* (`kicktimes.stats.ratio_verdict`). "
        "*Robust* means every reading of the protocol gives the same verdict. The paper's "
        "protocol (Sec. III C): eq. (4), λ_max(n) = 1/(τn) Σₖ log(‖δd(kτ)‖/‖δd(0)‖) with "
        f"‖δd(0)‖ = 1/{1 / D0:.0f}, x and y perturbed and measured separately on the "
        "positions, the larger exponent kept, n collision-truncated steps of τ, read "
        f"as printed ({'/'.join(PAPER_READING)}: estimator, measure, twin kicks, kick "
        "angle); the other reading renormalises the twins. *Decided by*: the single "
        "switches away from the paper's protocol that change the verdict. The ACF rows "
        "compare the mean R₁ the paper plots, and kicktimes' 1 − R₁; the RR rows the paper's "
        f"RR (all pairs, the main diagonal included) at ε = {EPS:g} on its steps, and the "
        f"RR off the diagonal, at r ≤ {SMALL_RADIUS:g} (the paper's small radii are not "
        "given) and above (where the paper sees a balloon, a ratio < 1); one control each. "
        "*Poisson vs actual*: d = |ln R_poisson| − |ln R_actual|, the difference of the "
        "two log-distances from 1, and the 10 % band on exp(d) (for two ratios on the same "
        "side of 1 it is the ratio of the two kicked values: equally close when the Poisson- "
        "and actual-kicked values agree within 10 %; a CI of d that excludes 0 inside the "
        "band is a real but smaller difference). The count rows come from the paper "
        "study's findings, under its controls.", "",
        "## Fig. 6, both readings", "",
        f"![Fig. 6 reproduced]({FIGURE})", "",
        "Left: eq. (4) as printed; right: Benettin's algorithm. Rows: the paper's two "
        f"panels ({p0.n_ics} ICs, n = {p0.n_steps}, τ = {p0.tau:g}; "
        f"{panel_list[1].n_ics} ICs, n = {panel_list[1].n_steps}, τ = {panel_list[1].tau:g}). "
        "Bars: ±SD/10, the paper's; bands: 95 % CI of the mean. The paper's bars are what "
        "its figure could resolve; the per-radius means, SDs and ratios are in "
        "[paper_by_radius.csv](paper_by_radius.csv).", "",
        "## Which choice decides the ratio", "",
        "Shapley shares of the change in the ratio's distance from 1, |log R|, from "
        "kicktimes' reading (renormalised, x/y measure, shared kicks: distance "
        f"{_span(shapley, 'distance_from')}) to the reading with all three switched "
        f"(literal, norm, independent: {_span(shapley, 'distance_to')}); a negative share "
        "brings R towards 1. 95 % CIs from the same IC resamples "
        "([paper_shapley.csv](paper_shapley.csv)); a share whose CI contains 0 is inside "
        "its noise and is not read. The twin-kick share is not agreement: under Benettin, "
        "twins with their own kicks overshoot, "
        f"{_span(overshoot)} ({_verdicts(overshoot)}), where twins sharing them give "
        f"{_span(shared)} ({_verdicts(shared)}).", "",
        *markdown_table(shares), "",
        "## Convergence: the same ratios at T, 2T, 4T, 8T", "",
        f"Radii {', '.join(f'{r:g}' for r in p0.convergence_radii)} (panel A) and "
        f"{', '.join(f'{r:g}' for r in panel_list[1].convergence_radii)} (panel B), the "
        f"first {p0.convergence_ics} ICs ([paper_convergence.csv](paper_convergence.csv)).",
        "",
        *markdown_table(conv_md), "",
        "All readings of every claim: [paper_findings.csv](paper_findings.csv), "
        "[paper_claims.csv](paper_claims.csv).", "",
    ]
    return write_results_page(out / "paper.md", lines, SOURCES)
