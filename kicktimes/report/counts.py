r"""Number of disk-disk collisions against radius, its regressions and the kinetic theory
(the paper's Fig. 5), and the sticky ICs whose collision rate is far above the kinetic one.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from kicktimes.render.figures import (
    check_frame,
    check_radii,
    finite,
    new_axes,
    radius_axis,
)
from kicktimes.render.pages import p_value_text
from kicktimes.report.context import Section
from kicktimes.stats import STICKY_FACTOR
from kicktimes.validation import keyword_only_after

__all__ = ["counts_by_radius", "counts_vs_radius", "experiment_kinetic", "kinetic_rate_of",
           "sticky_ics",
           "STICKY_FACTOR", "sections"]



def kinetic_rate_of(radius, rule="mirror", kinetic=None):
    """The kinetic rate at ``radius``: ``kinetic(radius)`` if given (e.g.
    ``Experiment.kinetic_rate``, the pair's rate for unequal disks), else that of two equal
    disks under ``rule`` (`kicktimes.stats.kinetic_rate`)."""
    if kinetic is not None:
        return kinetic(radius)
    from kicktimes import stats

    return stats.kinetic_rate(radius, rule=rule)


def experiment_kinetic(exp):
    """The kinetic rate of an experiment's disks as a function of the radius
    (``Experiment.kinetic_rate``: the pair's for unequal disks), or ``None`` for an object
    without one (the event times of `kicktimes analyze`, a duck-typed experiment): then the
    equal disks' rate under its rule."""
    return getattr(exp, "kinetic_rate", None)


def sticky_ics(collisions, rule="mirror", *, factor=STICKY_FACTOR,
               kinetic=None) -> pd.DataFrame:
    """Per (radius, IC): collision rate, kinetic rate and whether the IC is sticky.

    Parameters
    ----------
    collisions : pandas.DataFrame
        ``radius, ic, n_pp, t_window`` (a store's collision table).
    rule : {"mirror", "elastic"}
        Rule of the kinetic rate :func:`kicktimes.stats.kinetic_rate`.
    factor : float
        Threshold: sticky when ``n_pp / t_window > factor * kinetic_rate(r, rule)``.
    kinetic : callable, optional
        The kinetic rate as a function of the radius (array in, array out), e.g.
        ``Experiment.kinetic_rate`` for unequal disks; default
        ``kicktimes.stats.kinetic_rate(r, rule)`` (equal disks).

    Returns
    -------
    pandas.DataFrame
        ``radius, ic, rate, kinetic_rate, rate_over_kinetic, sticky``.

    Examples
    --------
    >>> import pandas as pd
    >>> from kicktimes.report.counts import sticky_ics
    >>> df = pd.DataFrame({"radius": [0.01, 0.01], "ic": [0, 1], "n_pp": [10, 400],
    ...                    "t_window": [1000.0, 1000.0]})
    >>> sticky_ics(df)["sticky"].tolist()
    [False, True]
    """
    df = check_frame("collisions", collisions, ["radius", "ic", "n_pp", "t_window"])
    out = df[["radius", "ic"]].copy()
    out["rate"] = df["n_pp"].to_numpy(float) / df["t_window"].to_numpy(float)
    out["kinetic_rate"] = kinetic_rate_of(df["radius"].to_numpy(float), rule, kinetic)
    out["rate_over_kinetic"] = out["rate"] / out["kinetic_rate"]
    out["sticky"] = out["rate_over_kinetic"] > factor
    return out.reset_index(drop=True)


# ------------------------------------------------------------- counts vs radius


def counts_by_radius(collisions, *, x="radius") -> pd.DataFrame:
    """Per radius: ``n_ics``, ``mean_count``, ``std_count``, ``sem``, ``mean_t_window``.

    ``collisions`` has one row per (radius, IC) with ``radius``, ``n_pp``, ``t_window``;
    with ``x``, per value of that numeric column instead of the radius.
    """
    df = check_frame("collisions", collisions, [x, "n_pp", "t_window"])
    (check_radii if x == "radius" else finite)(f"collisions[{x!r}]", df[x])
    n_pp = finite("collisions['n_pp']", df["n_pp"])
    if (n_pp < 0).any():
        raise ValueError("collisions['n_pp'] must be non-negative")
    if (finite("collisions['t_window']", df["t_window"]) <= 0).any():
        raise ValueError("collisions['t_window'] must be positive")
    g = df.groupby(x, observed=True)
    out = pd.DataFrame(
        {
            "n_ics": g.size(),
            "mean_count": g["n_pp"].mean(),
            "std_count": g["n_pp"].std(ddof=1),
            "mean_t_window": g["t_window"].mean(),
        }
    )
    out["sem"] = out["std_count"] / np.sqrt(out["n_ics"])
    return out


@keyword_only_after(1, since="0.2.0", names=('regression',))
def counts_vs_radius(collisions, *, regression=None, rule="mirror", ax=None, kinetic=None):
    r"""Mean number of disk-disk collisions against radius, with the fitted curves.

    Parameters
    ----------
    collisions : pandas.DataFrame
        One row per (radius, IC): ``radius``, ``n_pp`` (collision count) and
        ``t_window`` (observation time of that run).
    regression : CountRegression, optional
        From :func:`kicktimes.stats.regress_counts` on the same data (computed with
        ``rule`` when omitted).
    rule : {"mirror", "elastic"}
        Collision rule of the kinetic-theory curve (the regression's rule wins when it
        has one).
    ax : matplotlib Axes, optional
    kinetic : callable, optional
        The kinetic rate against the radius, as in `sticky_ics`.

    Returns
    -------
    matplotlib.figure.Figure
        Means ± s.e.m. over ICs; the paper's least-squares line, the Poisson and
        negative-binomial regressions (``log E[N] = b0 + b1 g(r) + log T``) and the
        kinetic rate :math:`\Gamma(r)\,T`, every curve evaluated at the mean window
        :math:`\bar T(r)` of each radius (linearly interpolated between radii).
    """
    from kicktimes import stats

    table = counts_by_radius(collisions)
    if regression is None:
        frame = collisions[["radius", "n_pp", "t_window"]].rename(columns={"n_pp": "count"})
        regression = stats.regress_counts(frame, rule=rule)
    elif not hasattr(regression, "predict") or not hasattr(regression, "negbin"):
        raise TypeError(
            f"regression must be a CountRegression (stats.regress_counts), got "
            f"{type(regression).__name__}"
        )
    r = table.index.to_numpy()
    grid = np.linspace(r.min(), r.max(), 200) if r.size > 1 else r
    t_grid = np.interp(grid, r, table["mean_t_window"].to_numpy())
    pred = regression.predict(grid, t_window=t_grid)
    kinetic_rule = regression.rule or rule
    # the kinetic rate at 9 radii, the line drawn through them: a table's rate is a
    # quadrature per radius (about a second each in an ellipse), and the rate is smooth in r
    nodes = np.linspace(r.min(), r.max(), 9) if r.size > 1 else r
    t_nodes = np.interp(nodes, r, table["mean_t_window"].to_numpy())
    kinetic = np.asarray(kinetic_rate_of(nodes, kinetic_rule, kinetic)) * t_nodes
    fig, ax = new_axes(ax, (6.0, 4.4))
    ax.errorbar(
        r,
        table["mean_count"],
        yerr=table["sem"],
        linestyle="none",
        marker="o",
        color="black",
        capsize=3,
        label="mean over ICs ± s.e.m.",
    )
    ax.plot(grid, pred["ols"], color="tab:red", label="least-squares line (paper)")
    ax.plot(grid, pred["poisson"], color="tab:green", linestyle="--", label="Poisson regression")
    ax.plot(
        grid,
        pred["negbin"],
        color="tab:purple",
        linestyle="-.",
        label=f"negative binomial (α = {regression.alpha:.3g})",
    )
    ax.plot(
        nodes, kinetic, color="grey", linestyle=":",
        label=f"kinetic theory Γ(r)·T ({kinetic_rule})"
    )
    radius_axis(ax)
    ax.set_ylabel("disk-disk collisions per run (count)")
    ax.set_title("Mean number of disk-disk collisions")
    ax.legend(fontsize="small")
    return fig


def sections(ctx):
    """Counts per radius, their regressions, over-dispersion and sticky ICs."""
    from kicktimes import stats

    exp, coll = ctx.exp, ctx.store.collisions
    table = counts_by_radius(coll)
    grouped = coll.groupby("radius", observed=True)
    table["pooled_rate"] = grouped["n_pp"].sum() / grouped["t_window"].sum()
    kinetic = experiment_kinetic(exp)
    table["kinetic_rate"] = kinetic_rate_of(table.index.to_numpy(), exp.rule, kinetic)
    table["rate_over_kinetic"] = table["pooled_rate"] / table["kinetic_rate"]
    table["dispersion_index"] = grouped["n_pp"].var(ddof=1) / grouped["n_pp"].mean()
    sticky = sticky_ics(coll, exp.rule, kinetic=kinetic)
    ctx.found.sticky = sticky
    table["n_sticky"] = sticky.groupby("radius", observed=True)["sticky"].sum().astype(int)
    sec = Section("counts", "Number of disk-disk collisions against radius")
    sec.table("counts_by_radius", table.reset_index(), "Counts per radius")
    sec.table("sticky_ics", sticky[sticky["sticky"]], "Sticky ICs", show=False)
    n_sticky = int(sticky["sticky"].sum())
    sec.text(
        f"Sticky ICs (collision rate above {STICKY_FACTOR:g} × the kinetic rate Γ(r), "
        f"{exp.rule} rule): {n_sticky} of {len(sticky)} (radius, IC) runs"
        + (
            " ("
            + ", ".join(f"{int(k)} at r = {r:g}" for r, k in table["n_sticky"].items() if k > 0)
            + "); they are flagged in the recurrence and autocorrelation tables, which give "
            "medians beside the means because a few such runs can move a mean."
            if n_sticky
            else "."
        )
    )
    if coll["radius"].nunique() < 2:
        sec.text("One radius only: no regression on radius.")
        return [sec]
    frame = coll[["radius", "n_pp", "t_window"]].rename(columns={"n_pp": "count"})
    with warnings.catch_warnings():
        # two radii leave the line no residual degree of freedom: its standard errors
        # are undefined (NaN in the table), which statsmodels warns about
        warnings.simplefilter("ignore", RuntimeWarning)
        reg = stats.regress_counts(frame, rule=exp.rule)
        coef = reg.coefficients()
        od = reg.overdispersion()
    sec.figure(
        "fig04_counts_vs_radius",
        counts_vs_radius(coll, regression=reg, rule=exp.rule, kinetic=kinetic),
        "Mean number of disk-disk collisions per run against radius (± s.e.m. over ICs) with "
        "the paper's least-squares line, Poisson and negative-binomial regressions and the "
        f"kinetic-theory count Γ(r)·T ({exp.rule} rule), curves at the mean window T(r).",
    )
    b1 = coef.loc[("negbin", reg.covariate)]
    sec.text(
        f"Least-squares line of the pooled rate on r: slope {reg.ols.params[1]:.4g} per unit r "
        f"per time unit, R² = {reg.ols.rsquared:.4f} over {len(table)} radii. Counts are "
        + ("over-dispersed" if od["lr_pvalue"] < 0.05 else "not significantly over-dispersed")
        + f" across ICs: Poisson Pearson dispersion {od['pearson_dispersion']:.3g}, "
        f"negative-binomial α = {od['alpha']:.3g} (LR test of α = 0: p = "
        f"{p_value_text(od['lr_pvalue'])}); AIC Poisson {reg.aic['poisson']:.6g} vs negative "
        f"binomial {reg.aic['negbin']:.6g}. The negative-binomial exponent of r is "
        f"{b1['estimate']:.3f} "
        f"(95% CI {b1['ci_low']:.3f} to {b1['ci_high']:.3f}; kinetic theory: about 1). The "
        f"pooled rate is {table['rate_over_kinetic'].min():.3g} to "
        f"{table['rate_over_kinetic'].max():.3g} times the kinetic-theory rate "
        f"(the {exp.ic_method} ICs are "
        + (
            "drawn from the invariant measure, so the ratio should be 1)."
            if exp.ic_method == "uniform"
            else "not from the invariant measure, so the ratio need not be 1)."
        )
    )
    sec.table("count_regression", coef.reset_index(), "Count regressions (coefficients)")
    sec.table(
        "count_overdispersion",
        od.to_frame("value").reset_index(names="quantity"),
        "Over-dispersion",
    )
    ctx.found.count_regression = reg
    return [sec]


def effects(ctx):
    """Observed disk-disk collision counts over the kinetic-theory counts Γ(r)·T."""
    from kicktimes.report.effects import Effect, store_ratio

    coll = ctx.store.collisions.set_index(["radius", "ic"])
    r = coll.index.get_level_values("radius").to_numpy(float)
    expected = (kinetic_rate_of(r, ctx.exp.rule, experiment_kinetic(ctx.exp))
                * coll["t_window"].to_numpy(float))
    expected = pd.Series(expected, index=coll.index)
    per_r, tot = store_ratio(ctx, coll["n_pp"].astype(float), expected)
    sticky = ctx.found.sticky
    n_sticky = int(sticky["sticky"].sum()) if sticky is not None else 0
    return [
        Effect.of_ratio(
            "Collision counts against kinetic theory",
            "",
            f"ratio ΣN / Σ Γ(r)T ({ctx.exp.rule} rule, averaged over radii)",
            tot,
            tolerance=ctx.tolerance,
            method=f"bootstrap over {tot['n_ics']} ICs",
            detail=(
                f"per-radius ratio {per_r['ratio'].min():.3g} to {per_r['ratio'].max():.3g}; "
                f"{n_sticky} sticky runs (rate > {STICKY_FACTOR:g} Γ); ICs are "
                + (
                    "drawn from the invariant measure"
                    if ctx.exp.ic_method == "uniform"
                    else f"{ctx.exp.ic_method} ICs, not the invariant measure, so the ratio "
                    "need not be 1"
                )
            ),
        )
    ]
