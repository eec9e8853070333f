r"""How much of the kicked-versus-two-disk gap each ingredient of the kicks closes.

Two ingredients of a real disk-disk collision, each switched on or off, give a 2 x 2
factorial of kicked systems; the timing is switched two ways, so there are two
factorials with the same deflection law:

==================  ====================  ==============================  ====================
deflection \ time   Poisson times         kinetic rate of the disk's L    actual collision times
==================  ====================  ==============================  ====================
uniform direction   ``poisson`` (paper)   ``uniform_kinetic``             ``actual`` (paper)
scatter kick        ``poisson_scatter``   ``poisson_kinetic``             ``actual_scatter``
==================  ====================  ==============================  ====================

The kinetic-rate factorial (`FACTORIAL`) switches the timing to a model of the collision
process (a Cox process whose rate the disk's own angular momentum sets); the actual-times
factorial (`ACTUAL_FACTORIAL`) to the two-disk run's own collision times, which carry
the partner's memory as well. For a diagnostic with kicked / two-disk ratio
:math:`\rho_s`, the gap of system ``s`` is :math:`g_s = |\log \rho_s|`. In each factorial
the gap the two ingredients close together, :math:`g_{UP} - g_{ST}` (``T`` the factorial's
timing), is split by Shapley values (the average of the two orders in which the
ingredients can be added, so no order is privileged):

.. math::

    \phi_{\rm deflection} = \tfrac12\big[(g_{UP} - g_{SP}) + (g_{UT} - g_{ST})\big], \qquad
    \phi_{\rm timing} = \tfrac12\big[(g_{UP} - g_{UT}) + (g_{SP} - g_{ST})\big],

and the shares of the paper's gap :math:`g_{UP}` are :math:`\phi_{\rm deflection}/g_{UP}`,
:math:`\phi_{\rm timing}/g_{UP}` and what is left, :math:`g_{ST}/g_{UP}`: the gap the
factorial's best system still has (one minus the two shares). It is not attributed to any
mechanism: no experiment here switches partner memory or re-collisions on or off. A
negative share is an ingredient that widens the gap. The shares are computed only where
the paper's gap exists: where the CI of :math:`\rho_{UP}` lies entirely outside the
diagnostic's band (`kicktimes.stats.margin_of`: ±5 % for the FTLE, ±3 % for the off-diagonal
RR, ±10 % otherwise) under that control; elsewhere the row says "no gap to decompose" (a gap
inside its own noise is not decomposed). Every quantity is computed under the findings'
controls (`kicktimes.report.controls`; the recurrence diagnostics on uniform-time samples,
the paper's samples as the control ``paper_sampling``; the control experiments' rows are
folded in by :func:`merge_control_gaps`), with a percentile bootstrap clustered on ICs:
one resample draws IC indices and applies them to every system and radius, so the ratios
and their differences come from the same resampled ICs.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from kicktimes.report.controls import diagnostics_of
from kicktimes.report.store import REFERENCE, wide
from kicktimes.stats import (
    bootstrap_nanmedians,
    margin_of,
    percentile_interval,
    resample_indices,
    shapley_values,
)

__all__ = ["ACTUAL_FACTORIAL", "FACTORIAL", "NO_GAP", "NOT_READ", "STEPS", "closes_nothing",
           "gap_decomposition", "gap_everywhere", "gap_figure", "gap_summary", "merge_control_gaps"]

#: the kinetic-rate factorial's systems: (uniform, Poisson), (scatter, Poisson),
#: (uniform, kinetic), (scatter, kinetic)
FACTORIAL = ("poisson", "poisson_scatter", "uniform_kinetic", "poisson_kinetic")
#: the actual-times factorial's: (uniform, Poisson), (scatter, Poisson), (uniform, actual),
#: (scatter, actual)
ACTUAL_FACTORIAL = ("poisson", "poisson_scatter", "actual", "actual_scatter")
#: the shares, in the table's order: the kinetic-rate factorial's three, then the
#: actual-times factorial's three
STEPS = ("deflection law (Shapley)", "kinetic-rate timing (Shapley)",
         "left by the kinetic scatter kick (not attributed)",
         "deflection law, actual-times factorial (Shapley)", "actual-times timing (Shapley)",
         "left by the actual scatter kick (not attributed)")
#: the shares with a tested ingredient (the others are what is left)
INGREDIENTS = (STEPS[0], STEPS[1], STEPS[3], STEPS[4])
#: what a share's row says where the paper's gap lies inside its diagnostic's band
NO_GAP = "no gap to decompose"


def _arrays(table, systems, keep):
    """Per system a (radius, IC) array of values (NaN where missing or left out), the
    reference's, and the radii."""
    table = table.copy()
    radii = sorted(table.index.get_level_values(0).unique())
    ics = sorted(table.index.get_level_values(1).unique())
    full = pd.MultiIndex.from_product([radii, ics], names=["radius", "ic"])
    table = table.reindex(full)
    keep = keep.reindex(full, fill_value=True).to_numpy(bool).reshape(len(radii), len(ics))
    y = table[REFERENCE].to_numpy(float).reshape(len(radii), len(ics))
    xs = [table[s].to_numpy(float).reshape(len(radii), len(ics)) for s in systems]
    ok = np.isfinite(y) & keep
    for x in xs:
        ok &= np.isfinite(x)
    return [np.where(ok, x, np.nan) for x in xs], np.where(ok, y, np.nan), radii


def _ratio_means(x, y, counts):
    """Per resample the mean over radii of the ratio of weighted sums (``counts``: the
    resampled multiplicity of each IC, shape (B, N))."""
    num = counts @ np.nan_to_num(x).T
    den = counts @ np.nan_to_num(y).T
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a radius without pairs
        return np.nanmean(num / den, axis=1)


def _ratio_medians(x, y, idx):
    """Per resample the mean over radii of the median per-IC ratio (``idx``: resampled IC
    indices, shape (B, N))."""
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a radius without pairs
        q = x / y
        # radii x B, C-ordered as the reduction over radii expects (its summation order)
        medians = np.ascontiguousarray(bootstrap_nanmedians(q, idx).T)
        return np.nanmean(medians, axis=0)


def shapley_shares(rho):
    r"""The Shapley shares of the paper's gap from the factorial's four ratios.

    ``rho``: array of shape (4, ...) in the order of `FACTORIAL`. Returns an array (3, ...):
    deflection, timing and remainder, each over :math:`g_{UP} = |\log \rho_{UP}|`.

    Examples
    --------
    >>> import numpy as np
    >>> rho = np.array([0.25, 0.5, 0.25, 0.5])  # only the deflection law matters
    >>> shapley_shares(rho).round(3).tolist()
    [0.5, 0.0, 0.5]
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        g_up, g_sp, g_uk, g_sk = np.abs(np.log(np.asarray(rho, float)))
        # players 0 (the deflection law) and 1 (the kinetic-rate timing); a coalition's
        # value is minus the gap left with its ingredients
        deflection, timing = shapley_values(
            {frozenset(): -g_up, frozenset({0}): -g_sp, frozenset({1}): -g_uk,
             frozenset({0, 1}): -g_sk}, 2)
        return np.stack([deflection / g_up, timing / g_up, g_sk / g_up])


def gap_decomposition(results, collisions, *, family, eps, rule="mirror", rng, n_boot=1000,
                      level=0.95, kinetic=None) -> pd.DataFrame:
    """The Shapley decomposition of every comparison diagnostic's gap under every control.

    Parameters
    ----------
    results, collisions : pandas.DataFrame
        A store's tables (`kicktimes.experiment.load_store`), with the systems of
        `FACTORIAL` and ``two_particle``.
    family : str
        The experiment's name.
    eps : sequence of float
        The experiment's recurrence thresholds.
    rule : {"mirror", "elastic"}
        The collision rule (it defines the sticky runs).
    rng : numpy.random.Generator
        The bootstrap's stream.
    n_boot : int
        Bootstrap resamples of the ICs.
    level : float
        Confidence level of the percentile intervals.

    Returns
    -------
    pandas.DataFrame
        One row per (diagnostic, control, quantity): ``family, diagnostic, control,
        quantity, estimate, ci_low, ci_high, note``. Quantities: ``ratio <system>`` for the
        factorial, then the three `STEPS` shares (NaN with ``note = NO_GAP`` where the
        paper's ratio lies inside its band). Empty without the factorial's systems.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> rows = [(0.01, i, s, "lyapunov", v) for i in range(8) for s, v in
    ...         (("two_particle", 1.0), ("poisson", 0.25), ("poisson_scatter", 0.5),
    ...          ("uniform_kinetic", 0.25), ("poisson_kinetic", 0.5))]
    >>> res = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    >>> col = pd.DataFrame({"radius": [0.01] * 8, "ic": range(8), "t_window": [1e3] * 8,
    ...                     "n_pp": [16] * 8})
    >>> tab = gap_decomposition(res, col, family="demo", eps=(), rng=np.random.default_rng(0),
    ...                         n_boot=50)
    >>> tab[tab["control"] == "primary"]["estimate"].round(2).tolist()[4:]
    [0.5, 0.0, 0.5]
    """
    from kicktimes.report.counts import sticky_ics

    columns = ["family", "diagnostic", "control", "quantity", "estimate", "ci_low", "ci_high",
               "note"]
    present = set(results["system"].unique())
    if not set(FACTORIAL) | {REFERENCE} <= present:
        return pd.DataFrame(columns=columns)
    systems = list(dict.fromkeys(FACTORIAL + ACTUAL_FACTORIAL))
    actual = set(ACTUAL_FACTORIAL) <= present
    if not actual:
        systems = list(FACTORIAL)
    where = [systems.index(s) for s in FACTORIAL]
    where_actual = [systems.index(s) for s in ACTUAL_FACTORIAL] if actual else None
    sticky = sticky_ics(collisions, rule, kinetic=kinetic).set_index(["radius", "ic"])["sticky"]
    rows = []
    for diagnostic, row, uniform in diagnostics_of(results, eps):
        # recurrence: uniform-time samples are the primary setting (as in the findings)
        main = wide(results, uniform if uniform is not None else row)
        settings = [("primary", "mean", main), ("paired_median", "median", main),
                    ("sticky_excluded", "mean", main)]
        if uniform is not None:
            settings.append(("paper_sampling", "mean", wide(results, row)))
        n_ic = None
        for control, name, table in settings:
            if diagnostic == "one_minus_r1":
                table = 1.0 - table
            keep = (~sticky if control == "sticky_excluded"
                    else pd.Series(True, index=sticky.index))
            xs, y, _ = _arrays(table, systems, keep)
            if n_ic is None:
                n_ic = y.shape[1]
                idx = resample_indices(n_ic, n_boot=n_boot, rng=rng)
                counts = np.zeros((n_boot, n_ic))
                np.add.at(counts, (np.arange(n_boot)[:, None], idx), 1.0)
            ones = np.ones((1, n_ic))
            if name == "mean":
                point = np.array([_ratio_means(x, y, ones)[0] for x in xs])
                boot = np.stack([_ratio_means(x, y, counts) for x in xs])
            else:
                every = np.arange(n_ic)[None, :]
                point = np.array([_ratio_medians(x, y, every)[0] for x in xs])
                boot = np.stack([_ratio_medians(x, y, idx) for x in xs])
            shares = list(shapley_shares(point[where, None])[:, 0])
            boot_shares = list(shapley_shares(boot[where]))
            steps = list(STEPS[:3])
            if actual:
                shares += list(shapley_shares(point[where_actual, None])[:, 0])
                boot_shares += list(shapley_shares(boot[where_actual]))
                steps += list(STEPS[3:])
            lo0, hi0 = percentile_interval(boot[0], level=level)
            margin = margin_of(diagnostic)
            gap = bool(hi0 < 1 - margin or lo0 > 1 + margin)
            names = [f"ratio {s}" for s in systems] + steps
            estimates = [*point, *shares]
            draws = [*boot, *boot_shares]
            for k, (quantity, est, dist) in enumerate(zip(names, estimates, draws, strict=True)):
                note = ""
                if k >= len(systems) and not gap:
                    rows.append((family, diagnostic, control, quantity, np.nan, np.nan, np.nan,
                                 NO_GAP))
                    continue
                lo, hi = percentile_interval(dist, level=level)
                rows.append((family, diagnostic, control, quantity, float(est), float(lo),
                             float(hi), note))
    return pd.DataFrame(rows, columns=columns)


def merge_control_gaps(tables) -> pd.DataFrame:
    """Fold the gap tables of control experiments into their family's, as
    `kicktimes.report.controls.merge_control_families` does for the findings: the
    ``primary`` rows of experiment ``"<family>-<control>"`` become rows of ``<family>``
    with ``control = "<control>"`` (when ``<family>``'s own table is present)."""
    tables = [t for t in tables if t is not None and not t.empty]
    if not tables:
        return pd.DataFrame()
    names = {t["family"].iloc[0] for t in tables}
    out = []
    for t in tables:
        family, _, control = t["family"].iloc[0].partition("-")
        if control and family in names:
            out.append(t[t["control"] == "primary"].assign(family=family, control=control))
        else:
            out.append(t)
    return pd.concat(out, ignore_index=True)


#: what a kinetic-factorial share's cell says where that factorial closes none of the gap
NOT_READ = "not read (closes none)"


def closes_nothing(table: pd.DataFrame) -> set:
    """The ``(family, diagnostic)`` pairs whose kinetic-rate factorial closes none of the
    paper's gap under every control: each control's 'left' (one minus its two shares) has
    a 95 % CI that contains 1. Their two shares then only redistribute nothing (typically
    they cancel), so the pages do not read them; the actual-times factorial's shares stand
    apart. Where some control's 'left' excludes 1, the factorial closes part of the gap
    (or widens it) under that control, and its shares are read with their sign marks."""
    left = table[table["quantity"] == STEPS[2]]
    out = set()
    for key, g in left.groupby(["family", "diagnostic"], sort=False, observed=True):
        if len(g) and ((g["ci_low"] <= 1) & (g["ci_high"] >= 1)).all():
            out.add(key)
    return out


def gap_everywhere(table: pd.DataFrame) -> dict:
    """Per ``(family, diagnostic)``, ``""`` when the paper's gap exists under every control
    (the only case decomposed on the pages: a gap that one control removes is inside its
    own noise), else the first control without a gap."""
    out = {}
    shares = table[table["quantity"] == STEPS[0]]
    for key, part in shares.groupby(["family", "diagnostic"], sort=False, observed=True):
        missing = part.loc[~np.isfinite(part["estimate"]), "control"]
        out[key] = str(missing.iloc[0]) if len(missing) else ""
    return out


def _sides(part, step):
    """Per control the side of 0 of the share's CI (1, -1, 0 straddles, None no gap)."""
    sides = {}
    for _, r in part[part["quantity"] == step].iterrows():
        if not np.isfinite(r["estimate"]):
            sides[r["control"]] = None
        else:
            sides[r["control"]] = (1 if r["ci_low"] > 0 else -1 if r["ci_high"] < 0 else 0)
    return sides


def gap_figure(table: pd.DataFrame):
    """The Shapley shares of the paper's gap closed by each tested ingredient (deflection
    law; kinetic-rate timing; actual-times timing), one panel per diagnostic whose gap
    exists under every control in some family (`gap_everywhere`; primary setting:
    uniform-time samples for recurrence), with their 95 % CIs (bootstrap clustered on
    ICs), families side by side, and what is left of the kinetic factorial's gap (one
    minus its two shares; grey: at 1 nothing here closes the gap; no ingredient of it is
    tested). A share whose sign is not the same under every control is drawn faded and
    marked ✗; the kinetic factorial's two shares are not drawn where it closes none of the
    gap (`closes_nothing`: only its 'left' is). One y scale for all."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.report.answers import PANELS

    with_gap = {d for (_, d), missing in gap_everywhere(table).items() if not missing}
    panels = [(d, t) for d, t in PANELS if d in with_gap]
    steps = [s for s in INGREDIENTS if s in set(table["quantity"]) and s != STEPS[3]]
    if STEPS[2] in set(table["quantity"]):
        steps.append(STEPS[2])
    families = list(dict.fromkeys(table["family"]))
    unread = closes_nothing(table)
    fig = Figure(figsize=(max(3.4 * len(panels), 8.0), 4.3), layout="constrained")
    axes = fig.subplots(1, max(len(panels), 1), squeeze=False, sharey=True)[0]
    colours = {STEPS[0]: "tab:red", STEPS[1]: "tab:purple", STEPS[4]: "tab:green",
               STEPS[2]: "0.35"}
    short = {STEPS[0]: "deflection\n(kinetic)", STEPS[1]: "kinetic-rate\ntiming",
             STEPS[4]: "actual-times\ntiming", STEPS[2]: "left (kinetic:\n1 − its shares)"}
    for ax, (diagnostic, title) in zip(axes, panels, strict=False):
        ax.axhline(0.0, color="0.5", linewidth=0.8, zorder=0)
        ax.axhline(1.0, color="0.8", linewidth=0.8, linestyle=":", zorder=0)
        part = table[table["diagnostic"] == diagnostic]
        everywhere = gap_everywhere(table)
        for f, family in enumerate(families):
            if everywhere.get((family, diagnostic), "none"):
                continue  # this family's gap vanishes under some control
            fam = part[part["family"] == family]
            rows = fam[fam["control"] == "primary"].set_index("quantity")
            for i, step in enumerate(steps):
                if step not in rows.index or not np.isfinite(rows.loc[step, "estimate"]):
                    continue
                if (family, diagnostic) in unread and step in (STEPS[0], STEPS[1]):
                    continue
                est, lo, hi = rows.loc[step, ["estimate", "ci_low", "ci_high"]]
                sides = set(_sides(fam, step).values())
                robust = step == STEPS[2] or (len(sides) == 1 and sides <= {1, -1})
                x = i + 0.22 * (f - (len(families) - 1) / 2)
                ax.errorbar([x], [est], yerr=[[max(est - lo, 0.0)], [max(hi - est, 0.0)]],
                            fmt="os"[f % 2], color=colours[step], capsize=2.5, ms=5,
                            alpha=1.0 if robust else 0.45)
                if not robust:
                    ax.annotate("✗", (x, hi), textcoords="offset points", xytext=(0, 3),
                                ha="center", fontsize="small", color=colours[step])
        ax.set_xticks(range(len(steps)), [short[s] for s in steps], fontsize="small")
        ax.set_xlim(-0.5, len(steps) - 0.5)
        ax.set_title(title, fontsize="medium")
    if not panels:
        axes[0].text(0.5, 0.5, "no gap to decompose: the paper's kick is within\nits "
                     "diagnostic's band (or its CI on a band edge)\nfor every diagnostic",
                     transform=axes[0].transAxes, ha="center", va="center",
                     fontsize="small", color="0.3")
    axes[0].set_ylabel("share of the paper's gap |log(kicked / two-disk)|")
    handles = [Line2D([], [], color="k", marker="os"[f % 2], linestyle="none", label=fam)
               for f, fam in enumerate(families)]
    handles.append(Line2D([], [], color="k", marker="o", alpha=0.45, linestyle="none",
                          label="✗ faded: the sign changes or the CI contains 0 under some "
                                "control"))
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles),
               fontsize="small")
    fig.suptitle("Share of the paper's gap closed by each ingredient (Shapley, 95 % CI)\n"
                 "deflection, kinetic-rate timing, 'left': the kinetic-rate factorial;\n"
                 "actual-times timing: the actual-times factorial", fontsize="medium")
    return fig


def gap_summary(table: pd.DataFrame) -> pd.DataFrame:
    """One row per (family, diagnostic): each share under the primary setting with its
    95 % CI (or `NO_GAP`), and for the shares of a tested ingredient whether its sign is
    the same under every control: ``"sign ✓ (a to b)"`` with the range of the estimates
    over the controls (the sign is all the mark checks; the range shows how much the size
    moves), or ``"✗ <control>: ..."`` naming the first control that breaks it. What is
    left gets no mark: it is not attributed.

    Returns columns ``family, diagnostic`` and per step ``<step>`` and ``<step> robust``.
    """
    from kicktimes.stats import format_interval

    rows = []
    steps = [s for s in STEPS if s in set(table["quantity"])]
    unread = closes_nothing(table)
    for (family, diagnostic), part in table.groupby(["family", "diagnostic"], sort=False,
                                                    observed=True):
        head = part[part["control"] == "primary"].set_index("quantity")
        row = {"family": family, "diagnostic": diagnostic}
        for step in steps:
            if (family, diagnostic) in unread and step in (STEPS[0], STEPS[1]):
                row[step], row[f"{step} robust"] = NOT_READ, "—"
                continue
            est, lo, hi = head.loc[step, ["estimate", "ci_low", "ci_high"]]
            row[step] = (format_interval(est, lo, hi, edges=(0.0,)) if np.isfinite(est)
                         else NO_GAP)
            if step not in INGREDIENTS or not np.isfinite(est):
                values = part.loc[part["quantity"] == step, "estimate"].dropna()
                # what is left gets no mark, but its range over the controls
                row[f"{step} robust"] = (f"({values.min():.2g} to {values.max():.2g} over "
                                         "the controls)" if np.isfinite(est) and len(values) > 1
                                         else "—")
                continue
            verdict = None
            first = None
            for control, side in _sides(part, step).items():
                if side is None:
                    verdict = f"✗ {control} (no gap)"
                elif side == 0:
                    verdict = f"✗ {control}: CI contains 0"
                elif first is not None and side != first:
                    verdict = f"✗ {control}: other sign"
                first = side if first is None else first
                if verdict:
                    break
            values = part.loc[part["quantity"] == step, "estimate"]
            if verdict is None:
                verdict = f"sign ✓ ({values.min():.2g} to {values.max():.2g})"
            elif verdict.endswith("other sign"):
                # a share whose sign changes with the control has no size to quote: the
                # range over the controls, not the primary's interval
                row[step] = (f"sign depends on the control ({values.min():.2g} to "
                             f"{values.max():.2g})")
                verdict = f"✗ {verdict[2:].split(':')[0]}"
            row[f"{step} robust"] = verdict
        rows.append(row)
    return pd.DataFrame(rows)
