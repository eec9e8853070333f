r"""Recurrence rates and recurrence quantification against radius (the paper's Fig. 7).

The paper's recurrence rate counts every pair (i, j), the main diagonal i = j included:
:math:`RR = 1/N + (1 - 1/N)\,RR_{\rm off}`, with :math:`RR_{\rm off}` the rate over pairs
i ≠ j. At ε = 10⁻³ the diagonal dominates (RR ≈ 1.15/N), so the paper's RR hardly
distinguishes the systems; every figure and table here shows the off-diagonal rate beside
it, at each threshold of the experiment, and DET (the share of off-diagonal recurrences on
diagonal lines of length ≥ 2) where the store has it.

Store rows (per eps ``e`` formatted ``f"{e:g}"``): ``rr@e``, ``rr_offdiag@e``, ``det@e``,
and with ``rr_sampling = "run+uniform"`` the same from uniform-time samples,
``uniform_rr@e``, ``uniform_rr_offdiag@e``, ``uniform_det@e``: the figures draw those
first (uniform samples do not cluster at collisions) and the run's own samples as the
control.
Old stores have only ``recurrence_rate`` at one ε; the off-diagonal rate is then derived
as :math:`(N\,RR - 1)/(N - 1)` with N = ``n_steps`` + 1 samples (the run's own samples),
and DET is missing.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from kicktimes.render.figures import plain_ticks, radius_axis, shared_legend
from kicktimes.render.pages import number_text
from kicktimes.report.context import Section
from kicktimes.report.effects import Effect, store_ratio
from kicktimes.report.store import REFERENCE, distinct, eps_values, kicked_systems, wide
from kicktimes.report.summary import diagnostic_summary, diagnostic_vs_radius

__all__ = ["recurrence_rows", "sampling_statement", "rr_figure", "family_figure", "sections",
           "effects", "shared_peaks"]

#: prefix of the rows computed from uniform-time samples (``rr_sampling = "run+uniform"``)
UNIFORM = "uniform_"

_QUANTITIES = {
    "rr": ("paper's RR (all pairs, diagonal included)", "RR (fraction of pairs)"),
    "rr_offdiag": ("off-diagonal RR (pairs i ≠ j)", "off-diagonal RR (fraction of pairs)"),
    "det": ("DET (determinism)", "DET (share of recurrences on lines)"),
}


def n_samples(exp):
    """Samples per run behind the stored RR: the initial point and one per step."""
    return exp.n_steps + 1


def recurrence_rows(results, exp):
    """Tidy rows ``rr@e``, ``rr_offdiag@e``, ``det@e`` for every ε of the experiment.

    Parameters
    ----------
    results : pandas.DataFrame
        The store's tidy results.
    exp : Experiment
        For ε and N.

    Returns
    -------
    rows : pandas.DataFrame
        Rows as in the store (``diagnostic`` = ``"rr@0.001"``...), taken from the store
        where present, else derived from ``recurrence_rate`` (old stores, first ε only);
        with them the uniform-time rows ``uniform_rr@e``, ``uniform_rr_offdiag@e``,
        ``uniform_det@e`` where the store has them.
    notes : list of str
        What was derived or is missing.
    """
    have = set(results["diagnostic"].unique())
    out, notes = [], []
    for k, e in enumerate(eps_values(exp)):
        tag = f"{e:g}"
        uniform = [f"{UNIFORM}{q}@{tag}" for q in _QUANTITIES]
        if any(u in have for u in uniform):
            out.append(results[results["diagnostic"].isin(uniform)])
        if f"rr@{tag}" in have:
            out.append(results[results["diagnostic"].isin([f"{q}@{tag}" for q in _QUANTITIES])])
            continue
        if k > 0 or "recurrence_rate" not in have:
            notes.append(f"ε = {tag}: no recurrence rows in the store.")
            continue
        rr = results[results["diagnostic"] == "recurrence_rate"]
        n = n_samples(exp)
        off = rr.assign(diagnostic=f"rr_offdiag@{tag}", value=(n * rr["value"] - 1) / (n - 1))
        out += [rr.assign(diagnostic=f"rr@{tag}"), off]
        notes.append(
            f"ε = {tag}: the store predates the off-diagonal and DET rows; the off-diagonal "
            f"rate is derived from the stored RR as (N·RR − 1)/(N − 1) with N = {n} samples, "
            "and DET is not available (rerun the sweep for it)."
        )
    rows = pd.concat(out, ignore_index=True) if out else results.iloc[:0]
    return rows, notes


def sampling_statement(exp):
    """Which samples the recurrence rate uses, in words."""
    rr_sampling = getattr(exp, "rr_sampling", "run")
    if rr_sampling == "uniform":
        return (
            f"The recurrence rates use samples at k·τ (τ = {exp.tau:g}) over each run's "
            "horizon, from a uniformly sampled re-run of the same trajectory with the same kicks."
        )
    uniform = (
        f" The rows uniform_* (rr_sampling = 'run+uniform') use samples at k·τ (τ = "
        f"{exp.tau:g}) over each run's horizon, from a uniformly sampled re-run of the same "
        "trajectory with the same kicks."
        if rr_sampling == "run+uniform" else ""
    )
    what = (
        "the paper's collision-truncated steps (a step ends early at every collision, so "
        "samples cluster at collisions and many off-diagonal recurrences at small ε are pairs "
        "of samples taken at boundary hits on the rim)"
        if exp.sampling == "paper"
        else f"uniform steps of τ = {exp.tau:g}"
    )
    return (
        f"The recurrence rates use the run's own {n_samples(exp)} samples (initial point and "
        f"{exp.n_steps} steps): {what}." + uniform
    )


#: the uniform-time DET panels split the systems in two (each beside the two-disk
#: reference): seven series with bars of ± std/10 on one axis overlap beyond reading at
#: ε = 10⁻³, where DET is about 0.005 with a spread as large
DET_GROUPS = (
    ("uniform kick angles", ("poisson", "actual", "uniform_kinetic")),
    ("scattering kick angles", ("poisson_scatter", "actual_scatter", "poisson_kinetic")),
)


def _det_groups(rows):
    """The systems of each uniform-time DET panel, :data:`DET_GROUPS` with the reference
    first, when both groups have a system in ``rows``; else one panel of every system
    (None)."""
    have = distinct(rows, "system")
    groups = [(words, (REFERENCE,) + tuple(s for s in members if s in have))
              for words, members in DET_GROUPS]
    listed = {s for _, members in DET_GROUPS for s in members}
    if REFERENCE not in have or any(len(g) < 2 for _, g in groups) or have - listed - {REFERENCE}:
        return [(None, None)]
    return groups


def _columns(rows, eps):
    """The panels' ``(prefix, quantity, (words, systems))`` triples, the uniform-time ones
    first: the uniform-time off-diagonal RR and DET (the panels that matter; DET in two
    panels of :data:`DET_GROUPS` where the store has both groups), then the run's own
    samples (the control): the paper's RR, off-diagonal RR and DET, every system."""
    have = distinct(rows, "diagnostic")
    out = []
    for prefix, quantities in ((UNIFORM, ("rr_offdiag", "det")), ("", tuple(_QUANTITIES))):
        for q in quantities:
            if not any(f"{prefix}{q}@{e:g}" in have for e in eps):
                continue
            groups = _det_groups(rows) if (prefix, q) == (UNIFORM, "det") else [(None, None)]
            out += [(prefix, q, group) for group in groups]
    return out


def _sampling_words(prefix):
    return "uniform-time samples" if prefix == UNIFORM else "run's own samples"


def _panel(ax, summary, name, title, ylabel, n, systems=None):
    """One quantity against radius: mean ± bars per system (no medians: with seven
    systems they would double the series), the axis from 0, and the number and radii of
    the means above the axis written in the title.

    Parameters
    ----------
    ax : matplotlib Axes
    summary : pandas.DataFrame
        :func:`~kicktimes.report.summary.diagnostic_summary` output.
    name : str
        The row name drawn, e.g. ``"uniform_rr_offdiag@0.001"``.
    title, ylabel : str
    n : int
        Samples per run (the 1/N guide of the paper's RR).
    systems : sequence of str, optional
        Only these systems (default: every system of ``summary``).

    Notes
    -----
    The y range from 0 covers every mean unless the largest is more than 2.5 times the
    top of :func:`~kicktimes.report.summary.diagnostic_vs_radius`'s robust range; then
    the means above are written at the top edge and counted, with radius and value, in
    the title.
    """
    q = name.split("@")[0].removeprefix(UNIFORM)
    part = summary[summary["diagnostic"] == name]
    if systems is not None:
        part = part[part["system"].isin(list(systems))]
    diagnostic_vs_radius(part, name, ax=ax, medians=False, title=title, ylabel=ylabel)
    plain_ticks(ax.yaxis)
    top = ax.get_ylim()[1]
    if q == "rr":
        # the paper's RR is mostly the diagonal 1/N, and the axis shows it
        top = max(top, 1.05 / n)
        ax.axhline(1.0 / n, color="grey", linestyle="--", linewidth=0.8)
        # just below the dashed line, whatever the axis' range
        ax.annotate(f"dashed: 1/N = {1.0 / n:.3g}, the main diagonal alone",
                    xy=(0.02, 1.0 / n), xycoords=("axes fraction", "data"), xytext=(0, -4),
                    textcoords="offset points", va="top", fontsize="x-small", color="grey")
    # every rate and DET from 0; from 0, a mean a little above the robust range is no
    # outlier: show every mean unless the largest is far (> 2.5x) above the range's top
    # (a long bar may still leave the axis)
    full = float(np.nanmax(part["mean"].to_numpy(float)))
    if np.isfinite(full) and full <= 2.5 * top:
        top = max(top, 1.08 * full)
        for note in [t for t in ax.texts if t.get_text().endswith(("↑", "↓"))]:
            note.remove()  # the clipping notes of diagnostic_vs_radius: nothing is clipped
    bottom = 0.0
    if q == "rr_offdiag":
        # a point that fills the table uniformly recurs at rate eps^2 / (1 - r)^2: the
        # guide every system's off-diagonal RR is read against; the axis is not from 0,
        # so that differences of a few per cent stay visible
        eps = float(name.split("@")[1])
        r = np.linspace(part["radius"].min(), part["radius"].max(), 50)
        guide = eps**2 / (1.0 - r) ** 2
        ax.plot(r, guide, color="0.3", linestyle=":", linewidth=1.2, zorder=1,
                label="ε²/(1 − r)²: uniform filling")
        low = float(np.nanmin(part["mean"].to_numpy(float)))
        bottom = 0.8 * min(low, guide.min()) if np.isfinite(low) else 0.0
    ax.set_ylim(bottom, top)
    above = part[part["mean"] > top]
    if len(above):
        above = above.sort_values(["radius", "mean"])
        where = "; ".join(f"r = {row.radius:g}: {row.mean:.3g}"
                          for row in above.head(4).itertuples())
        more = f"; {len(above) - 4} more" if len(above) > 4 else ""
        ax.set_title(f"{title}\n{len(above)} mean(s) above the axis ({where}{more})",
                     fontsize="small")


def shared_peaks(summary, name):
    """The interior radii where every system's mean of ``name`` is a strict local maximum
    (above both neighbouring radii): a tooth that all systems share.

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`~kicktimes.report.summary.diagnostic_summary` output.
    name : str
        The row name, e.g. ``"uniform_det@0.01"``.

    Returns
    -------
    list of float
        The radii, ascending (empty with fewer than three radii or two systems).

    Examples
    --------
    >>> import pandas as pd
    >>> s = pd.DataFrame({"diagnostic": "det@0.01", "radius": [1, 2, 3] * 2,
    ...                   "system": ["a"] * 3 + ["b"] * 3, "mean": [1, 3, 2, 2, 4, 1]})
    >>> shared_peaks(s, "det@0.01")
    [2.0]
    """
    part = summary[summary["diagnostic"] == name]
    means = part.pivot_table(index="radius", columns="system", values="mean", observed=True)
    means = means.sort_index().dropna(axis=1, how="all")
    if means.shape[0] < 3 or means.shape[1] < 2:
        return []
    v = means.to_numpy(float)
    peak = np.all((v[1:-1] > v[:-2]) & (v[1:-1] > v[2:]), axis=1)
    return [float(r) for r in means.index[1:-1][peak]]


def _peaks_note(rows, exp):
    """The caption's sentence on the uniform-time DET peaks that every system shares."""
    if not len(rows):
        return ""
    summary = diagnostic_summary(rows)
    found, control = [], []
    for e in eps_values(exp):
        name = f"{UNIFORM}det@{e:g}"
        if name in distinct(summary, "diagnostic"):
            peaks = shared_peaks(summary, name)
            if peaks:
                found.append(f"ε = {e:g}: r = " + ", ".join(f"{r:g}" for r in peaks))
        if f"det@{e:g}" in distinct(summary, "diagnostic"):
            own = shared_peaks(summary, f"det@{e:g}")
            control.append(f"ε = {e:g}: " + (", ".join(f"r = {r:g}" for r in own)
                                             if own else "none"))
    if not found:
        return ""
    own_words = (
        "The run's own samples, whose phase restarts at every collision, have shared "
        "local maxima at " + "; ".join(control) + ". " if control else "")
    return (
        " Every system's uniform-time DET has a local maximum (above both neighbouring "
        "radii; not necessarily its highest value) at the same radius (" + "; ".join(found)
        + "): a peak the two-disk billiard, which has no kicks, shares with every kicked "
        "one is a property of the radius or of the sampling, not of the kicks. "
        + own_words
        + "Checked outside this report on family B's two-disk billiard alone (issue 50; "
        "400 to 1000 ICs run to t = 4000, not recomputed here): its step in DET at ε = 0.01 "
        "from r = 0.016 to 0.018 is there with the sampling step τ = 0.3 and gone with "
        "τ = 0.27 or 0.33, so that one is, by inference, a resonance of the grid k·τ with "
        "the return times of the table's near-periodic orbits, which scale with 1 − r (a "
        "diagonal line needs two consecutive samples to return within ε); its peak at "
        "ε = 0.001 and r = 0.01 is there with τ = 0.27 as well, so that one is not the "
        "sampling grid, and its cause is not known; its peak at ε = 0.001 and r = 0.02 was "
        "within the noise of that check."
    )


def rr_figure(rows, exp, *, radii=None, title=None):
    """Small multiples: one row per ε; columns the uniform-time off-diagonal RR and DET
    (where the store has them; DET in two panels on one y range, the uniform-angle and
    the scattering kicks of :data:`DET_GROUPS`, each beside the two-disk billiard), then
    the run's own samples: paper's RR, off-diagonal RR, DET.

    Parameters
    ----------
    rows : pandas.DataFrame
        :func:`recurrence_rows` output.
    exp : Experiment
        For N (the 1/N guide of the main diagonal) and ε.
    radii : sequence of float, optional
        Only these radii (a zoom, as the paper's bottom panel).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Per panel the mean over ICs of each system with its two error bars (no medians:
        they are in the section's table), one series per system, at most three panels a
        row; the y axis starts at 0 (the off-diagonal RR: near its data, with the guide
        ε²/(1 − r)² of a point filling the table uniformly), and a mean above the axis
        is written at the top edge and counted, with its radius, in the panel's title.
        One legend below the panels.
    """
    if radii is not None:
        rows = rows[rows["radius"].isin(list(radii))]
    eps = [e for e in eps_values(exp)
           if any(f"{p}rr@{e:g}" in distinct(rows, "diagnostic") for p in ("", UNIFORM))
           or f"{UNIFORM}rr_offdiag@{e:g}" in distinct(rows, "diagnostic")]
    columns = _columns(rows, eps)
    # at most three panels a row (a row of six is an unreadable strip): each ε takes
    # `blocks` rows, the uniform-time panels first
    per_row = min(3, max(len(columns), 1))
    blocks = -(-max(len(columns), 1) // per_row)
    fig = Figure(figsize=(4.6 * per_row, 3.6 * blocks * max(len(eps), 1)),
                 layout="constrained")
    grid = np.atleast_2d(fig.subplots(blocks * max(len(eps), 1), per_row, squeeze=False))
    for extra in range(len(columns), blocks * per_row):
        for i in range(max(len(eps), 1)):
            grid[i * blocks + extra // per_row, extra % per_row].set_visible(False)
    axes = np.array([[grid[i * blocks + j // per_row, j % per_row]
                      for j in range(max(len(columns), 1))]
                     for i in range(max(len(eps), 1))])
    summary = diagnostic_summary(rows) if len(rows) else None
    n = n_samples(exp)
    for i, e in enumerate(eps):
        for j, (prefix, q, (words, systems)) in enumerate(columns):
            ax = axes[i, j]
            name = f"{prefix}{q}@{e:g}"
            if summary is None or name not in distinct(summary, "diagnostic"):
                ax.text(0.5, 0.5, "not in the store", transform=ax.transAxes, ha="center")
                radius_axis(ax)
                ax.set_ylabel(_QUANTITIES[q][1])
                continue
            role = "" if prefix == UNIFORM or not columns[0][0] else " (control)"
            group = f", {words}" if words else ""
            _panel(ax, summary, name,
                   f"{_QUANTITIES[q][0]}, ε = {e:g}\n{_sampling_words(prefix)}{role}{group}",
                   _QUANTITIES[q][1], n, systems=systems)
        # the split DET panels of one ε on one y range: they are read side by side
        split = [axes[i, j] for j, c in enumerate(columns) if c[2][0] is not None]
        if split:
            top = max(ax.get_ylim()[1] for ax in split)
            for ax in split:
                ax.set_ylim(0.0, top)
    for ax in axes.ravel():
        ax.title.set_fontsize("medium")
    shared_legend(fig, axes.ravel())
    if title:
        fig.suptitle(title)
    return fig


def _sticky_table(rows, sticky):
    """Mean, median and sticky-free mean per radius, system and quantity."""
    values = rows["value"].to_numpy()
    flag = None
    if sticky is not None:
        # each row's flag, looked up once (not once per group: ~700 groups at paper scale)
        flags = sticky.set_index(["radius", "ic"])["sticky"]
        where = pd.MultiIndex.from_frame(rows[["radius", "ic"]])
        flag = flags.reindex(where).fillna(False).astype(bool).to_numpy()
    out = []
    groups = rows.groupby(["radius", "system", "diagnostic"], observed=True).indices
    for (r, system, diagnostic), idx in sorted(groups.items(), key=lambda kv: kv[0]):
        # the group's values in row order as a Series: the same sums as before, bit for bit
        v = pd.Series(values[idx])
        entry = {
            "radius": r,
            "system": system,
            "quantity": diagnostic,
            "n": int(v.notna().sum()),
            "mean": v.mean(),
            "median": v.median(),
        }
        if flag is not None:
            f = flag[idx]
            entry["n_sticky"] = int(f.sum())
            entry["mean_without_sticky"] = v[~f].mean()
        out.append(entry)
    return pd.DataFrame(out)


def sections(ctx):
    """The recurrence section: RR beside the off-diagonal rate and DET at every ε."""
    exp = ctx.exp
    rows, notes = recurrence_rows(ctx.results, exp)
    ctx.found.recurrence_rows = rows
    if rows.empty:
        return []
    sec = Section("recurrence_rate", "Recurrence rate, off-diagonal rate and DET against radius")
    sec.figure(
        "fig06_recurrence_rate_vs_radius",
        rr_figure(rows, exp),
        "Per threshold ε (rows): "
        + ("the off-diagonal rate (pairs i ≠ j) and DET from uniform-time samples (the "
           "comparison that matters: they do not cluster at collisions), then, as the "
           "control, from the run's own samples: "
           if any(c[0] == UNIFORM for c in _columns(rows, eps_values(exp))) else "")
        + "the paper's recurrence rate (all pairs; dashed: 1/N, the main diagonal alone), "
        "the off-diagonal rate and DET, per system: mean over ICs (thick pale bars ± std/10 "
        "as in the paper, thin capped bars ± s.e.m.; medians in the table). Every axis "
        "starts at 0 but the off-diagonal RR's, which sits near its data with the dotted "
        "guide ε²/(1 − r)² of a point filling the table uniformly; a mean above the axis is "
        "written at the top edge and counted, with its radius, in the panel's title. "
        + sampling_statement(exp)
        + (" The uniform-time DET is drawn in two panels per ε on one y range, the "
           "uniform-angle and the scattering kicks, each beside the two-disk billiard: "
           "seven series on one axis hide each other."
           if any(c[2][0] for c in _columns(rows, eps_values(exp))) else "")
        + _peaks_note(rows, exp),
    )
    sec.text(sampling_statement(exp))
    for note in notes:
        sec.text(note)
    table = _sticky_table(rows, ctx.found.sticky)
    n = n_samples(exp)
    for e in eps_values(exp):
        rr = table[(table["quantity"] == f"rr@{e:g}") & (table["system"] == REFERENCE)]
        if rr.empty:
            continue
        share = 1.0 / (n * rr["mean"])
        sec.text(
            f"ε = {e:g}: the two-particle RR is {number_text(rr['mean'].min() * n)}/N to "
            f"{number_text(rr['mean'].max() * n)}/N over the radii, so the main diagonal is "
            f"{number_text(100 * share.min())}–{number_text(100 * share.max())} % of it; compare "
            "the systems on the off-diagonal rate and DET, not on the paper's RR."
        )
    sec.table(
        "recurrence_by_radius",
        table,
        "Recurrence quantities per radius and system (mean, median; sticky ICs flagged)",
    )
    return [sec]


def family_figure(stores):
    """Recurrence rates of every family (store), one row per store, at its first ε.

    Parameters
    ----------
    stores : sequence of Store
        The families' stores (each with ``experiment`` and ``results``).

    Returns
    -------
    (matplotlib.figure.Figure, str) or None
        The figure and its caption, None when no store has recurrence rows. Row k is
        store k; its columns: the off-diagonal RR from uniform-time samples (where any
        store has them; "not in the store" where this one has not), then from the run's
        own samples the off-diagonal RR and the paper's RR (diagonal included, dashed
        1/N). Every axis starts at 0 but the off-diagonal RR's (near its data, with the
        guide ε²/(1 − r)²); the rows of a column share one y range.
    """
    found = []
    for store in stores:
        exp = store.experiment
        rows, _ = recurrence_rows(store.results, exp)
        e = eps_values(exp)[0]
        names = [f"{p}{q}@{e:g}" for p, q in ((UNIFORM, "rr_offdiag"), ("", "rr_offdiag"),
                                              ("", "rr"))]
        rows = rows[rows["diagnostic"].isin(names)]
        if not rows.empty:
            found.append((exp, e, rows))
    if not found:
        return None
    uniform = any(f"{UNIFORM}rr_offdiag@{e:g}" in distinct(rows, "diagnostic")
                  for _, e, rows in found)
    columns = ([(UNIFORM, "rr_offdiag")] if uniform else []) + [("", "rr_offdiag"), ("", "rr")]
    fig = Figure(figsize=(4.6 * len(columns), 3.9 * len(found)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(found), len(columns), squeeze=False))
    for i, (exp, e, rows) in enumerate(found):
        summary = diagnostic_summary(rows)
        for j, (prefix, q) in enumerate(columns):
            ax = axes[i, j]
            name = f"{prefix}{q}@{e:g}"
            title = f"{exp.name}: {_QUANTITIES[q][0]}, ε = {e:g}\n{_sampling_words(prefix)}"
            if name not in distinct(summary, "diagnostic"):
                ax.text(0.5, 0.5, "not in the store", transform=ax.transAxes, ha="center")
                radius_axis(ax)
                ax.set_ylabel(_QUANTITIES[q][1])
                ax.set_title(title)
                continue
            _panel(ax, summary, name, title, _QUANTITIES[q][1], n_samples(exp))
    # one y range per column over the families, so that the rows compare at a glance
    for j in range(len(columns)):
        drawn = [ax for ax in axes[:, j] if ax.has_data()]
        if len(drawn) > 1:
            low = min(ax.get_ylim()[0] for ax in drawn)
            high = max(ax.get_ylim()[1] for ax in drawn)
            for ax in drawn:
                ax.set_ylim(low, high)
    for ax in axes.ravel():
        ax.title.set_fontsize("small")
    fig.suptitle("Recurrence rates of every family (one row per family) against radius",
                 fontsize="medium")
    shared_legend(fig, axes.ravel())
    names = ", ".join(exp.name for exp, _, _ in found)
    return fig, (
        f"Recurrence rates of every family ({names}; one row each) at its first ε, mean over "
        "ICs per system (thick pale bars ± std/10, thin capped bars ± s.e.m.): "
        + ("left, the off-diagonal rate from uniform-time samples where the store has them; "
           "then " if uniform else "")
        + "the off-diagonal rate and the paper's RR (diagonal included, dashed: 1/N) from "
        "the run's own samples, the paper's layout. Every axis starts at 0 but the "
        "off-diagonal RR's (near its data, dotted: ε²/(1 − r)² of a point filling the table "
        "uniformly); means above the axis are counted in the panel titles. "
        + " ".join(f"{exp.name}: {sampling_statement(exp)}" for exp, _, _ in found)
    )


def effects(ctx):
    """Off-diagonal RR and DET of each kicked system over the two-particle values, on the
    findings tables' primary samples (uniform-time where the store has them)."""
    rows = ctx.found.recurrence_rows
    if rows is None:
        rows, _ = recurrence_rows(ctx.results, ctx.exp)
    out = []
    have = set(distinct(rows, "diagnostic"))
    for e in eps_values(ctx.exp):
        for q, question in (("rr_offdiag", "Off-diagonal RR"), ("det", "DET")):
            # the primary setting of the findings tables (controls.py): uniform-time
            # samples where the store has them, else the paper's samples
            name = f"{q}@{e:g}"
            samples = "the paper's samples"
            if UNIFORM + name in have:
                name, samples = UNIFORM + name, "uniform-time samples"
            if name not in have:
                continue
            values = wide(rows, name)
            for system in kicked_systems(rows):
                if system not in values.columns or REFERENCE not in values.columns:
                    continue
                per_r, tot = store_ratio(ctx, values[system], values[REFERENCE])
                med = values.groupby(level="radius", observed=True).median()
                out.append(
                    Effect.of_ratio(
                        f"{question} (ε = {e:g})",
                        system,
                        f"ratio of means on {samples} (kicked / two-particle, averaged "
                        "over radii)",
                        tot,
                        tolerance=ctx.tolerance,
                        detail=(
                            f"per-radius ratio {number_text(per_r['ratio'].min())} to "
                            f"{number_text(per_r['ratio'].max())}; ratio of per-radius medians "
                            f"{number_text((med[system] / med[REFERENCE]).min())} to "
                            f"{number_text((med[system] / med[REFERENCE]).max())}"
                        ),
                    )
                )
    return out
