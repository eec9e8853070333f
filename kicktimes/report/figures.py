"""Shared figure helpers: system styles, axis labels with units, input checks and the
constrained-layout Figure factory (never pyplot)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, NullFormatter

SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter")
SYSTEM_LABELS = {
    "two_particle": "Two-particle",
    "poisson": "Poisson",
    "actual": "Actual",
    "poisson_scatter": "Poisson, scatter",
    "actual_scatter": "Actual, scatter",
}
_SYSTEM_STYLE = {
    "two_particle": {"color": "black", "marker": "o"},
    "poisson": {"color": "tab:orange", "marker": "s"},
    "actual": {"color": "tab:blue", "marker": "^"},
    "poisson_scatter": {"color": "tab:red", "marker": "v"},
    "actual_scatter": {"color": "tab:green", "marker": "D"},
}
# (title, y-axis label with units) of each diagnostic of the store
DIAGNOSTIC_LABELS = {
    "lyapunov": ("Finite-time Lyapunov exponent", r"$\lambda$ (1 / time unit)"),
    "lyapunov_x": ("Finite-time Lyapunov exponent (x)", r"$\lambda^x$ (1 / time unit)"),
    "lyapunov_y": ("Finite-time Lyapunov exponent (y)", r"$\lambda^y$ (1 / time unit)"),
    "lyapunov_per_perturbation": (
        "Stretching per perturbation",
        r"$\lambda T / n$ (nats per perturbation)",
    ),
    "recurrence_rate": ("Recurrence rate", r"RR($\varepsilon$) (fraction of sample pairs)"),
    "autocorrelation": ("Autocorrelation of boundary angles", r"$R_l$ of $\theta$ (dimensionless)"),
    "n_kicks": ("Number of kicks", "kicks per run (count)"),
    "n_boundary": ("Number of boundary collisions", "boundary collisions per run (count)"),
}
RADIUS_LABEL = "disk radius $r$ (table radii)"
#: the time unit is the table radius over the (unit) speed; captions say so once
TIME_UNIT = "time units"
_PAPER_BAR = {"linewidth": 5.0, "alpha": 0.3}
_SEM_BAR = {"linewidth": 1.0, "capsize": 3.0}


def radius_axis(ax):
    """Label ``ax``'s x axis as the disk radius, with at most 6 plain ticks (0.01, 0.015):
    radii in steps of 0.002 otherwise give ten 5-digit labels that run together."""
    from matplotlib.ticker import MaxNLocator

    ax.set_xlabel(RADIUS_LABEL)
    ax.xaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))


def system_label(system):
    return SYSTEM_LABELS.get(system, system.replace("_", " "))


def system_style(system, k=0):
    return _SYSTEM_STYLE.get(system, {"color": f"C{k + 3}", "marker": "D"})


def plain_ticks(axis):
    """Tick labels as plain numbers with 3 significant figures (no offset text, which
    would collide with the title)."""
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))


def shared_legend(fig, axes, *, ncol=4):
    """Move the legend of ``axes[0]`` below the panels (outside: it never covers data) and
    drop every panel's own legend."""
    handles, labels = axes[0].get_legend_handles_labels()
    legend = axes[0].get_legend()
    if legend is not None:
        # artists keep their markers; the legend's extra proxy entries come after them
        texts = [t.get_text() for t in legend.get_texts()]
        extra = [
            (h, t) for h, t in zip(legend.legend_handles, texts, strict=True) if t not in labels
        ]
        handles = handles + [h for h, _ in extra]
        labels = labels + [t for _, t in extra]
    for ax in axes:
        if ax.get_legend() is not None:
            ax.get_legend().remove()
    fig.legend(
        handles, labels, loc="outside lower center", ncol=min(ncol, len(labels)), fontsize="small"
    )


def plain_log_ticks(axis):
    """Log-axis tick labels as plain numbers (0.5, 2, 20), never "2x10^0"; no minor labels
    when the axis spans more than a decade (they would overlap)."""
    formatter = FuncFormatter(lambda v, _: f"{v:g}")
    axis.set_major_formatter(formatter)
    lo, hi = axis.get_view_interval()
    if lo > 0 and hi / lo > 10:
        axis.set_minor_formatter(NullFormatter())
    else:
        axis.set_minor_formatter(formatter)


# ----------------------------------------------------------------------------- checks


def check_frame(name, df, columns, *, allow_empty=False):
    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"{name} must be a pandas DataFrame, got {type(df).__name__}")
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"{name} must have columns {list(columns)!r}; missing {missing!r}")
    if len(df) == 0 and not allow_empty:
        raise ValueError(f"{name} must not be empty")
    return df


def finite(name, values, *, allow_nan=False):
    arr = np.asarray(values, dtype=float)
    bad = np.isinf(arr) if allow_nan else ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad.ravel())[0])
        what = "infinite values" if allow_nan else "NaN or infinite values"
        raise ValueError(
            f"{name} must not contain {what}, got {float(arr.ravel()[i])} at position {i}"
        )
    return arr


def check_radii(name, values):
    r = finite(name, values)
    if ((r <= 0) | (r >= 0.5)).any():
        bad = r[(r <= 0) | (r >= 0.5)][0]
        raise ValueError(f"{name} must satisfy 0 < r < 0.5 (two disks), got {float(bad)}")
    return r


def check_times(name, values):
    t = finite(name, values)
    if t.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {t.shape}")
    if (t < 0).any():
        raise ValueError(f"{name} must be non-negative, got {float(t[t < 0][0])}")
    if (np.diff(t) < 0).any():
        k = int(np.flatnonzero(np.diff(t) < 0)[0])
        raise ValueError(
            f"{name} must be sorted increasingly, got {float(t[k])} before {float(t[k + 1])}"
        )
    return t


def check_alpha(alpha):
    if isinstance(alpha, bool) or not isinstance(alpha, int | float | np.floating):
        raise TypeError(f"alpha must be a number, got {type(alpha).__name__}")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must satisfy 0 < alpha < 1, got {alpha!r}")
    return float(alpha)


def new_axes(ax, figsize):
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


def dodge(radii, k, n):
    """x offsets that keep the error bars of ``n`` series at the same radius apart."""
    u = np.unique(radii)
    step = np.min(np.diff(u)) if u.size > 1 else 0.01 * max(u[0], 1e-3)
    return (k - (n - 1) / 2) * 0.12 * step
