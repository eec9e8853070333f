r"""How much of the kicked-versus-two-disk gap each ingredient of the kicks closes.

The kicked disk approaches the two-disk system in three steps, each adding one
ingredient of a real disk-disk collision:

1. ``poisson``: a uniform new direction at Poisson times (the paper's kicked disk);
2. ``poisson_scatter``: a collision with a virtual partner, at the same kind of times
   (the *deflection law*);
3. ``poisson_kinetic``: the same collisions at the kinetic rate of the disk's own
   angular momentum, redrawn after every kick (the *state-dependent timing*);

and what no kick law has is the rest: the partner's memory (its angular momentum is
correlated with the disk's, and the pair can meet again soon after a glancing
collision). For a diagnostic with kicked / two-disk ratio :math:`\rho_s`, the gap of
system ``s`` is :math:`g_s = |\log \rho_s|`, and the shares of the paper's gap
:math:`g_{\rm poisson}` closed by each step are

.. math::

    \frac{g_{\rm poisson} - g_{\rm scatter}}{g_{\rm poisson}}, \qquad
    \frac{g_{\rm scatter} - g_{\rm kinetic}}{g_{\rm poisson}}, \qquad
    \frac{g_{\rm kinetic}}{g_{\rm poisson}} \ \text{(left)},

which sum to one; a negative share is a step that widens the gap. Every quantity is
computed under the findings' controls (`kicktimes.report.controls`), with a percentile
bootstrap clustered on ICs: one resample draws IC indices and applies them to every
system and radius, so the three ratios (and their differences) come from the same
resampled ICs.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from kicktimes.report.common import REFERENCE, wide
from kicktimes.report.controls import diagnostics_of
from kicktimes.stats import bootstrap_nanmedians

__all__ = ["LADDER", "STEPS", "gap_decomposition", "gap_figure", "gap_summary"]

#: the kicked systems in the order each adds an ingredient
LADDER = ("poisson", "poisson_scatter", "poisson_kinetic")
#: the step each share measures, in the table's order
STEPS = ("deflection law (uniform kick -> scatter kick)",
         "state-dependent timing (Poisson -> kinetic rate)",
         "left: partner memory and re-collisions")
_LABELS = {"poisson": "uniform kick, Poisson times", "poisson_scatter": "+ scatter kick",
           "poisson_kinetic": "+ kinetic rate"}


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


def _shares(rho):
    """The gaps ``|log rho|`` of the ladder and the three shares (columns: resamples)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.abs(np.log(rho))
        return g, np.stack([(g[0] - g[1]) / g[0], (g[1] - g[2]) / g[0], g[2] / g[0]])


def gap_decomposition(results, collisions, *, family, eps, rule="mirror", rng, n_boot=1000,
                      level=0.95, kinetic=None) -> pd.DataFrame:
    """The gap decomposition of every comparison diagnostic under every control.

    Parameters
    ----------
    results, collisions : pandas.DataFrame
        A store's tables (`kicktimes.experiment.load_store`), with the systems of `LADDER`
        and ``two_particle``.
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
        quantity, estimate, ci_low, ci_high``. Quantities: ``ratio <system>`` for the
        ladder, then the three `STEPS` shares. Empty without the ladder's systems.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> rows = [(0.01, i, s, "lyapunov", v) for i in range(8) for s, v in
    ...         (("two_particle", 1.0), ("poisson", 0.25), ("poisson_scatter", 0.5),
    ...          ("poisson_kinetic", 0.5))]
    >>> res = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value"])
    >>> col = pd.DataFrame({"radius": [0.01] * 8, "ic": range(8), "t_window": [1e3] * 8,
    ...                     "n_pp": [16] * 8})
    >>> tab = gap_decomposition(res, col, family="demo", eps=(), rng=np.random.default_rng(0),
    ...                         n_boot=50)
    >>> tab[tab["control"] == "primary"].set_index("quantity")["estimate"].round(2).iloc[3:]
    quantity
    deflection law (uniform kick -> scatter kick)       0.5
    state-dependent timing (Poisson -> kinetic rate)    0.0
    left: partner memory and re-collisions              0.5
    Name: estimate, dtype: float64
    """
    from kicktimes.report.counts import sticky_ics

    present = set(results["system"].unique())
    if not set(LADDER) | {REFERENCE} <= present:
        return pd.DataFrame(columns=["family", "diagnostic", "control", "quantity", "estimate",
                                     "ci_low", "ci_high"])
    sticky = sticky_ics(collisions, rule, kinetic=kinetic).set_index(["radius", "ic"])["sticky"]
    alpha = (1.0 - level) / 2.0
    rows = []
    for diagnostic, row, uniform in diagnostics_of(results, eps):
        tables = {"primary": wide(results, row)}
        if uniform is not None:
            tables["uniform_sampling"] = wide(results, uniform)
        n_ic = None
        for control, name, table in (
            ("primary", "mean", tables["primary"]),
            ("paired_median", "median", tables["primary"]),
            ("sticky_excluded", "mean", tables["primary"]),
            *((("uniform_sampling", "mean", tables["uniform_sampling"]),)
              if uniform is not None else ()),
        ):
            if diagnostic == "one_minus_r1":
                table = 1.0 - table
            keep = (~sticky if control == "sticky_excluded"
                    else pd.Series(True, index=sticky.index))
            xs, y, _ = _arrays(table, LADDER, keep)
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
            _, shares = _shares(point[:, None])
            _, boot_shares = _shares(boot)
            estimates = [*point, *shares[:, 0]]
            draws = [*boot, *boot_shares]
            names = [f"ratio {s}" for s in LADDER] + list(STEPS)
            for quantity, est, dist in zip(names, estimates, draws, strict=True):
                dist = dist[np.isfinite(dist)]
                lo, hi = (np.quantile(dist, [alpha, 1.0 - alpha]) if dist.size
                          else (np.nan, np.nan))
                rows.append((family, diagnostic, control, quantity, float(est), float(lo),
                             float(hi)))
    return pd.DataFrame(rows, columns=["family", "diagnostic", "control", "quantity",
                                       "estimate", "ci_low", "ci_high"])


def gap_figure(table: pd.DataFrame):
    """The ladder's ratios per diagnostic, one panel each (uniform-time samples for the
    recurrence diagnostics, the primary setting otherwise), with 95 % CIs (bootstrap
    clustered on ICs) and the ±10 % band; families side by side."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    from kicktimes.report.controls import PANELS, log_ratio_axis
    from kicktimes.report.figures import system_label, system_style

    panels = [(d, t) for d, t in PANELS if d in set(table["diagnostic"])
              and np.isfinite(table.loc[table["diagnostic"] == d, "estimate"]).any()]
    families = list(dict.fromkeys(table["family"]))
    fig = Figure(figsize=(3.0 * max(len(panels), 1), 3.9), layout="constrained")
    axes = fig.subplots(1, max(len(panels), 1), squeeze=False)[0]
    for ax, (diagnostic, title) in zip(axes, panels, strict=False):
        ax.axhspan(0.9, 1.1, color="0.85", zorder=0)
        ax.axhline(1.0, color="0.5", linewidth=0.8, zorder=0)
        part = table[table["diagnostic"] == diagnostic]
        control = ("uniform_sampling" if (part["control"] == "uniform_sampling").any()
                   else "primary")
        for f, family in enumerate(families):
            rows = part[(part["control"] == control) & (part["family"] == family)]
            rows = rows.set_index("quantity")
            for i, system in enumerate(LADDER):
                est, lo, hi = rows.loc[f"ratio {system}", ["estimate", "ci_low", "ci_high"]]
                if not np.isfinite(est):
                    continue
                # (a percentile interval need not contain the point estimate)
                err = [[max(est - lo, 0.0)], [max(hi - est, 0.0)]]
                style = system_style(system)
                ax.errorbar([i + 0.18 * (f - (len(families) - 1) / 2)], [est], yerr=err,
                            fmt=style["marker"], color=style["color"], capsize=2.5, ms=6,
                            mfc="white" if f else style["color"])
        ax.set_xticks(range(len(LADDER)), [_LABELS[s] for s in LADDER], rotation=25,
                      ha="right", fontsize="small")
        ax.set_xlim(-0.5, len(LADDER) - 0.5)
        ax.set_title(title, fontsize="medium")
        log_ratio_axis(ax)
    axes[0].set_ylabel("kicked / two-disk (ratio of means)")
    handles = [Line2D([], [], color=system_style(s)["color"], marker=system_style(s)["marker"],
                      linestyle="none", label=system_label(s)) for s in LADDER]
    if len(families) > 1:
        handles += [Line2D([], [], color="k", marker="o", mfc="white" if f else "k",
                           linestyle="none", label=fam) for f, fam in enumerate(families)]
    handles += [Line2D([], [], color="0.85", linewidth=6, label="±10 % band")]
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles),
               fontsize="small")
    return fig


def gap_summary(table: pd.DataFrame) -> pd.DataFrame:
    """One row per (family, diagnostic): the three shares under the headline setting
    (uniform-time samples for recurrence, the primary ratio otherwise) with their 95 % CIs,
    and whether each share keeps its sign (or its CI's side of 0) under every control.

    Returns columns ``family, diagnostic, setting`` and per step ``<step>`` (``"0.62
    [0.41, 0.80]"``) and ``<step> robust`` (True when the intervals of every control lie on
    the same side of 0 as the headline's, or all contain 0).
    """
    rows = []
    for (family, diagnostic), part in table.groupby(["family", "diagnostic"], sort=False):
        setting = ("uniform_sampling" if (part["control"] == "uniform_sampling").any()
                   else "primary")
        head = part[part["control"] == setting].set_index("quantity")
        row = {"family": family, "diagnostic": diagnostic, "setting": setting}
        for step in STEPS:
            est, lo, hi = head.loc[step, ["estimate", "ci_low", "ci_high"]]
            row[step] = f"{est:.2f} [{lo:.2f}, {hi:.2f}]" if np.isfinite(est) else "n/a"
            sides = set()
            for _, r in part[part["quantity"] == step].iterrows():
                sides.add(1 if r["ci_low"] > 0 else -1 if r["ci_high"] < 0 else 0)
            row[f"{step} robust"] = len(sides) == 1
        rows.append(row)
    return pd.DataFrame(rows)
