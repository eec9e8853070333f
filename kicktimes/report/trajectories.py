r"""Trajectory figures from the experiment's own IC 0: Poincaré sections and the
recurrence plot (the paper's Figs. 1-2), with the numbers behind them.

The trajectories are recomputed from IC 0 (``initial_conditions`` with the experiment's
seed and IC method at its largest radius) at the experiment's radii nearest to 0.02 and
0.014, with its rule, sampling, ``n_steps`` and ``tau``.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from kicktimes.billiard import KickLaw
from kicktimes.render.figures import TIME_UNIT, check_frame, finite, new_axes
from kicktimes.render.pages import percent_text
from kicktimes.report.context import Section
from kicktimes.report.store import REFERENCE, eps_values, nearest
from kicktimes.validation import keyword_only_after

__all__ = ["poincare_section", "poincare_panels", "recurrence_plot", "line_pairs", "sections"]

_POINCARE_RADII = (0.02, 0.014)


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
    check_frame("boundary data", df, ["s", "sin_theta"])
    if "particle" in df.columns:
        df = df[df["particle"] == particle]
        if len(df) == 0:
            raise ValueError(f"particle {particle} has no boundary collisions in the data")
    s = finite("s", df["s"].to_numpy())
    st = finite("sin_theta", df["sin_theta"].to_numpy())
    if ((s < 0) | (s > 2 * math.pi)).any() or (np.abs(st) > 1 + 1e-12).any():
        raise ValueError("boundary data must have s in [0, 2 pi] and sin_theta in [-1, 1]")
    return s, st, radius


@keyword_only_after(1, since="0.2.0", names=('particle',))
def poincare_section(data, *, particle=0, ax=None, title=None, markersize=0.6,
                     color="C0"):
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
    >>> from kicktimes import simulate_two_particle, initial_conditions
    >>> from kicktimes.report.trajectories import poincare_section
    >>> run = simulate_two_particle(initial_conditions(1, 0.02, rng=1)[0], 0.02, t_max=500.0)
    >>> fig = poincare_section(run)
    >>> fig.axes[0].get_ylabel()
    '$\\sin\\theta$ (dimensionless)'
    """
    s, st, radius = _boundary_frame(data, particle)
    fig, ax = new_axes(ax, (6.0, 3.6))
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
        poincare_section(run, particle=particle, ax=ax, title=title, markersize=markersize)
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
    i, j = recurrence_pairs(points, eps=eps)
    return i, j, int(np.asarray(points).shape[0])


def recurrence_plot(
    data, *, eps=1e-3, n_points=None, tau=None, ax=None, max_markers=300_000, bins=600,
    title=None, zoom=None,
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
    zoom : int, optional
        Also draw, enlarged in an inset, a ``zoom`` x ``zoom`` window of sample indices
        centred on the densest cluster of diagonal lines of length ≥ 2 (pairs
        ``(i, j)`` and ``(i + 1, j + 1)`` both recurrent, ``i ≠ j``: what DET counts), away
        from the main diagonal where there are any (at full scale the main diagonal and
        the dots hide them); the pairs on such lines are red, the others black.

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
        tau = float(finite("tau", tau))
        if tau <= 0:
            raise ValueError(f"tau must be positive, got {tau!r}")
    i, j, n = _as_pairs(data, eps, n_points)
    fig, ax = new_axes(ax, (5.0, 4.6))
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
    if zoom and n > 2 * zoom:
        _line_inset(ax, i, j, n, zoom, scale)
    ax.set_xlabel(f"{unit} $i$")
    ax.set_ylabel(f"{unit} $j$")
    rate = i.size / float(n) ** 2
    ax.set_title(title if title is not None else f"N = {n}, {i.size} pairs, RR = {rate:.3g}")
    return fig


def line_pairs(i, j, n):
    """Which pairs lie on a diagonal line of length ≥ 2 off the main diagonal.

    Parameters
    ----------
    i, j : numpy.ndarray of int
        Recurrent index pairs.
    n : int
        Number of samples.

    Returns
    -------
    numpy.ndarray of bool
        True where ``i ≠ j`` and ``(i - 1, j - 1)`` or ``(i + 1, j + 1)`` is also a pair
        (the diagonal structures DET counts with ``l_min = 2``).
    """
    i = np.asarray(i, dtype=np.int64)
    j = np.asarray(j, dtype=np.int64)
    if i.size == 0:
        return np.zeros(0, dtype=bool)
    key = i * n + j
    order = np.sort(key)

    def has(k):
        at = np.searchsorted(order, k).clip(0, order.size - 1)
        return order[at] == k

    nxt = (i + 1 < n) & (j + 1 < n) & has(key + n + 1)
    prv = (i > 0) & (j > 0) & has(key - n - 1)
    return (i != j) & (nxt | prv)


def _line_inset(ax, i, j, n, zoom, scale):
    """The inset of :func:`recurrence_plot`: a ``zoom`` window on diagonal lines."""
    lines = line_pairs(i, j, n)
    on = lines & (i < j)  # one triangle
    if not on.any():
        ax.text(0.98, 0.02, "no diagonal line of length ≥ 2 off the main diagonal",
                transform=ax.transAxes, ha="right", va="bottom", fontsize="x-small")
        return
    far = on & (j - i >= zoom)  # away from the main diagonal, where there are any
    pick = far if far.any() else on
    bi, bj = i[pick] // zoom, j[pick] // zoom
    cells = bi * (n // zoom + 1) + bj
    best = np.bincount(cells).argmax()
    inside = cells == best
    ci, cj = (int(np.median(a[pick][inside])) for a in (i, j))
    i0 = int(np.clip(ci - zoom // 2, 0, n - zoom))
    j0 = int(np.clip(cj - zoom // 2, 0, n - zoom))
    inset = ax.inset_axes([0.56, 0.04, 0.42, 0.42])
    sel = (i >= i0) & (i < i0 + zoom) & (j >= j0) & (j < j0 + zoom)
    size = max(1.5, 120.0 / zoom)
    for mask, colour in ((sel & ~lines, "black"), (sel & lines, "tab:red")):
        inset.plot(i[mask] * scale, j[mask] * scale, linestyle="none", marker="s",
                   markersize=size, markeredgewidth=0, color=colour, rasterized=True)
    inset.set_xlim(i0 * scale, (i0 + zoom) * scale)
    inset.set_ylim(j0 * scale, (j0 + zoom) * scale)
    inset.set_aspect("equal")
    # at most three ticks per side, none at the corners: the full sample indices (five
    # digits) collide at the default ticks and where the two axes meet
    for axis in (inset.xaxis, inset.yaxis):
        axis.set_major_locator(MaxNLocator(nbins=2, integer=True, prune="both"))
    inset.tick_params(labelsize="xx-small", pad=1.5)
    n_line = int((sel & lines).sum())
    # inside the inset, on white: above it the text would cross the main plot's dots
    inset.text(0.03, 0.97, f"{zoom} x {zoom} samples:\n{n_line} of {int(sel.sum())} pairs on "
               "lines\nof length ≥ 2 (red)", transform=inset.transAxes, fontsize="xx-small",
               va="top", bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                               "alpha": 0.85})
    ax.indicate_inset_zoom(inset, edgecolor="tab:red")


def _sweep_poisson_run(exp, ic, r, two):
    """The sweep's Poisson-kicked run of IC 0 at ``r``: its kick times and angles from the
    ``kick_rng(0, r, "poisson", rng=seed)`` stream, as the sweep draws them."""
    from kicktimes.billiard.one_particle import draw_kick_angles, simulate_one_particle
    from kicktimes.experiment import kick_rng
    from kicktimes.schedules import Poisson

    rng = kick_rng(0, r, "poisson", rng=exp.seed)
    rate = two.n_pp / two.t_max if two.t_max > 0 else 0.0
    times = Poisson(rate).sample(exp.horizon, rng=rng) if rate > 0 else np.empty(0)
    angles = draw_kick_angles(times.size, exp.kick_angle, exp.sigma, rng)
    law = KickLaw(times, angle=exp.kick_angle, angles=angles, sigma=exp.sigma)
    return simulate_one_particle(ic[0], r, kicks=law, n_steps=exp.n_steps, tau=exp.tau,
                                 sampling=exp.sampling)


def sections(ctx):
    """Poincaré sections and the recurrence plot from the experiment's own IC 0."""
    from kicktimes.billiard.initial import initial_conditions
    from kicktimes.billiard.two_particle import simulate_two_particle
    from kicktimes.diagnostics import recurrence_pairs

    store, exp = ctx.store, ctx.exp
    secs = []
    ic = initial_conditions(1, exp.r_max, rng=exp.seed, method=exp.ic_method, rule=exp.rule)[0]
    radii = list(dict.fromkeys(nearest(exp.radii, r) for r in _POINCARE_RADII))
    runs = {
        r: simulate_two_particle(
            ic,
            r,
            rule=exp.rule,
            sampling=exp.sampling,
            n_steps=exp.n_steps,
            tau=exp.tau,
            track=0,
            )
        for r in radii
    }
    sec = Section("poincare", "Poincaré sections of one disk")
    rows = []
    for r, run in runs.items():
        b = run.boundary
        st = b.loc[b["particle"] == 0, "sin_theta"].to_numpy()
        kept = float(np.mean(np.abs(np.diff(st)) < 1e-9)) if st.size > 1 else math.nan
        rows.append(
            {
                "radius": r,
                "ic": 0,
                "t_max": run.t_max,
                "n_pp": run.n_pp,
                "n_boundary_disk0": int(st.size),
                "share_sin_theta_kept": kept,
                "n_distinct_sin_theta": int(np.unique(np.round(st, 9)).size),
            }
        )
    table = pd.DataFrame(rows)
    kicked = {r: _sweep_poisson_run(exp, ic, r, run) for r, run in runs.items()}
    fig = Figure(figsize=(11.0, 3.2 * len(radii)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(radii), 2, sharex=True, sharey=True, squeeze=False))
    for k, r in enumerate(radii):
        poincare_section(runs[r], particle=0, ax=axes[k, 0],
                         title=f"({chr(ord('a') + 2 * k)}) two disks, disk 0, r = {r:g}")
        poincare_section(kicked[r], particle=0, ax=axes[k, 1], color="tab:orange",
                         title=f"({chr(ord('b') + 2 * k)}) one disk, Poisson kicks, r = {r:g}")
        if k < len(radii) - 1:
            for ax in axes[k]:
                ax.set_xlabel("")
        axes[k, 1].set_ylabel("")
    sec.figure(
        "fig01_poincare_sections",
        fig,
        f"Poincaré sections (s, sin θ) of disk 0 of IC 0 (drawn at r_max = {exp.r_max:g} with "
        f"seed {exp.seed}, {exp.ic_method} method), at r = "
        + " and ".join(f"{r:g}" for r in radii)
        + f"; {exp.n_steps} {exp.sampling}-sampled steps of τ = {exp.tau:g}. Left: the two-disk "
        "billiard; right: the same disk kicked at the sweep's own Poisson times and angles "
        "(rate n_pp / t_window of the left run). Horizontal segments are regular motion "
        "between perturbations.",
    )
    parts = [
        f"r = {row.radius:g}: {row.n_boundary_disk0} boundary collisions of disk 0 and "
        f"{row.n_pp} disk-disk collisions in t = {row.t_max:.4g}; "
        f"{percent_text(row.share_sin_theta_kept)} of consecutive boundary collisions keep sin θ "
        f"(the horizontal segments of regular motion), {row.n_distinct_sin_theta} distinct "
        f"values of sin θ"
        for row in table.itertuples()
    ]
    sec.text("; ".join(parts) + ".")
    if len(radii) < len(_POINCARE_RADII):
        sec.text(
            "The experiment has no separate radius near each of the paper's 0.02 and 0.014, "
            f"so only r = {radii[0]:g} is shown."
        )
    sec.table("poincare_runs", table, "Runs behind the Poincaré sections")
    secs.append(sec)

    r_rr = nearest(exp.radii, 0.02)
    run = runs[r_rr]
    eps = eps_values(exp)[0]
    i, j = recurrence_pairs(run.samples, eps=eps)
    n = run.samples.shape[0]
    rr = i.size / float(n) ** 2
    stored = store.results[
        (store.results["radius"] == r_rr)
        & (store.results["ic"] == 0)
        & (store.results["system"] == REFERENCE)
        & (store.results["diagnostic"] == "recurrence_rate")
    ]["value"]
    sec2 = Section("recurrence_plot", "Recurrence plot")
    sec2.figure(
        "fig02_recurrence_plot",
        recurrence_plot(
            (i, j),
            n_points=n,
            tau=exp.tau if exp.sampling == "uniform" else None,
            title=(f"two-disk billiard, disk 0 of IC 0 ({exp.sampling} sampling)\n"
                   f"r = {r_rr:g}, ε = {eps:g}: N = {n}, RR = {rr:.4g}"),
            zoom=min(40, n // 4),
        ),
        f"Recurrence plot of disk 0's sampled centre in the two-disk billiard, IC 0, "
        f"r = {r_rr:g}, ε = {eps:g} (L2 norm), drawn from the list of recurrent pairs (no "
        "N x N matrix); inset: the window of samples with the most pairs on diagonal lines "
        "of length ≥ 2 off the main diagonal (red; what DET counts), away from the main "
        "diagonal where there are such lines, enlarged.",
    )
    off = (i.size - n) / (n * (n - 1.0))
    text = (
        f"N = {n} samples give {i.size} recurrent pairs, {n} of them the main diagonal "
        f"(i = j, always recurrent) and {i.size - n} off it: the paper's RR = {rr:.4g} "
        f"= {rr * n:.4g}/N, of which 1/N is the diagonal; the off-diagonal rate "
        f"(pairs i ≠ j over N(N − 1)) is {off:.3g}."
    )
    if len(stored) == 1:
        same = np.isclose(float(stored.iloc[0]), rr, rtol=1e-12, atol=0)
        text += (
            f" The store's recurrence rate of this IC and radius is {float(stored.iloc[0]):.4g}"
            + (
                " (identical: the plot is the stored trajectory)."
                if same
                else " (differs: the store was computed with other settings)."
            )
        )
    if getattr(exp, "rr_sampling", "run") != "run":
        text += (
            f" (The store's recurrence rates use rr_sampling = {exp.rr_sampling!r}; the plot "
            "shows the run's own samples.)"
        )
    sec2.text(text)
    secs.append(sec2)
    return secs
