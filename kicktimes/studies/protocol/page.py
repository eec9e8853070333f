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
from kicktimes.studies.protocol.claims import SMALL_RADIUS, claims_table  # noqa: E402
from kicktimes.studies.protocol.compute import D0, EPS, panels  # noqa: E402
from kicktimes.studies.protocol.tables import (  # noqa: E402
    N_BOOT,
    PAPER_READING,
    Ratios,
    convergence_table,
    count_line_table,
    fig4_table,
    per_radius_table,
    r1_table,
    ratio_table,
    rr_table,
    shapley_table,
)
from kicktimes.studies.protocol.verdicts import (  # noqa: E402
    CLOSER_MARGIN,
    CLOSER_RULE,
    REPRODUCES_RULE,
    reproduces,
)

__all__ = ["FIGURE", "SOURCES", "build_page", "fig6_figure"]

FIGURE = "paper_fig06_ftle_both_readings.png"
#: the closing table of ``paper.md``: its five CSVs (the same at every scale and with or
#: without the paper study's findings), the columns the page quotes and their functions
SOURCES = (
    Source("paper_claims.csv", "claim, figure, paper_says, estimate, interval, verdict, "
           "other_estimate, other_interval, other_verdict, decided_by", claims_table),
    Source("paper_claims.csv", "reproduces", reproduces),
    Source("paper_lines.csv", "diagnostic, radius, estimate, ci_low, ci_high, verdict, r2",
           fig4_table),
    Source("paper_lines.csv", "estimate, ci_low, ci_high, verdict, slope, intercept",
           count_line_table),
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
#: the columns of paper_lines.csv (Figs. 4 and 5: `fig4_table`, `count_line_table`)
LINE_COLUMNS = ["family", "figure", "diagnostic", "question", "radius", "estimate", "ci_low",
                "ci_high", "verdict", "r2", "r2_ci_low", "r2_ci_high", "slope", "intercept",
                "n_radii", "n_ics"]
_COLUMNS = (("literal", "eq. (4) as printed (twin never renormalised)"),
            ("renormalised", "Benettin (twin renormalised every step)"))


def fig6_figure(by_radius: pd.DataFrame, panel_list):
    """The paper's Fig. 6, both panels (rows), each reading of eq. (4) (columns): mean FTLE
    over ICs against the radius, with the paper's error bars (±SD/10) and, shaded, the
    95 % normal interval of the mean.

    The Benettin column's y axis starts at 0 and is shared by both rows. The eq.-(4)-as-
    printed column is zoomed on its data (bars and bands included): there the systems
    differ by about 1.5 % of a value near 37 (top) or 25 (bottom), which an axis from 0
    flattens into one line; every zoomed axis spans the same height (the largest any
    panel needs), so equal gaps are equal differences in both rows, and says so in its
    corner, with the value it starts at.
    """
    fig, axes = plt.subplots(len(panel_list), 2, figsize=(10, 7.5), layout="constrained",
                             squeeze=False)
    zoom, top = {}, 0.0
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
                         fontsize=10)
            ax.set_xlabel("disk radius r")
            ax.set_ylabel("λ_max(n)  [1 / time]" if estimator == "renormalised"
                          else "eq. (4) as printed  [1 / time]\n"
                          "(≈ log(d_sat / d₀) / τ: saturation)")
            if estimator == "renormalised":
                top = max(top, np.nanmax(high) if np.isfinite(high).any() else 0.0)
            elif np.isfinite(low).any():
                zoom[i] = (np.nanmin(low), np.nanmax(high))
            ax.xaxis.set_major_locator(MultipleLocator(0.005))
            ax.grid(alpha=0.3)
            if i == 0:
                ax.legend(fontsize=8, loc="upper right" if j == 0 else "upper left",
                          title="bars ±SD/10 (paper); band 95 % CI", title_fontsize=7)
    # from 0, as a reader sets it beside the paper's: equal gaps look equal; one x range
    radii = [r for p in panel_list for r in p.radii]
    pad = 0.04 * (max(radii) - min(radii)) or 0.001
    for i in range(len(panel_list)):
        axes[i, 1].set_ylim(0.0, 1.2 * top if top > 0 else 1.0)
        for ax in axes[i]:
            ax.set_xlim(min(radii) - pad, max(radii) + pad)
    # zoomed, the same height in every row; room above for the legend
    span = max((hi - lo for lo, hi in zoom.values()), default=0.0) * 1.6
    for i, (lo, hi) in zoom.items():
        start = 0.5 * (lo + hi) - 0.4 * span
        axes[i, 0].set_ylim(start, start + span)
        axes[i, 0].text(0.02, 0.03, f"zoomed: y axis starts at {start:.3g}, not 0; "
                        f"height {span:.2g} in every row", transform=axes[i, 0].transAxes,
                        fontsize=8, ha="left", va="bottom",
                        bbox={"boxstyle": "round", "fc": "lightyellow", "ec": "0.6"})
    return fig


def _cell(row, prefix=""):
    return format_interval(row[f"{prefix}estimate"], row[f"{prefix}ci_low"],
                           row[f"{prefix}ci_high"])


def _g(x, digits=3) -> str:
    return f"{x:#.{digits}g}".rstrip(".")


def _span(frame, column="estimate"):
    values = frame if isinstance(frame, pd.Series) else frame[column]
    lo, hi = _g(values.min()), _g(values.max())
    return lo if lo == hi else f"{lo}–{hi}"


def _envelope(frame, prefix="", scale=1.0):
    """"[lowest CI end, highest CI end]" of the rows' 95 % CIs, with the digits that keep
    the two ends apart."""
    lo = scale * frame[f"{prefix}ci_low"]
    hi = scale * frame[f"{prefix}ci_high"]
    lo, hi = (hi.min(), lo.max()) if scale < 0 else (lo.min(), hi.max())
    digits = next((d for d in range(3, 7) if _g(lo, d) != _g(hi, d)), 7)
    return f"[{_g(lo, digits)}, {_g(hi, digits)}]"


def _verdicts(frame, column="verdict"):
    return " / ".join(dict.fromkeys(str(v) for v in frame[column]))


def _short(frame, column="verdict"):
    """The rows' verdicts, each once, without their parenthesised detail."""
    return " / ".join(dict.fromkeys(str(v).split(" (")[0] for v in frame[column]))


def _answer(frame) -> str:
    """The rows' "reproduces?" answers, each once (`verdicts.reproduces`)."""
    return _verdicts(frame, "reproduces")


def _readme_numbers(findings_dir, panel_list) -> dict:
    """The README's own numbers for the quantities this page also measures, by name (each
    line quotes them beside its own): ``{"ftle": ..., "rr_offdiag@0.001": ...}`` (the RR at
    this page's ε, `EPS`), the paper study's primary Poisson and actual rows; empty without
    ``findings_dir``."""
    out = {}
    for diagnostic in ("ftle", f"rr_offdiag@{EPS:g}"):
        rows = _paper_study(findings_dir, panel_list, diagnostic)
        if len(rows):
            out[diagnostic] = rows
    return out


def _first_screen(claims: pd.DataFrame, rr_tab: pd.DataFrame,
                  by_radius: pd.DataFrame, readme=None) -> list[str]:
    """At most five one-line answers: whether each claim reproduces by the paper's
    protocol, its numbers with their 95 % CIs, and the caveat; where the README measures
    the same quantity on the paper study's runs (``readme``, `_readme_numbers`), its
    number is quoted beside this page's by name."""
    readme = readme or {}
    def rows(prefix):
        return claims[claims["claim"].str.startswith(prefix)]

    ftle, acf, closer = rows("FTLE"), rows("ACF"), rows("Poisson vs")
    fig4, fig5 = rows("Poisson kick times"), rows("Counts vs radius")
    in_paper = claims["kind"] != "not_in_paper"
    rr = claims[claims["claim"].str.startswith("RR, small") & in_paper]
    balloon = claims[claims["claim"].str.startswith("RR, larger") & in_paper]
    r1 = by_radius[by_radius["diagnostic"] == "r1"]
    only = ((ftle["reproduces"] == "yes").all()
            and (ftle["other_verdict"] != ftle["verdict"]).all())
    lead = ("reproduces only by eq. (4) as printed, which never renormalises its twins" if only
            else f"by eq. (4) as printed (twins never renormalised): {_answer(ftle)}")
    out = [
        f"- **FTLE (Fig. 6)** {lead}: kicked/two-disk {_span(ftle)}, CIs in {_envelope(ftle)}; "
        f"renormalised {_span(ftle, 'other_estimate')} ({_verdicts(ftle, 'other_verdict')})"
        + (f", the README's tangent FTLE on the paper study's runs {_span(readme['ftle'])}"
           if "ftle" in readme else "") + ".",
        f"- **ACF (Fig. 8)** {_answer(acf)}: R₁ ratio {_span(acf)}, CIs in {_envelope(acf)}, "
        f"but R₁ is {_span(r1, 'mean')} everywhere, so the ratio leaves the band only if the "
        "kicked R₁ falls below 0.9 of the two-disk's; 1 − R₁ over t ≤ nτ "
        f"{_span(acf, 'other_estimate')} ({_verdicts(acf, 'other_verdict')}).",
        f"- **Poisson vs actual (Sec. IV)** {_answer(closer)}: {_short(closer)} (m = "
        f"{CLOSER_MARGIN:g}), |d| = {_span(closer['estimate'].abs())}, CIs in "
        f"{_envelope(closer, scale=-1)}; renormalised {_span(closer['other_estimate'].abs())} "
        f"({_short(closer, 'other_verdict')}).",
    ]
    if not rr.empty and not balloon.empty:
        diagonal = rr_tab.loc[rr_tab["figure"].str.startswith("Fig. 7"), "diagonal_share"]
        only = (rr["reproduces"] == "yes").all() and (rr["other_verdict"] != rr["verdict"]).all()
        small = (f"small radii reproduce only with the diagonal ({_span(100 * diagonal.dropna())} "
                 "% of the RR)" if only else f"small radii {_answer(rr)}")
        rr_offdiag = readme.get(f"rr_offdiag@{EPS:g}")
        out.insert(1, (
            f"- **RR (Fig. 7, panel A, ε = {EPS:g}, the paper's steps)**: {small}, {_span(rr)}; "
            f"off it {_span(rr, 'other_estimate')} ({_verdicts(rr, 'other_verdict')}"
            + (f"; the README's at the same ε on uniform-time samples, {_span(rr_offdiag)}"
               if rr_offdiag is not None else "")
            + f"); balloon {_answer(balloon)}: {_span(balloon)}, {_verdicts(balloon)}."))
    tested4 = fig4[fig4["kind"] != "not_tested"]
    tested5 = fig5[fig5["kind"] != "not_tested"]
    parts = []
    if not tested4.empty:
        parts.append(f"Fig. 4's slope {_span(tested4)}, CIs in {_envelope(tested4)}")
    if not tested5.empty:
        parts.append(f"Fig. 5's RMS residual {_span(tested5)}, CIs in {_envelope(tested5)}")
    other = fig4.dropna(subset=["other_estimate"])
    caveat = (f"; yet {_span(100 * other['other_estimate'])} % of runs reject uniform "
              f"times ({_verdicts(other, 'other_verdict')})") if not other.empty else ""
    out.append(f"- **Figs. 4–5 (lines)** {_answer(fig4)} / {_answer(fig5)}: "
               f"{'; '.join(parts) or 'not run'}{caveat}.")
    return out


def _paper_study(findings_dir, panel_list, diagnostic):
    """The paper study's primary Poisson and actual rows of ``diagnostic`` (the README's
    numbers), or an empty frame without ``findings_dir``."""
    if findings_dir is None:
        return pd.DataFrame(columns=["estimate"])
    frames = [pd.read_csv(Path(findings_dir) / f"{p.name}_findings.csv") for p in panel_list]
    table = pd.concat(frames, ignore_index=True)
    return table[(table["diagnostic"] == diagnostic) & (table["control"] == "primary")
                 & table["system"].isin(["poisson", "actual"])]


def _notes(claims, conv, shapley_src, findings_dir, panel_list) -> list[str]:
    """The rules and caveats under the claims table, generated from the tables."""
    lit_end = conv[(conv["estimator"] == "literal") & (conv["horizon"] == conv["horizon"].max())]
    ftle = claims[claims["claim"].str.startswith("FTLE")]
    acf = claims[claims["claim"].str.startswith("ACF")]
    readme_acf = _paper_study(findings_dir, panel_list, "one_minus_r1")
    readme_ftle = _paper_study(findings_dir, panel_list, "ftle")
    out = [
        f"*Verdicts* (95 % CIs, bootstrap clustered on ICs, {N_BOOT} resamples shared by "
        "every reading): a ratio inside [0.9, 1.1] is *within 10 %* (equivalence, margin "
        "`kicktimes.stats.MARGIN`), beyond it *higher* / *lower*, else *inconclusive*. "
        "*Poisson vs actual*: " + CLOSER_RULE + ". *The balloon* (Fig. 7 top: the two-disk "
        "RR above the kicked ones at larger radii) is a sign: a ratio's CI below 1 is "
        "*balloon*, above 1 *no balloon* (`verdicts.balloon_verdict`). " + REPRODUCES_RULE
        + ".",
        "",
        "*The paper's protocol* (Sec. III C): eq. (4), λ_max(n) = 1/(τn) Σₖ "
        f"log(‖δd(kτ)‖/‖δd(0)‖), ‖δd(0)‖ = 1/{1 / D0:.0f}, x and y measured separately, the "
        "larger kept, n collision-truncated steps of τ, read as printed "
        f"({'/'.join(PAPER_READING)}: estimator, measure, twin kicks, kick angle); *Other "
        "reading* renormalises the twins; *Decided by*: the single switches that change the "
        "verdict. Never renormalised, the twins saturate and eq. (4) measures "
        f"log(d_sat/d0)/τ (two-disk {_span(lit_end, 'two_particle_mean')} at 8T): the FTLE "
        f"reproduces by that reading only ({_span(ftle)}); renormalised it is "
        f"{_span(ftle, 'other_estimate')}"
        + (f", the paper study's tangent-space ratio (the README's) {_span(readme_ftle)}"
           if not readme_ftle.empty else "") + ".",
        "",
        f"*RR*: the paper's RR (all pairs, the diagonal included) at ε = {EPS:g} on its "
        f"steps, and off the diagonal; small radii r ≤ {SMALL_RADIUS:g} (not given by the "
        "paper). Fig. 7 shows panel A only, so panel B's RR rows are *not in the paper*. "
        "*ACF*: the mean R₁ the paper plots, and 1 − R₁, both over t ≤ nτ for every "
        "system"
        + (f" ({_span(acf, 'other_estimate')}); the paper study's 1 − R₁ ratios (the "
           f"README's, {_span(readme_acf)}) end each run after its n collision-truncated "
           "steps instead, a window that depends on the system (both disks' boundary "
           "collisions truncate the two-disk steps)" if not readme_acf.empty else "") + ". "
        "*Figs. 4–5*: the paper's least-squares lines (Fig. 4: each IC's Poisson kick "
        "times on its collision times at the smallest radius, slope averaged over ICs; "
        "Fig. 5: the mean counts against r, their RMS relative residual against 10 %) in "
        "[paper_lines.csv](paper_lines.csv); the other "
        "readings are the paper study's uniformity test and Γ(r)T, under its controls.",
    ]
    return out


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
    line_tab, fig4_tab = count_line_table(rows, panel_list), fig4_table(rows, panel_list)
    claims = claims_table(ratios, ratio_tab, r1_tab, rr_tab, findings_dir, panel_list,
                          line_tab=line_tab, fig4_tab=fig4_tab)
    findings = pd.concat([ratio_tab, r1_tab, rr_tab], ignore_index=True)
    lines_csv = pd.concat([fig4_tab, line_tab], ignore_index=True).reindex(
        columns=LINE_COLUMNS)
    tables = {"paper_findings.csv": findings, "paper_by_radius.csv": by_radius,
              "paper_shapley.csv": shapley, "paper_convergence.csv": conv,
              "paper_claims.csv": claims, "paper_lines.csv": lines_csv}
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
        "By its protocol": [i if k != "not_tested" else "not run" for i, k in
                            zip(claims["interval"], claims["kind"], strict=True)],
        "Verdict": claims["verdict"],
        "reproduces?": claims["reproduces"],
        "Other reading": [f"{r.other_interval} {r.other_verdict}"
                          if np.isfinite(r.other_estimate) else "not read"
                          for r in claims.itertuples()],
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
        *_first_screen(claims, rr_tab, by_radius,
                       readme=_readme_numbers(findings_dir, panel_list)), "",
        *markdown_table(main_table), "",
        *_notes(claims, conv, shapley, findings_dir, panel_list), "",
        "## Fig. 6, both readings", "",
        f"![Fig. 6 reproduced]({FIGURE})", "",
        "Left: eq. (4) as printed, zoomed to one height per row; right: Benettin's "
        "algorithm, one y axis from 0 for both rows. Rows: the paper's two panels "
        f"({p0.n_ics} ICs, n = {p0.n_steps}, τ = {p0.tau:g}; "
        f"{panel_list[1].n_ics} ICs, n = {panel_list[1].n_steps}, τ = {panel_list[1].tau:g}). "
        "Bars: ±SD/10, the paper's; bands: 95 % CI of the mean. Means, SDs and ratios per "
        "radius: [paper_by_radius.csv](paper_by_radius.csv).", "",
        "## Which choice decides the ratio", "",
        "Shapley shares of the change in |log R|, from kicktimes' reading (renormalised, "
        f"x/y measure, shared kicks: {_span(shapley, 'distance_from')}) to all three "
        f"switched (literal, norm, independent: {_span(shapley, 'distance_to')}); negative "
        "brings R towards 1; CIs from the same IC resamples "
        "([paper_shapley.csv](paper_shapley.csv)); a share whose CI contains 0 is not read. "
        "The twin-kick share is not agreement: under Benettin, twins with their own kicks "
        f"give {_span(overshoot)} ({_verdicts(overshoot)}), sharing them "
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
