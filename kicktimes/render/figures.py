"""Shared figure helpers: system styles, axis labels with units, input checks and the
constrained-layout Figure factory (never pyplot)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, NullFormatter

SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter",
           "poisson_kinetic", "uniform_kinetic", "mmpp")
SYSTEM_LABELS = {
    "two_particle": "Two-particle",
    "poisson": "Poisson",
    "actual": "Actual",
    "poisson_scatter": "Poisson, scatter",
    "actual_scatter": "Actual, scatter",
    "poisson_kinetic": "Kinetic rate, scatter",
    "uniform_kinetic": "Kinetic rate, uniform",
    "mmpp": "MMPP (clustered times)",
}
_SYSTEM_STYLE = {
    "two_particle": {"color": "black", "marker": "o"},
    "poisson": {"color": "tab:orange", "marker": "s"},
    "actual": {"color": "tab:blue", "marker": "^"},
    "poisson_scatter": {"color": "tab:red", "marker": "v"},
    "actual_scatter": {"color": "tab:green", "marker": "D"},
    "poisson_kinetic": {"color": "tab:purple", "marker": "P"},
    "uniform_kinetic": {"color": "tab:olive", "marker": "*"},
    "mmpp": {"color": "tab:brown", "marker": "X"},
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
#: the error bars of the paper's summaries (wide, pale) and of a mean's s.e.m. (thin, capped)
PAPER_BAR = {"linewidth": 5.0, "alpha": 0.3}
SEM_BAR = {"linewidth": 1.0, "capsize": 3.0}


def radius_axis(ax):
    """Label ``ax``'s x axis as the disk radius, with at most 6 plain ticks (0.01, 0.015):
    radii in steps of 0.002 otherwise give ten 5-digit labels that run together."""
    XAxis().draw(ax)


@dataclass(frozen=True)
class Nouns:
    """The words a figure uses for what it shows: its event times, one event, one
    sequence of them, and several sequences.

    A figure drawn against the disk radius shows kicktimes' own runs (``SWEEP_NOUNS``:
    disk-disk collision times, ICs); drawn against any other column it shows event times
    from elsewhere (``EVENT_NOUNS``: events, sequences), the page of ``kicktimes
    analyze``, which must not speak of disks.
    """

    events: str
    event: str
    one: str
    many: str


SWEEP_NOUNS = Nouns("disk-disk collision times", "disk-disk collision", "IC", "ICs")
EVENT_NOUNS = Nouns("event times", "event", "sequence", "sequences")


@dataclass(frozen=True)
class XAxis:
    """What a figure draws along x: a column of its tables and the axis label.

    The report's figures draw against the disk radius (the default); ``kicktimes analyze``
    draws the same figures against the sequences' group. A numeric column is drawn at its
    values (a column other than the radius with at most `MAX_VALUE_TICKS` distinct values
    gets a tick at each value and none between); a column of labels (text groups, the
    analysis' single group ``"all"``) at 0, 1, ... in order of first appearance, with the
    labels as ticks (``labels``, set by :meth:`positions`): categories, so figures draw
    their points without joining lines (:attr:`line`). The figure's words follow the
    column (:attr:`nouns`).

    Examples
    --------
    >>> import pandas as pd
    >>> axis = XAxis("density", "particles per unit area")
    >>> axis.positions(t=pd.DataFrame({"density": [0.2, 0.1]}))[0]["density"].tolist()
    [0.2, 0.1]
    >>> t, axis = XAxis("group", "group").positions(t=pd.DataFrame({"group": ["all"]}))
    >>> t["group"].tolist(), axis.labels, axis.line
    ([0.0], ('all',), 'none')
    >>> XAxis().nouns.many, XAxis("group").nouns.many
    ('ICs', 'sequences')
    """

    column: str = "radius"
    label: str = RADIUS_LABEL
    labels: tuple | None = None
    values: tuple | None = None

    #: a numeric column other than the radius with this many distinct values or fewer
    #: is ticked at its values
    MAX_VALUE_TICKS = 8

    @property
    def nouns(self) -> Nouns:
        """The figure's words: kicktimes' runs along the radius, events elsewhere."""
        return SWEEP_NOUNS if self.column == "radius" else EVENT_NOUNS

    @property
    def line(self) -> str:
        """The linestyle joining points along x: none between categories."""
        return "none" if self.labels is not None else "-"

    def positions(self, **frames):
        """Check the column in every frame, given by name (radii: 0 < r < 0.5; other
        numbers: finite), and return ``(*frames, axis)``: the frames with the column as
        float positions, in the order given; a column of labels becomes 0, 1, ... (shared
        by the frames) and the returned axis carries the labels."""
        for name, frame in frames.items():
            check_frame(name, frame, [self.column], allow_empty=True)
        values = {name: frame[self.column] for name, frame in frames.items()}
        if all(
            v.empty or (pd.api.types.is_numeric_dtype(v) and not pd.api.types.is_bool_dtype(v))
            for v in values.values()
        ):
            check = check_radii if self.column == "radius" else finite
            for name, v in values.items():
                check(f"{name}[{self.column!r}]", v)
            distinct = np.unique(
                np.concatenate([np.asarray(v, float) for v in values.values()] or [[]])
            )
            if self.column != "radius" and 0 < distinct.size <= self.MAX_VALUE_TICKS:
                return (*frames.values(), replace(self, values=tuple(distinct.tolist())))
            return (*frames.values(), self)
        labels = tuple(dict.fromkeys(str(v) for column in values.values() for v in column))
        where = {label: float(k) for k, label in enumerate(labels)}
        mapped = [
            frame.assign(**{self.column: [where[str(v)] for v in frame[self.column]]})
            for frame in frames.values()
        ]
        return (*mapped, replace(self, labels=labels))

    @staticmethod
    def step(values, single):
        """The smallest gap between the distinct ``values`` (``single`` for one value)."""
        u = np.unique(np.asarray(values, float))
        return float(np.min(np.diff(u))) if u.size > 1 else single

    def draw(self, ax):
        """Label the x axis; at most 6 plain ticks for numbers (a tick at each value of a
        column with few values), the labels for text, with a margin of half a step."""
        from matplotlib.ticker import FixedFormatter, FixedLocator, MaxNLocator

        ax.set_xlabel(self.label)
        if self.labels is not None:
            ax.xaxis.set_major_locator(FixedLocator(np.arange(len(self.labels), dtype=float)))
            ax.xaxis.set_major_formatter(FixedFormatter(list(self.labels)))
            ax.set_xlim(-0.5, len(self.labels) - 0.5)
            return
        if self.values is not None:
            ax.xaxis.set_major_locator(FixedLocator(np.asarray(self.values, float)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            return
        ax.xaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))
        # radii: 3 significant digits (0.0125); any other value as a plain number
        digits = ".3g" if self.column == "radius" else "g"
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:{digits}}"))


def x_axis(x="radius", xlabel=None):
    """The :class:`XAxis` of a figure's ``x`` and ``xlabel`` arguments (``xlabel`` None:
    the radius label for ``"radius"``, the column's name otherwise)."""
    if not isinstance(x, str) or not x:
        raise TypeError(f"x must be a column name, got {x!r}")
    if xlabel is None:
        xlabel = RADIUS_LABEL if x == "radius" else x
    if not isinstance(xlabel, str):
        raise TypeError(f"xlabel must be a string, got {type(xlabel).__name__}")
    return XAxis(x, xlabel)


#: the systems whose kicks scatter (the rule of a disk-disk collision) rather than redraw
#: the direction by the kick-angle rule; figures with many systems draw them apart
SCATTER_SYSTEMS = ("poisson_scatter", "actual_scatter", "poisson_kinetic")


def kick_groups(systems, reference="two_particle"):
    """``[(name, systems)]``: ``reference`` with the systems whose kicks follow the
    kick-angle rule (``"uniform kicks"``), then with those whose kicks scatter
    (``"scatter kicks"``, `SCATTER_SYSTEMS`), each in the order of ``systems``; a group
    without a kicked system is left out, and ``[("", systems)]`` if both are.

    Examples
    --------
    >>> for name, members in kick_groups(["two_particle", "poisson", "poisson_scatter"]):
    ...     print(name, members)
    uniform kicks ['two_particle', 'poisson']
    scatter kicks ['two_particle', 'poisson_scatter']
    """
    systems = list(systems)
    ref = [s for s in systems if s == reference]
    uniform = [s for s in systems if s != reference and s not in SCATTER_SYSTEMS]
    scatter = [s for s in systems if s in SCATTER_SYSTEMS]
    groups = [("uniform kicks", ref + uniform), ("scatter kicks", ref + scatter)]
    return [(name, members) for name, members in groups if len(members) > len(ref)] or [
        ("", systems)
    ]


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


def survival_steps(ax, km, *, color, label=None, line=None, start=None, end=None, clip=None,
                   gid=None):
    """Draw a Kaplan-Meier table (`kicktimes.stats.escape_survival`) on ``ax``: the survival
    as steps with its 95 % band while at least `kicktimes.stats.MIN_AT_RISK` runs are at
    risk (`kicktimes.stats.reliable_until`), holding its value up to that time; from there
    a thin grey dotted line without a band (``gid`` names it).

    ``line``: the measured steps' line properties; ``start``: begin at S = 1 there;
    ``end``: hold the last value up to it (the last observed time); ``clip``: draw values
    below it at it (a log axis' floor).
    """
    from kicktimes.stats import reliable_until

    cols = ["time", "survival", "ci_low", "ci_high"] + (
        ["n_at_risk"] if "n_at_risk" in km.columns else [])
    km = km[cols]
    if start is not None:
        first = pd.DataFrame({"time": [start], "survival": [1.0], "ci_low": [1.0],
                              "ci_high": [1.0]})
        if "n_at_risk" in cols:
            first["n_at_risk"] = np.inf
        km = pd.concat([first, km], ignore_index=True)
    if end is not None:
        km = pd.concat([km, km.iloc[[-1]].assign(time=end)], ignore_index=True)
    cut = reliable_until(km) if "n_at_risk" in cols else np.inf
    kept = km[km["time"] < cut]
    rest = km[km["time"] >= cut]
    if len(kept) and len(rest):
        kept = pd.concat([kept, kept.iloc[[-1]].assign(time=cut)])
        rest = pd.concat([kept.iloc[[-1]], rest])

    def shown(values):
        return values if clip is None else np.maximum(values, clip)

    ax.step(kept["time"], shown(kept["survival"]), where="post", color=color, label=label,
            **(line or {}))
    ax.fill_between(kept["time"], shown(kept["ci_low"]), shown(kept["ci_high"]), step="post",
                    color=color, alpha=0.12, linewidth=0, zorder=1)
    if len(rest):
        ax.step(rest["time"], shown(rest["survival"]), where="post", color="0.6",
                linewidth=0.8, linestyle=":", zorder=1, gid=gid)
