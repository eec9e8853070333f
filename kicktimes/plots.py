r"""Figures of the paper and of the collision-time statistics.

Every function takes data (run records, arrays, tidy DataFrames) and returns a
:class:`matplotlib.figure.Figure`. Nothing here touches ``pyplot`` or the global
backend: figures are created with ``Figure(...)`` and saved with ``fig.savefig``, so
they work headless and are never left open in a pyplot registry. Pass ``ax=`` to draw
into an existing Axes (the function then returns that Axes' figure).

Paper figures (Ranković & Porter, Chaos 2013):

* :func:`poincare_section`, :func:`poincare_panels` — ``(s, sin θ)`` of one disk;
* :func:`recurrence_plot` — from :func:`kicktimes.diagnostics.recurrence_pairs`,
  never an N x N matrix;
* :func:`kick_times_vs_collision_times` — k-th Poisson kick time against k-th actual
  collision time with the least-squares line (:func:`kth_time_fit`);
* :func:`counts_vs_radius` — mean disk-disk collision count against radius with the
  paper's line, Poisson / negative-binomial regressions and the kinetic theory;
* :func:`diagnostic_vs_radius` — FTLE / recurrence rate / autocorrelation against
  radius for the three systems with the paper's bars (± std/10) *and* standard
  errors (std/√n_valid); the numbers come from :func:`diagnostic_summary`.

Statistics figures: :func:`poisson_rejection_rates`, :func:`model_comparison`,
:func:`rate_heterogeneity`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pandas as pd
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

SYSTEMS = ("two_particle", "poisson", "actual")
SYSTEM_LABELS = {"two_particle": "Two-particle", "poisson": "Poisson", "actual": "Actual"}
_SYSTEM_STYLE = {
    "two_particle": {"color": "black", "marker": "o"},
    "poisson": {"color": "tab:orange", "marker": "s"},
    "actual": {"color": "tab:blue", "marker": "^"},
}
# (title, y-axis label with units) of each diagnostic of the store
DIAGNOSTIC_LABELS = {
    "lyapunov": ("Finite-time Lyapunov exponent", r"$\lambda$ (1 / time unit)"),
    "lyapunov_x": ("Finite-time Lyapunov exponent (x)", r"$\lambda^x$ (1 / time unit)"),
    "lyapunov_y": ("Finite-time Lyapunov exponent (y)", r"$\lambda^y$ (1 / time unit)"),
    "recurrence_rate": ("Recurrence rate", r"RR($\varepsilon$) (fraction of sample pairs)"),
    "autocorrelation": ("Autocorrelation of boundary angles", r"$R_l$ of $\theta$ (dimensionless)"),
    "n_kicks": ("Number of kicks", "kicks per run (count)"),
    "n_boundary": ("Number of boundary collisions", "boundary collisions per run (count)"),
}
RADIUS_LABEL = "disk radius $r$ (table radii)"
TIME_UNIT = "time units (table radius / speed)"
_PAPER_BAR = {"linewidth": 5.0, "alpha": 0.3}
_SEM_BAR = {"linewidth": 1.0, "capsize": 3.0}


# ----------------------------------------------------------------------------- checks


def _check_frame(name, df, columns, *, allow_empty=False):
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"{name} must be a pandas DataFrame, got {type(df).__name__}")
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"{name} must have columns {list(columns)!r}; missing {missing!r}")
    if len(df) == 0 and not allow_empty:
        raise ValueError(f"{name} must not be empty")
    return df


def _finite(name, values, *, allow_nan=False):
    arr = np.asarray(values, dtype=float)
    bad = np.isinf(arr) if allow_nan else ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad.ravel())[0])
        what = "infinite values" if allow_nan else "NaN or infinite values"
        raise ValueError(f"{name} must not contain {what}, got {arr.ravel()[i]!r} at position {i}")
    return arr


def _check_radii(name, values):
    r = _finite(name, values)
    if ((r <= 0) | (r >= 0.5)).any():
        bad = r[(r <= 0) | (r >= 0.5)][0]
        raise ValueError(f"{name} must satisfy 0 < r < 0.5 (two disks), got {bad!r}")
    return r


def _check_times(name, values):
    t = _finite(name, values)
    if t.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {t.shape}")
    if (t < 0).any():
        raise ValueError(f"{name} must be non-negative, got {t[t < 0][0]!r}")
    if (np.diff(t) < 0).any():
        k = int(np.flatnonzero(np.diff(t) < 0)[0])
        raise ValueError(f"{name} must be sorted increasingly, got {t[k]!r} before {t[k + 1]!r}")
    return t


def _check_alpha(alpha):
    if isinstance(alpha, bool) or not isinstance(alpha, int | float | np.floating):
        raise TypeError(f"alpha must be a number, got {type(alpha).__name__}")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must satisfy 0 < alpha < 1, got {alpha!r}")
    return float(alpha)


def _new_axes(ax, figsize):
    """A fresh constrained-layout Figure with one Axes, or the figure of ``ax``."""
    if ax is None:
        fig = Figure(figsize=figsize, layout="constrained")
        return fig, fig.add_subplot()
    if not hasattr(ax, "figure") or not hasattr(ax, "plot"):
        raise TypeError(f"ax must be a matplotlib Axes, got {type(ax).__name__}")
    fig = ax.figure
    # a SubFigure's .figure is the root Figure; a Figure's .figure is itself
    while getattr(fig, "figure", fig) is not fig:
        fig = fig.figure
    return fig, ax


def _dodge(radii, k, n):
    """x offsets that keep the error bars of ``n`` series at the same radius apart."""
    u = np.unique(radii)
    step = np.min(np.diff(u)) if u.size > 1 else 0.01 * max(u[0], 1e-3)
    return (k - (n - 1) / 2) * 0.12 * step


# ----------------------------------------------------------------------- Poincaré


def _boundary_frame(data, particle):
    if isinstance(particle, bool) or particle not in (0, 1):
        raise ValueError(f"particle must be 0 or 1, got {particle!r}")
    radius = getattr(data, "r", None)
    if isinstance(data, pd.DataFrame):
        df = data
    elif hasattr(data, "boundary"):
        df = data.boundary
    else:
        raise TypeError(
            "data must be a run record (TwoParticleRun / OneParticleRun) or a DataFrame with "
            f"columns s and sin_theta, got {type(data).__name__}"
        )
    _check_frame("boundary data", df, ["s", "sin_theta"])
    if "particle" in df.columns:
        df = df[df["particle"] == particle]
        if len(df) == 0:
            raise ValueError(f"particle {particle} has no boundary collisions in the data")
    s = _finite("s", df["s"].to_numpy())
    st = _finite("sin_theta", df["sin_theta"].to_numpy())
    if ((s < 0) | (s > 2 * math.pi)).any() or (np.abs(st) > 1 + 1e-12).any():
        raise ValueError("boundary data must have s in [0, 2 pi] and sin_theta in [-1, 1]")
    return s, st, radius


def poincare_section(data, particle=0, *, ax=None, title=None, markersize=0.6, color="C0"):
    r"""Poincaré section ``(s, sin θ)`` of one disk's boundary collisions.

    Parameters
    ----------
    data : TwoParticleRun, OneParticleRun or pandas.DataFrame
        A run record (its ``boundary`` table is used) or a DataFrame with columns
        ``s`` (contact point's polar angle in ``[0, 2π)``, = arclength on the unit
        table) and ``sin_theta`` (tangential component of the incoming unit velocity),
        and optionally ``particle``.
    particle : {0, 1}
        The disk to show when the data hold both disks.
    ax : matplotlib Axes, optional
        Draw here instead of a new figure.
    title : str, optional
        Axes title (default: the radius, when the data is a run).
    markersize, color :
        Marker size (points) and colour.

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    Without disk-disk collisions ``sin θ = L/(1-r)`` is conserved, so regular stretches
    show as horizontal segments; disk-disk collisions scatter the points.

    Examples
    --------
    >>> from kicktimes import simulate_two_particle, initial_conditions, plots
    >>> run = simulate_two_particle(initial_conditions(1, 0.02, seed=1)[0], 0.02, t_max=500.0)
    >>> fig = plots.poincare_section(run)
    >>> fig.axes[0].get_ylabel()
    '$\\sin\\theta$ (dimensionless)'
    """
    s, st, radius = _boundary_frame(data, particle)
    fig, ax = _new_axes(ax, (6.0, 3.6))
    # rasterized: a section has 10^4-10^5 points; keep the PDF small
    ax.plot(
        s, st, color=color, marker=".", markersize=markersize, linestyle="none", rasterized=True
    )
    ax.set_xlim(0.0, 2 * math.pi)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xticks(np.arange(5) * math.pi / 2, ["0", r"$\pi/2$", r"$\pi$", r"$3\pi/2$", r"$2\pi$"])
    ax.set_xlabel("arclength $s$ of the contact point (table radii)")
    ax.set_ylabel(r"$\sin\theta$ (dimensionless)")
    if title is None and radius is not None:
        title = f"disk {particle}, r = {radius:g} ({s.size} boundary collisions)"
    if title:
        ax.set_title(title)
    return fig


def poincare_panels(runs, *, particle=0, titles=None, markersize=0.6):
    """Poincaré sections of several runs stacked vertically (the paper: r = 0.02, 0.014).

    Parameters
    ----------
    runs : sequence of run records or DataFrames
        One panel each (see :func:`poincare_section`); the paper uses the same IC.
    particle : {0, 1}
        The disk shown.
    titles : sequence of str, optional
        Panel titles (default: ``(a) r = ...``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if isinstance(runs, pd.DataFrame) or hasattr(runs, "boundary"):
        runs = [runs]
    runs = list(runs)
    if not runs:
        raise ValueError("runs must hold at least one run, got none")
    if titles is not None and len(titles) != len(runs):
        raise ValueError(f"titles must have one entry per run ({len(runs)}), got {len(titles)}")
    fig = Figure(figsize=(6.0, 3.2 * len(runs)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(runs), 1, sharex=True))
    for k, (run, ax) in enumerate(zip(runs, axes, strict=True)):
        title = None if titles is None else titles[k]
        if title is None and getattr(run, "r", None) is not None:
            title = f"({chr(ord('a') + k)}) disk {particle}, r = {run.r:g}"
        poincare_section(run, particle, ax=ax, title=title, markersize=markersize)
        if k < len(runs) - 1:
            ax.set_xlabel("")
    return fig


# ---------------------------------------------------------------- recurrence plot


def _as_pairs(data, eps, n_points):
    """``(i, j, N)`` from index pairs or from points (via recurrence_pairs)."""
    if (
        isinstance(data, tuple | list)
        and len(data) == 2
        and all(isinstance(a, np.ndarray) and a.ndim == 1 for a in data)
    ):
        i, j = (np.asarray(a) for a in data)
        if not (np.issubdtype(i.dtype, np.integer) and np.issubdtype(j.dtype, np.integer)):
            raise TypeError(f"pairs (i, j) must be integer arrays, got {i.dtype} and {j.dtype}")
        if i.shape != j.shape:
            raise ValueError(f"pairs i and j must have the same length, got {i.size} and {j.size}")
        if i.size and (min(i.min(), j.min()) < 0):
            raise ValueError("pairs i and j must be non-negative indices")
        top = int(max(i.max(), j.max())) + 1 if i.size else 0
        if n_points is None:
            n_points = top
        elif isinstance(n_points, bool) or not isinstance(n_points, int | np.integer):
            raise TypeError(f"n_points must be an integer, got {type(n_points).__name__}")
        elif n_points < max(top, 1):
            raise ValueError(f"n_points must be at least max index + 1 = {top}, got {n_points}")
        if n_points < 1:
            raise ValueError("pairs must not be empty when n_points is not given")
        return i, j, int(n_points)
    from kicktimes.diagnostics import recurrence_pairs

    points = data.samples if hasattr(data, "samples") else data
    i, j = recurrence_pairs(points, eps)
    return i, j, int(np.asarray(points).shape[0])


def recurrence_plot(
    data, *, eps=1e-3, n_points=None, tau=None, ax=None, max_markers=300_000, bins=600, title=None
):
    r"""Recurrence plot from the list of recurrent index pairs (never an N x N matrix).

    Parameters
    ----------
    data : (i, j) tuple of integer arrays, array_like (N, 2), or a run record
        Either the pairs from :func:`kicktimes.diagnostics.recurrence_pairs`, or the
        sampled positions (a run's ``samples``), from which the pairs are computed with
        threshold ``eps``.
    eps : float
        Recurrence threshold (used only when points are given), ``eps > 0``.
    n_points : int, optional
        N, the number of samples, when pairs are given (default: largest index + 1).
    tau : float, optional
        Sampling step; when given the axes are in time units ``t = k τ`` (exact for
        uniform sampling, the step index times τ for the paper's sampling).
    ax : matplotlib Axes, optional
    max_markers : int
        Up to this many pairs are drawn as dots; beyond, the pairs are binned on a
        ``bins x bins`` grid (memory O(bins²), not O(N²)) and shown as counts.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    :math:`R_{ij} = \Theta(\varepsilon - |x_i - x_j|)`; the title reports
    RR = (number of pairs) / N² (main diagonal included).
    """
    if (
        isinstance(max_markers, bool)
        or not isinstance(max_markers, int | np.integer)
        or (max_markers < 0)
    ):
        raise ValueError(f"max_markers must be a non-negative integer, got {max_markers!r}")
    if isinstance(bins, bool) or not isinstance(bins, int | np.integer) or not 2 <= bins <= 4000:
        raise ValueError(f"bins must be an integer in [2, 4000], got {bins!r}")
    if tau is not None:
        tau = float(_finite("tau", tau))
        if tau <= 0:
            raise ValueError(f"tau must be positive, got {tau!r}")
    i, j, n = _as_pairs(data, eps, n_points)
    fig, ax = _new_axes(ax, (5.0, 4.6))
    scale = 1.0 if tau is None else tau
    unit = "sample index" if tau is None else f"time ({TIME_UNIT})"
    if i.size <= max_markers:
        # dots big enough to see isolated recurrences, small enough to resolve diagonals
        size = float(np.clip(400.0 / math.sqrt(max(i.size, 1)), 0.8, 3.0))
        ax.plot(
            i * scale,
            j * scale,
            linestyle="none",
            marker=".",
            markersize=size,
            markeredgewidth=0,
            color="black",
            rasterized=True,
        )
    else:
        counts, xe, ye = np.histogram2d(i, j, bins=bins, range=[[0, n], [0, n]])
        image = ax.imshow(
            np.ma.masked_equal(counts.T, 0),
            origin="lower",
            cmap="Greys",
            aspect="equal",
            extent=(0, n * scale, 0, n * scale),
            norm=LogNorm(vmin=1),
            interpolation="nearest",
        )
        cell = f"{n / bins:.3g}"
        fig.colorbar(image, ax=ax, label=f"recurrent pairs per {cell} x {cell} cell")
    ax.set_xlim(0, n * scale)
    ax.set_ylim(0, n * scale)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{unit} $i$")
    ax.set_ylabel(f"{unit} $j$")
    rate = i.size / float(n) ** 2
    ax.set_title(title if title is not None else f"N = {n}, {i.size} pairs, RR = {rate:.3g}")
    return fig


# ------------------------------------------------------- Poisson vs actual times


class TimesFit(NamedTuple):
    """Least-squares line ``poisson_k = intercept + slope * actual_k`` over k."""

    slope: float
    intercept: float
    r_squared: float
    n: int


def kth_time_fit(pp_times, poisson_times) -> TimesFit:
    r"""Least-squares line of the k-th Poisson kick time on the k-th collision time.

    Parameters
    ----------
    pp_times, poisson_times : array_like
        Increasing, finite, non-negative times; the first ``n = min(len)`` are paired.

    Returns
    -------
    TimesFit
        ``slope``, ``intercept``, ``r_squared`` (:math:`1 - SS_{res}/SS_{tot}`), ``n``.

    Examples
    --------
    >>> from kicktimes.plots import kth_time_fit
    >>> round(kth_time_fit([1.0, 2.0, 3.0], [2.0, 4.0, 6.0, 8.0]).slope, 12)
    2.0
    """
    x = _check_times("pp_times", pp_times)
    y = _check_times("poisson_times", poisson_times)
    n = min(x.size, y.size)
    if n < 3:
        raise ValueError(f"need at least 3 paired times for a line and its R², got {n}")
    x, y = x[:n], y[:n]
    slope, intercept = np.polyfit(x, y, 1)
    ss_res = float(np.sum((y - (intercept + slope * x)) ** 2))
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else math.nan
    return TimesFit(float(slope), float(intercept), float(r2), int(n))


def kick_times_vs_collision_times(pp_times, poisson_times, *, ax=None, radius=None):
    r"""The paper's Fig. "Times": k-th Poisson kick time against k-th collision time.

    Parameters
    ----------
    pp_times : array_like
        Disk-disk collision times of one two-particle run (increasing).
    poisson_times : array_like
        Kick times of the Poisson process (rate estimated from that run).
    ax : matplotlib Axes, optional
    radius : float, optional
        Disk radius, for the title.

    Returns
    -------
    matplotlib.figure.Figure
        Points ``(t_k^{actual}, t_k^{Poisson})``, their least-squares line
        (:func:`kth_time_fit`, slope, intercept and R² in the legend) and the diagonal.
    """
    fit = kth_time_fit(pp_times, poisson_times)
    x = np.asarray(pp_times, dtype=float)[: fit.n]
    y = np.asarray(poisson_times, dtype=float)[: fit.n]
    fig, ax = _new_axes(ax, (5.0, 4.4))
    ax.plot(
        x,
        y,
        linestyle="none",
        marker="o",
        markersize=3,
        color="tab:blue",
        label=f"k-th kick vs k-th collision (k = 1..{fit.n})",
    )
    grid = np.array([0.0, max(x.max(), y.max())])
    ax.plot(
        grid,
        fit.intercept + fit.slope * grid,
        color="tab:red",
        label=f"least squares: {fit.slope:.3f} t + {fit.intercept:.3g}, R² = {fit.r_squared:.4f}",
    )
    ax.plot(grid, grid, color="grey", linestyle=":", label="identity")
    ax.set_xlabel(f"actual disk-disk collision time $t_k$ ({TIME_UNIT})")
    ax.set_ylabel(f"Poisson kick time ({TIME_UNIT})")
    if radius is not None:
        ax.set_title(f"r = {float(_finite('radius', radius)):g}")
    ax.legend(loc="upper left", fontsize="small")
    return fig


# ------------------------------------------------------------- counts vs radius


def counts_by_radius(collisions) -> pd.DataFrame:
    """Per radius: ``n_ics``, ``mean_count``, ``std_count``, ``sem``, ``mean_t_window``.

    ``collisions`` has one row per (radius, IC) with ``radius``, ``n_pp``, ``t_window``.
    """
    df = _check_frame("collisions", collisions, ["radius", "n_pp", "t_window"])
    _check_radii("collisions['radius']", df["radius"])
    n_pp = _finite("collisions['n_pp']", df["n_pp"])
    if (n_pp < 0).any():
        raise ValueError("collisions['n_pp'] must be non-negative")
    if (_finite("collisions['t_window']", df["t_window"]) <= 0).any():
        raise ValueError("collisions['t_window'] must be positive")
    g = df.groupby("radius")
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


def counts_vs_radius(collisions, regression=None, *, rule="mirror", ax=None):
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
    kinetic = stats.kinetic_rate(grid, kinetic_rule) * t_grid
    fig, ax = _new_axes(ax, (6.0, 4.4))
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
        grid, kinetic, color="grey", linestyle=":", label=f"kinetic theory Γ(r)·T ({kinetic_rule})"
    )
    ax.set_xlabel(RADIUS_LABEL)
    ax.set_ylabel("disk-disk collisions per run (count)")
    ax.set_title("Mean number of disk-disk collisions")
    ax.legend(fontsize="small")
    return fig


# ------------------------------------------------------ diagnostics vs radius


def diagnostic_summary(results, diagnostic=None) -> pd.DataFrame:
    r"""Ensemble summary of a tidy results table, per radius x system x diagnostic.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy rows ``radius, ic, system, diagnostic, value`` (``value`` may be NaN: an
        undefined diagnostic, excluded and counted; ±inf is rejected).
    diagnostic : str or sequence of str, optional
        Keep only these diagnostics.

    Returns
    -------
    pandas.DataFrame
        Columns ``radius, system, diagnostic, n, n_valid, mean, std, sem, paper_err``:
        mean and standard deviation (ddof = 1) of the finite values, standard error
        ``std / sqrt(n_valid)`` and the paper's error bar ``std / 10``.
    """
    df = _check_frame("results", results, ["radius", "system", "diagnostic", "value"])
    if diagnostic is not None:
        wanted = [diagnostic] if isinstance(diagnostic, str) else list(diagnostic)
        present = set(df["diagnostic"].unique())
        missing = [d for d in wanted if d not in present]
        if missing:
            raise ValueError(
                f"diagnostic {missing[0]!r} is not in results; present: {sorted(present)!r}"
            )
        df = df[df["diagnostic"].isin(wanted)]
    _check_radii("results['radius']", df["radius"])
    values = _finite("results['value']", df["value"], allow_nan=True)
    df = df.assign(value=values, valid=np.isfinite(values))
    g = df.groupby(["radius", "system", "diagnostic"], sort=True)
    out = g.agg(
        n=("value", "size"), n_valid=("valid", "sum"), mean=("value", "mean"), std=("value", "std")
    ).reset_index()
    out["n_valid"] = out["n_valid"].astype(np.int64)
    out["sem"] = out["std"] / np.sqrt(out["n_valid"].where(out["n_valid"] > 0))
    out["paper_err"] = out["std"] / 10.0
    return out


def diagnostic_vs_radius(results, diagnostic, *, systems=None, ax=None, title=None):
    r"""A diagnostic against radius for the three systems, with both kinds of error bar.

    Parameters
    ----------
    results : pandas.DataFrame
        Tidy results (see :func:`diagnostic_summary`), or that function's output.
    diagnostic : str
        ``"lyapunov"``, ``"recurrence_rate"``, ``"autocorrelation"``, ...
    systems : sequence of str, optional
        Systems to draw (default: those of ``SYSTEMS`` present in the data).
    ax : matplotlib Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
        Per system, the ensemble mean with the paper's error bar ± std/10 (thick pale
        bar, no caps) and the standard error ± std/√n_valid (thin bar with caps);
        systems are shifted slightly along r so the bars do not hide each other.
    """
    if not isinstance(diagnostic, str):
        raise TypeError(f"diagnostic must be a string, got {type(diagnostic).__name__}")
    if isinstance(results, pd.DataFrame) and {"mean", "sem", "paper_err"} <= set(results.columns):
        summary = results[results["diagnostic"] == diagnostic]
        if len(summary) == 0:
            raise ValueError(f"diagnostic {diagnostic!r} is not in the summary")
    else:
        summary = diagnostic_summary(results, diagnostic)
    present = [s for s in SYSTEMS if s in set(summary["system"])]
    present += sorted(set(summary["system"]) - set(SYSTEMS))
    if systems is None:
        systems = present
    else:
        systems = [systems] if isinstance(systems, str) else list(systems)
        for s in systems:
            if s not in present:
                raise ValueError(f"systems: {s!r} is not in the data; present: {present!r}")
    fig, ax = _new_axes(ax, (6.4, 4.4))
    radii = summary["radius"].to_numpy()
    for k, system in enumerate(systems):
        part = summary[summary["system"] == system].sort_values("radius")
        style = _SYSTEM_STYLE.get(system, {"color": f"C{k + 3}", "marker": "D"})
        x = part["radius"].to_numpy() + _dodge(radii, k, len(systems))
        y = part["mean"].to_numpy()
        ax.errorbar(
            x,
            y,
            yerr=part["paper_err"].to_numpy(),
            linestyle="none",
            color=style["color"],
            **_PAPER_BAR,
        )
        ax.errorbar(
            x,
            y,
            yerr=part["sem"].to_numpy(),
            color=style["color"],
            marker=style["marker"],
            markersize=5,
            linestyle="-",
            label=SYSTEM_LABELS.get(system, system),
            **_SEM_BAR,
        )
    handles, labels = ax.get_legend_handles_labels()
    handles += [
        Line2D([], [], color="grey", **_PAPER_BAR),
        Line2D([], [], color="grey", linewidth=1.0, marker="_", markersize=8),
    ]
    labels += ["± std/10 (paper's bar)", "± std/√n_valid (standard error)"]
    ax.legend(handles, labels, fontsize="small")
    name, ylabel = DIAGNOSTIC_LABELS.get(diagnostic, (diagnostic, diagnostic))
    ax.set_xlabel(RADIUS_LABEL)
    ax.set_ylabel(ylabel)
    ax.set_title(title if title is not None else name)
    return fig


# ------------------------------------------------------------ statistics figures


def binomial_ci(k, n, level=0.95):
    """Clopper-Pearson interval of ``k`` successes in ``n`` trials (NaN where n = 0)."""
    from statsmodels.stats.proportion import proportion_confint

    k = np.asarray(k, dtype=float)
    n = np.asarray(n, dtype=float)
    ok = n > 0
    low = np.full(k.shape, np.nan)
    high = np.full(k.shape, np.nan)
    if ok.any():
        lo, hi = proportion_confint(k[ok], n[ok], alpha=1 - level, method="beta")
        low[ok], high[ok] = lo, hi
    return low, high


def rejection_table(rejections, *, level=0.95) -> pd.DataFrame:
    """Add ``rate`` and Clopper-Pearson ``ci_low``/``ci_high`` to counts of rejections.

    ``rejections`` has columns ``radius, test, n_tested, n_reject``.
    """
    df = _check_frame("rejections", rejections, ["radius", "test", "n_tested", "n_reject"])
    n = _finite("rejections['n_tested']", df["n_tested"])
    k = _finite("rejections['n_reject']", df["n_reject"])
    if ((k < 0) | (k > n)).any():
        raise ValueError("rejections must satisfy 0 <= n_reject <= n_tested")
    out = df.copy()
    with np.errstate(invalid="ignore", divide="ignore"):
        out["rate"] = np.where(n > 0, k / np.where(n > 0, n, 1), np.nan)
    out["ci_low"], out["ci_high"] = binomial_ci(k, n, level)
    return out


def poisson_rejection_rates(rejections, *, alpha=0.05, ax=None):
    """Rejection rate of each Poisson test per radius, with 95% binomial intervals.

    Parameters
    ----------
    rejections : pandas.DataFrame
        ``radius, test, n_tested, n_reject`` (sequences tested and rejected at level
        ``alpha``); ``rate``/``ci_low``/``ci_high`` are computed when absent
        (Clopper-Pearson, :func:`rejection_table`).
    alpha : float
        The level of the tests; drawn as the rate expected if every IC were Poisson.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    alpha = _check_alpha(alpha)
    if isinstance(rejections, pd.DataFrame) and {"rate", "ci_low", "ci_high"} <= set(
        rejections.columns
    ):
        table = _check_frame("rejections", rejections, ["radius", "test", "rate"])
    else:
        table = rejection_table(rejections)
    _check_radii("rejections['radius']", table["radius"])
    fig, ax = _new_axes(ax, (6.4, 4.4))
    tests = list(dict.fromkeys(table["test"]))
    radii = table["radius"].to_numpy()
    for k, test in enumerate(tests):
        part = table[table["test"] == test].sort_values("radius")
        x = part["radius"].to_numpy() + _dodge(radii, k, len(tests))
        rate = part["rate"].to_numpy()
        err = np.vstack([rate - part["ci_low"].to_numpy(), part["ci_high"].to_numpy() - rate])
        ax.errorbar(
            x,
            rate,
            yerr=err,
            marker="o",
            markersize=4,
            capsize=2,
            linewidth=1,
            label=test.replace("_", " "),
            color=f"C{k}",
        )
    ax.axhline(alpha, color="black", linestyle=":", label=f"α = {alpha:g} (all ICs Poisson)")
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel(RADIUS_LABEL)
    ax.set_ylabel(f"share of ICs rejected at α = {alpha:g}")
    ax.set_title("Poisson tests of the disk-disk collision times, per IC")
    ax.legend(fontsize="x-small", ncol=2)
    return fig


def model_comparison(per_ic, pooled, *, models=None):
    r"""Renewal-model comparison per radius: per IC (AIC-best shares) and pooled (ΔAIC).

    Parameters
    ----------
    per_ic : pandas.DataFrame
        One row per (radius, IC) with ``radius`` and ``best_model`` (the AIC-best
        renewal model of that IC's intervals).
    pooled : pandas.DataFrame
        ``radius, model, delta_aic``: ΔAIC = AIC - min AIC of each model on the
        intervals pooled over ICs at that radius.
    models : sequence of str, optional
        Models and their order (default: those present).

    One of the two tables may be empty (e.g. no IC has enough intervals for a fit of
    its own): its panel then says so.

    Returns
    -------
    matplotlib.figure.Figure
        (a) stacked bars of the share of ICs for which each model is AIC-best, with the
        number of ICs on top; (b) pooled ΔAIC per model on a symmetric-log axis, with
        the usual ΔAIC = 2 and 10 guides.
    """
    per_ic = _check_frame("per_ic", per_ic, ["radius", "best_model"], allow_empty=True)
    pooled = _check_frame("pooled", pooled, ["radius", "model", "delta_aic"], allow_empty=True)
    if per_ic.empty and pooled.empty:
        raise ValueError("per_ic and pooled must not both be empty")
    _check_radii("per_ic['radius']", per_ic["radius"])
    _check_radii("pooled['radius']", pooled["radius"])
    delta = _finite("pooled['delta_aic']", pooled["delta_aic"], allow_nan=True)
    if (delta < 0).any():
        raise ValueError("pooled['delta_aic'] must be non-negative (AIC - min AIC)")
    if models is None:
        models = list(dict.fromkeys([*pooled["model"], *per_ic["best_model"]]))
    colour = {m: f"C{k}" for k, m in enumerate(models)}
    fig = Figure(figsize=(11.0, 4.4), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    counts = pd.crosstab(per_ic["radius"], per_ic["best_model"]).reindex(
        columns=models, fill_value=0
    )
    share = counts.div(counts.sum(axis=1), axis=0)
    r = share.index.to_numpy()
    width = 0.8 * (np.min(np.diff(r)) if r.size > 1 else 0.01)
    bottom = np.zeros(r.size)
    for m in models:
        ax1.bar(r, share[m].to_numpy(), width=width, bottom=bottom, color=colour[m], label=m)
        bottom += share[m].to_numpy()
    for x, n in zip(r, counts.sum(axis=1), strict=True):
        ax1.text(x, 1.01, str(int(n)), ha="center", va="bottom", fontsize="x-small")
    for ax, empty in ((ax1, per_ic.empty), (ax2, pooled.empty)):
        if empty:
            ax.text(
                0.5,
                0.5,
                "no sample with enough intervals",
                transform=ax.transAxes,
                ha="center",
                va="center",
            )
    ax1.set_ylim(0, 1.08)
    ax1.set_xlabel(RADIUS_LABEL)
    ax1.set_ylabel("share of ICs where the model is AIC-best")
    ax1.set_title("(a) per IC (number of ICs on top)")
    if not per_ic.empty:
        ax1.legend(fontsize="x-small")
    for m in models:
        part = pooled[pooled["model"] == m].sort_values("radius")
        if len(part):
            ax2.plot(
                part["radius"],
                part["delta_aic"],
                marker="o",
                markersize=4,
                color=colour[m],
                label=m,
            )
    for level in (2.0, 10.0):
        ax2.axhline(level, color="grey", linestyle=":", linewidth=0.8)
    ax2.set_yscale("symlog", linthresh=1.0)
    ax2.set_xlabel(RADIUS_LABEL)
    ax2.set_ylabel("ΔAIC = AIC − min AIC (pooled intervals)")
    ax2.set_title("(b) intervals pooled over ICs")
    if not pooled.empty:
        ax2.legend(fontsize="x-small")
    return fig


def rate_heterogeneity(collisions, *, homogeneity=None, rule="mirror", max_points=4000):
    r"""Collision rates across ICs: per-IC rates and their dispersion, per radius.

    Parameters
    ----------
    collisions : pandas.DataFrame
        One row per (radius, IC): ``radius``, ``n_pp``, ``t_window``.
    homogeneity : pandas.DataFrame, optional
        Indexed or keyed by ``radius`` with a column ``pvalue``: the p-value of the
        test that every IC at that radius has the same rate (e.g. the Pearson
        dispersion test of :func:`kicktimes.stats.test_poisson_ensemble`); printed in
        panel (b).
    rule : {"mirror", "elastic"}
        Rule of the kinetic-theory rate.
    max_points : int
        At most this many per-IC points are drawn per radius (every k-th IC in index
        order; the summaries use all).

    Returns
    -------
    matplotlib.figure.Figure
        (a) per-IC rates ``n_pp / t_window`` (log axis; ICs without collisions at the
        bottom edge as ▽), the pooled rate :math:`\sum N / \sum T`, the median and the
        kinetic rate; (b) the index of dispersion of the counts, variance / mean
        (1 for a common Poisson rate and equal windows), with the p-values.
    """
    from kicktimes import stats

    df = _check_frame("collisions", collisions, ["radius", "n_pp", "t_window"])
    table = counts_by_radius(df)
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 1:
        raise ValueError(f"max_points must be a positive integer, got {max_points!r}")
    rate = df["n_pp"].to_numpy(float) / df["t_window"].to_numpy(float)
    positive = rate[rate > 0]
    floor = 0.5 * positive.min() if positive.size else 1e-6
    fig = Figure(figsize=(11.0, 4.4), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    radii = table.index.to_numpy()
    jitter = 0.25 * (np.min(np.diff(radii)) if radii.size > 1 else 0.004)
    rng = np.random.default_rng(0)  # jitter only: the figure is reproducible
    zero_labelled = False
    for k, r in enumerate(radii):
        sel = np.flatnonzero(df["radius"].to_numpy() == r)
        sel = sel[:: max(1, math.ceil(sel.size / max_points))]
        y = rate[sel]
        x = r + rng.uniform(-jitter, jitter, sel.size)
        lab = "per-IC rate" if k == 0 else None
        ax1.plot(
            x[y > 0],
            y[y > 0],
            linestyle="none",
            marker=".",
            markersize=2,
            alpha=0.4,
            color="tab:blue",
            label=lab,
            rasterized=True,
        )
        if (y == 0).any():
            ax1.plot(
                x[y == 0],
                np.full((y == 0).sum(), floor),
                linestyle="none",
                marker="v",
                markersize=3,
                color="tab:red",
                label=None if zero_labelled else "IC without collisions (at the floor)",
            )
            zero_labelled = True
    grouped = df.groupby("radius")
    pooled = grouped["n_pp"].sum() / grouped["t_window"].sum()
    median = pd.Series(rate, index=df.index).groupby(df["radius"]).median()
    ax1.plot(pooled.index, pooled.to_numpy(), marker="o", color="black", label="pooled ΣN/ΣT")
    ax1.plot(
        median.index,
        median.to_numpy(),
        marker="_",
        markersize=12,
        linestyle="none",
        color="tab:green",
        label="median over ICs",
    )
    grid = np.linspace(radii.min(), radii.max(), 100) if radii.size > 1 else radii
    ax1.plot(
        grid,
        stats.kinetic_rate(grid, rule),
        color="grey",
        linestyle=":",
        label=f"kinetic theory Γ(r) ({rule})",
    )
    ax1.set_yscale("log")
    ax1.set_xlabel(RADIUS_LABEL)
    ax1.set_ylabel("disk-disk collision rate (1 / time unit)")
    ax1.set_title("(a) rates of the individual ICs")
    ax1.legend(fontsize="x-small")
    dispersion = grouped["n_pp"].var(ddof=1) / grouped["n_pp"].mean()
    ax2.plot(
        dispersion.index,
        dispersion.to_numpy(),
        marker="o",
        color="black",
        label="variance / mean of counts",
    )
    ax2.axhline(1.0, color="grey", linestyle=":", label="Poisson, common rate")
    ax2.set_yscale("log")
    if homogeneity is not None:
        hom = homogeneity
        if not isinstance(hom, pd.DataFrame):
            raise TypeError(f"homogeneity must be a DataFrame, got {type(hom).__name__}")
        if "radius" in hom.columns:
            hom = hom.set_index("radius")
        if "pvalue" not in hom.columns:
            raise ValueError("homogeneity must have a column 'pvalue'")
        for r, p in hom["pvalue"].items():
            if r in dispersion.index and np.isfinite(dispersion[r]):
                ax2.annotate(
                    "p<1e-300" if p == 0 else f"p={p:.2g}",
                    (r, dispersion[r]),
                    textcoords="offset points",
                    xytext=(0, 6),
                    ha="center",
                    fontsize="xx-small",
                )
    ax2.set_xlabel(RADIUS_LABEL)
    ax2.set_ylabel("index of dispersion of counts across ICs")
    ax2.set_title("(b) over-dispersion (p: test of a common rate)")
    ax2.legend(fontsize="x-small")
    return fig
