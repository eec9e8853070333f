r"""How much of the kicked-versus-two-disk gap each ingredient of the kicks closes.

Two ingredients of a real disk-disk collision, each switched on or off, give a 2 x 2
factorial of kicked systems:

==================  ====================  ==============================
deflection \ time   Poisson times         kinetic rate of the disk's L
==================  ====================  ==============================
uniform direction   ``poisson`` (paper)   ``uniform_kinetic``
scatter kick        ``poisson_scatter``   ``poisson_kinetic``
==================  ====================  ==============================

For a diagnostic with kicked / two-disk ratio :math:`\rho_s`, the gap of system ``s`` is
:math:`g_s = |\log \rho_s|`. The gap the two ingredients close together,
:math:`g_{UP} - g_{SK}`, is split by Shapley values (the average of the two orders in
which the ingredients can be added, so no order is privileged):

.. math::

    \phi_{\rm deflection} = \tfrac12\big[(g_{UP} - g_{SP}) + (g_{UK} - g_{SK})\big], \qquad
    \phi_{\rm timing} = \tfrac12\big[(g_{UP} - g_{UK}) + (g_{SP} - g_{SK})\big],

and the shares of the paper's gap :math:`g_{UP}` are :math:`\phi_{\rm deflection}/g_{UP}`,
:math:`\phi_{\rm timing}/g_{UP}` and the remainder :math:`g_{SK}/g_{UP}` (partner memory,
re-collisions: what no kick law has; *not measured*, only left over). They sum to one; a
negative share is an ingredient that widens the gap. The shares are computed only where
the paper's gap exists: where the CI of :math:`\rho_{UP}` lies entirely outside the
±10 % band under that control; elsewhere the row says "no gap to decompose" (a gap
inside its own noise is not decomposed). Every quantity is computed under the findings'
controls (`kicktimes.report.controls`; the recurrence diagnostics on uniform-time samples,
the paper's samples as the control ``paper_sampling``), with a percentile bootstrap
clustered on ICs: one resample draws IC indices and applies them to every system and
radius, so the four ratios and their differences come from the same resampled ICs.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from kicktimes.report.common import REFERENCE, wide
from kicktimes.report.controls import diagnostics_of
from kicktimes.stats import bootstrap_nanmedians

__all__ = ["FACTORIAL", "NO_GAP", "STEPS", "gap_decomposition", "gap_figure", "gap_summary"]

#: the factorial's systems: (uniform, Poisson), (scatter, Poisson), (uniform, kinetic),
#: (scatter, kinetic)
FACTORIAL = ("poisson", "poisson_scatter", "uniform_kinetic", "poisson_kinetic")
#: the shares, in the table's order
STEPS = ("deflection law (Shapley)", "state-dependent timing (Shapley)",
         "remainder (partner memory, re-collisions; not measured)")
#: what a share's row says where the paper's gap lies inside the ±10 % band
NO_GAP = "no gap to decompose"
_BAND = (0.9, 1.1)


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
        deflection = 0.5 * ((g_up - g_sp) + (g_uk - g_sk))
        timing = 0.5 * ((g_up - g_uk) + (g_sp - g_sk))
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
    sticky = sticky_ics(collisions, rule, kinetic=kinetic).set_index(["radius", "ic"])["sticky"]
    alpha = (1.0 - level) / 2.0
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
            xs, y, _ = _arrays(table, FACTORIAL, keep)
            if n_ic is None:
                n_ic = y.shape[1]
                idx = rng.integers(0, n_ic, size=(n_boot, n_ic))
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
            shares = shapley_shares(point[:, None])[:, 0]
            boot_shares = shapley_shares(boot)
            finite = boot[0][np.isfinite(boot[0])]
            lo0, hi0 = (np.quantile(finite, [alpha, 1.0 - alpha]) if finite.size
                        else (np.nan, np.nan))
            gap = bool(hi0 < _BAND[0] or lo0 > _BAND[1])
            names = [f"ratio {s}" for s in FACTORIAL] + list(STEPS)
            estimates = [*point, *shares]
            draws = [*boot, *boot_shares]
            for k, (quantity, est, dist) in enumerate(zip(names, estimates, draws, strict=True)):
                note = ""
                if k >= len(FACTORIAL) and not gap:
                    rows.append((family, diagnostic, control, quantity, np.nan, np.nan, np.nan,
                                 NO_GAP))
                    continue
                dist = dist[np.isfinite(dist)]
                lo, hi = (np.quantile(dist, [alpha, 1.0 - alpha]) if dist.size
                          else (np.nan, np.nan))
                rows.append((family, diagnostic, control, quantity, float(est), float(lo),
                             float(hi), note))
    return pd.DataFrame(rows, columns=columns)


def gap_figure(table: pd.DataFrame):
    """The Shapley shares of the paper's gap, one panel per diagnostic with a gap (primary
    setting: uniform-time samples for recurrence), with their 95 % CIs (bootstrap clustered
    on ICs), families side by side; a panel without a gap says so. One y scale for all."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.report.answers import PANELS

    panels = [(d, t) for d, t in PANELS if d in set(table["diagnostic"])]
    families = list(dict.fromkeys(table["family"]))
    fig = Figure(figsize=(2.9 * max(len(panels), 1), 3.9), layout="constrained")
    axes = fig.subplots(1, max(len(panels), 1), squeeze=False, sharey=True)[0]
    colours = ("tab:red", "tab:purple", "0.45")
    short = ("deflection", "timing", "remainder")
    for ax, (diagnostic, title) in zip(axes, panels, strict=False):
        ax.axhline(0.0, color="0.5", linewidth=0.8, zorder=0)
        ax.axhline(1.0, color="0.8", linewidth=0.8, linestyle=":", zorder=0)
        part = table[(table["diagnostic"] == diagnostic) & (table["control"] == "primary")]
        drawn = False
        for f, family in enumerate(families):
            rows = part[part["family"] == family].set_index("quantity")
            for i, step in enumerate(STEPS):
                if step not in rows.index or not np.isfinite(rows.loc[step, "estimate"]):
                    continue
                est, lo, hi = rows.loc[step, ["estimate", "ci_low", "ci_high"]]
                err = [[max(est - lo, 0.0)], [max(hi - est, 0.0)]]
                ax.errorbar([i + 0.2 * (f - (len(families) - 1) / 2)], [est], yerr=err,
                            fmt="os"[f % 2], color=colours[i], capsize=2.5, ms=5,
                            mfc="white" if f else colours[i])
                drawn = True
        if not drawn:
            ax.text(0.5, 0.5, "no gap to decompose:\nthe paper's kick is within\nthe ±10 % "
                    "band or its CI\nstraddles an edge", transform=ax.transAxes,
                    ha="center", va="center", fontsize="small", color="0.3")
        ax.set_xticks(range(len(STEPS)), short, fontsize="small")
        ax.set_xlim(-0.5, len(STEPS) - 0.5)
        ax.set_title(title, fontsize="medium")
    axes[0].set_ylabel("share of the paper's gap |log(kicked / two-disk)|")
    handles = [Line2D([], [], color="k", marker="os"[f % 2], mfc="white" if f else "k",
                      linestyle="none", label=fam) for f, fam in enumerate(families)]
    fig.legend(handles=handles, loc="outside lower center", ncol=max(len(handles), 1),
               fontsize="small")
    fig.suptitle("Shapley shares of the paper's kicked-disk gap closed by the deflection law "
                 "and the timing (95 % CI); the remainder is not measured", fontsize="medium")
    return fig


def gap_summary(table: pd.DataFrame) -> pd.DataFrame:
    """One row per (family, diagnostic): the three shares under the primary setting with
    their 95 % CIs (or `NO_GAP`), and whether each is robust: every control has a gap, and
    every control's CI lies on the same side of 0, none straddling it.

    Returns columns ``family, diagnostic`` and per step ``<step>`` (``"0.62 [0.41, 0.80]"``)
    and ``<step> robust`` (``"✓"``, or ``"✗ <control>"`` naming the first control that breaks
    it).
    """
    from kicktimes.stats import format_interval

    rows = []
    for (family, diagnostic), part in table.groupby(["family", "diagnostic"], sort=False,
                                                    observed=True):
        head = part[part["control"] == "primary"].set_index("quantity")
        row = {"family": family, "diagnostic": diagnostic}
        for step in STEPS:
            est, lo, hi = head.loc[step, ["estimate", "ci_low", "ci_high"]]
            row[step] = (format_interval(est, lo, hi, edges=(0.0,)) if np.isfinite(est)
                         else NO_GAP)
            verdict = "✓"
            sides = []
            for _, r in part[part["quantity"] == step].iterrows():
                side = 1 if r["ci_low"] > 0 else -1 if r["ci_high"] < 0 else 0
                if not np.isfinite(r["estimate"]):
                    verdict = f"✗ {r['control']} (no gap)"
                    break
                if side == 0:
                    verdict = f"✗ {r['control']}: CI contains 0"
                    break
                if sides and side != sides[0]:
                    verdict = f"✗ {r['control']}: other sign"
                    break
                sides.append(side)
            row[f"{step} robust"] = verdict if np.isfinite(est) else "—"
        rows.append(row)
    return pd.DataFrame(rows)
