r"""Poisson kick times against the actual disk-disk collision times (the paper's Fig. 3).

The Poisson kick times are the sweep's own: rate ``n_pp / t_window`` of each IC's
two-particle run and the sweep's ``kick_rng(ic, radius, "poisson", rng=seed)`` stream.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from numba import njit

from kicktimes import stats
from kicktimes._results import Result, TupleCompat
from kicktimes.render.figures import TIME_UNIT, check_times, finite, new_axes
from kicktimes.report.context import Section
from kicktimes.report.store import nearest

__all__ = ["TimesFit", "kth_time_fit", "kick_times_vs_collision_times", "rescaled_intervals",
           "time_rescaling_qq", "sections"]

_TIMES_RADIUS = 0.008


@dataclass(frozen=True)
class TimesFit(TupleCompat, Result):
    """Least-squares line ``poisson_k = intercept + slope * actual_k`` over k.

    Unpacking (``slope, intercept, r_squared, n = kth_time_fit(...)``) and indexing still
    work until 0.3.0, with a DeprecationWarning: use the fields.
    """

    _title = "Least-squares line of the k-th Poisson kick time on the k-th collision time"
    _tuple_fields = ("slope", "intercept", "r_squared", "n")

    @property
    def reason(self) -> str | None:
        """Why ``r_squared`` is NaN (None when it is defined)."""
        if math.isfinite(self.r_squared):
            return None
        return "the Poisson kick times do not vary: R² is undefined"

    slope: float
    intercept: float
    r_squared: float
    n: int


def line_text(slope, intercept, var="t"):
    """``slope t ± |intercept|`` with a true minus sign: ``line_text(1.102, -407)`` is
    ``"1.102 t − 407"`` (not ``"1.102 t + -407"``).

    Examples
    --------
    >>> line_text(1.102, -407.0)
    '1.102 t − 407'
    >>> line_text(0.5, 3.25)
    '0.500 t + 3.25'
    """
    sign = "−" if intercept < 0 else "+"
    return f"{slope:.3f} {var} {sign} {abs(intercept):.3g}"


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
    >>> from kicktimes.report.kick_times import kth_time_fit
    >>> round(kth_time_fit([1.0, 2.0, 3.0], [2.0, 4.0, 6.0, 8.0]).slope, 12)
    2.0
    """
    x = check_times("pp_times", pp_times)
    y = check_times("poisson_times", poisson_times)
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
    fig, ax = new_axes(ax, (5.6, 4.8))
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
        label=f"least squares: {line_text(fit.slope, fit.intercept)}, R² = {fit.r_squared:.4f}",
    )
    ax.plot(grid, grid, color="grey", linestyle=":", label="identity")
    # one level of parentheses: the unit (table radius / speed) is explained in captions
    ax.set_xlabel(f"k-th disk-disk collision time $t_k$ ({TIME_UNIT})")
    ax.set_ylabel(f"k-th Poisson kick time ({TIME_UNIT})")
    if radius is not None:
        ax.set_title(f"r = {float(finite('radius', radius)):g}")
    ax.legend(loc="upper left", fontsize="small")
    return fig


def rescaled_intervals(seqs, windows):
    """Inner intervals of every sequence times its own rate ``n / window``, pooled.

    Under a homogeneous Poisson process of any rate these are (given n) spacings of n
    uniform points scaled by n: Exp(1) up to O(1/n). The first interval (from 0) is kept,
    the censored one after the last event is not.
    """
    seqs = [np.asarray(t, dtype=float) for t in seqs]
    windows = np.asarray(windows, dtype=float)
    if len(seqs) != windows.size:
        raise ValueError(f"windows: need one per sequence ({len(seqs)}), got {windows.size}")
    counts = np.array([t.size for t in seqs], dtype=np.int64)
    times = np.concatenate(seqs) if seqs else np.empty(0)  # a copy: the kernel sorts it
    return _pooled_rescaled_intervals(times, counts, windows)


@njit(cache=True, error_model="numpy")
def _pooled_rescaled_intervals(times, counts, windows):
    """The intervals of `rescaled_intervals` of the sequences ``times[s_k : s_k +
    counts[k]]`` (sorted here in place), pooled in sequence order: ``(t_i - t_{i-1}) n_k /
    w_k`` with ``t_0 = 0``, for the sequences of 2 or more events."""
    n_out = 0
    for n in counts:
        if n >= 2:
            n_out += n
    out = np.empty(n_out)
    start, k_out = 0, 0
    for k in range(counts.size):
        n = counts[k]
        if n >= 2:
            seg = times[start : start + n]
            seg.sort()
            rate = n / windows[k]
            prev = 0.0
            for t in seg:
                out[k_out] = (t - prev) * rate
                prev = t
                k_out += 1
        start += n
    return out


def _poisson_null_rescaled(counts, windows, n_rep, rng):
    """``n_rep`` rows of sorted `rescaled_intervals` of Poisson ensembles with the given
    counts and windows (times uniform given n), drawn IC after IC and row after row:
    the numbers of a loop of ``rng.uniform(0.0, w, n)`` per IC, in one call per row."""
    counts = np.asarray(counts, dtype=np.int64)
    windows = np.asarray(windows, dtype=float)
    high = np.repeat(windows, counts)
    rows = [np.sort(_pooled_rescaled_intervals(rng.uniform(0.0, high), counts, windows))
            for _ in range(n_rep)]
    return np.vstack(rows)


def time_rescaling_qq(seqs, windows, *, rng, n_rep=200, ax=None, radius=None):
    r"""Time-rescaling Q-Q plot of collision intervals against Exp(1), with a 95 % band.

    Each IC's intervals are multiplied by its own rate :math:`n_i / T_i` (so the mixture
    of rates across ICs does not count against Poisson) and pooled; their quantiles are
    drawn against those of Exp(1). The band is the pointwise 2.5-97.5 % range of the same
    construction on ``n_rep`` simulated Poisson ensembles with the same counts and windows
    (times uniform given n): an exact null, unlike a fitted line's R², which is close to 1
    for any two processes with similar rates.

    Returns
    -------
    matplotlib.figure.Figure
    """
    obs = np.sort(rescaled_intervals(seqs, windows))
    fig, ax = new_axes(ax, (5.6, 4.8))
    if obs.size < 3:
        ax.text(0.5, 0.5, "fewer than 3 intervals", transform=ax.transAxes, ha="center")
        return fig
    probs = (np.arange(obs.size) + 0.5) / obs.size
    theory = -np.log1p(-probs)
    counts = [np.asarray(t).size for t in seqs]
    null = _poisson_null_rescaled(counts, windows, n_rep, rng)
    low, high = stats.percentile_interval(null, axis=0)
    ax.fill_between(theory, low, high, color="0.8", label="95 % band, Poisson (same n, T)")
    ax.plot(theory, obs, color="tab:blue", linewidth=1.2,
            label=f"disk-disk collisions ({obs.size} intervals)")
    ax.plot([0, theory[-1]], [0, theory[-1]], color="grey", linestyle=":", label="Exp(1)")
    ax.set_xlabel("Exp(1) quantile")
    ax.set_ylabel("rescaled interval (interval × the IC's rate)")
    if radius is not None:
        ax.set_title(f"r = {float(finite('radius', radius)):g}: time-rescaling Q-Q")
    ax.legend(loc="upper left", fontsize="small")
    return fig


def sections(ctx):
    """The kick-times figure and the per-IC least-squares lines at the radius nearest 0.008."""
    from kicktimes.experiment import kick_rng
    from kicktimes.schedules import Poisson

    exp, coll = ctx.exp, ctx.store.collisions
    r = nearest(coll["radius"].unique(), _TIMES_RADIUS)
    part = coll[coll["radius"] == r].sort_values("ic")
    rows, sample = [], None
    for row in part.itertuples():
        pp = np.asarray(row.pp_times, dtype=float)
        rate = row.n_pp / row.t_window
        kicks = (
            Poisson(rate).sample(exp.horizon, rng=kick_rng(int(row.ic), r, "poisson", rng=exp.seed))
            if rate > 0
            else np.empty(0)
        )
        entry = {
            "radius": r,
            "ic": int(row.ic),
            "n_pp": int(row.n_pp),
            "rate": rate,
            "n_kicks": int(kicks.size),
            "slope": math.nan,
            "intercept": math.nan,
            "r_squared": math.nan,
            "n_paired": min(pp.size, kicks.size),
        }
        if entry["n_paired"] >= 3:
            fit = kth_time_fit(pp, kicks)
            entry.update(slope=fit.slope, intercept=fit.intercept, r_squared=fit.r_squared)
            if sample is None:
                sample = (int(row.ic), pp, kicks, fit)
        rows.append(entry)
    table = pd.DataFrame(rows)
    sec = Section("times", "Poisson kick times against actual collision times")
    if sample is None:
        sec.text(f"No IC at r = {r:g} has 3 or more disk-disk collisions and kicks: no figure.")
    else:
        ic, pp, kicks, fit = sample
        fig = Figure(figsize=(11.2, 4.8), layout="constrained")
        ax_paper, ax_qq = fig.subplots(1, 2)
        kick_times_vs_collision_times(pp, kicks, radius=r, ax=ax_paper)
        ax_paper.set_title(f"(a) the paper's view: IC {ic}, r = {r:g}")
        time_rescaling_qq([np.asarray(t, float) for t in part["pp_times"]],
                          part["t_window"].to_numpy(float), rng=ctx.rng(8), ax=ax_qq, radius=r)
        ax_qq.set_title(f"(b) every IC at r = {r:g}: time-rescaling Q-Q")
        sec.figure(
            "fig03_kick_times_vs_collision_times",
            fig,
            f"(a) k-th Poisson kick time against k-th disk-disk collision time, IC {ic}, "
            f"r = {r:g} (the sweep's own Poisson kicks: rate n_pp / t_window, kick_rng "
            "stream), as in the paper; its R² is close to 1 for any two processes with similar "
            "rates. (b) The test it stands for: every IC's collision intervals times the IC's "
            "own rate, pooled, against Exp(1) quantiles, with the 95 % band of Poisson "
            "ensembles with the same counts and windows. Time unit: table radius / speed.",
        )
        ok = table["r_squared"].notna()
        sec.text(
            f"IC {ic}"
            + (" (IC 0 has fewer than 3 collisions)" if ic != 0 else "")
            + f": slope {fit.slope:.3f}, intercept {fit.intercept:.3g}, R² = "
            f"{fit.r_squared:.4f} over {fit.n} pairs. Over the {int(ok.sum())} ICs at r = {r:g} "
            f"with at least 3 pairs: median R² = {table.loc[ok, 'r_squared'].median():.4f} "
            f"(10% quantile {table.loc[ok, 'r_squared'].quantile(0.1):.4f}), median slope "
            f"{table.loc[ok, 'slope'].median():.3f}. A high R² only says that both sequences "
            "grow roughly linearly in k (it holds for any two processes with similar rates); "
            "the Poisson tests below test the collision times themselves."
        )
    sec.table("kick_times_fit", table, "Least-squares line per IC", show=False)
    return [sec]
