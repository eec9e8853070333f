"""The figures of docs/results/disks.md: functions of its tables returning a `Figure`.

`rejection_figure` (the Poisson battery's rejection shares against N), `hazard_figure` (the
hazard of the next collision against the time since the last, per N) and `rates_figure`
(collision frequency over Enskog's, index of dispersion and the hazard's first bin
against N), from `kicktimes.studies.disks.tables.disks_table` and `disks_hazard`; `controls_figure`
(the findings under their controls against N, from
`kicktimes.studies.disks.controls.controls_findings`).
"""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter

from kicktimes.render.figures import plain_log_ticks
from kicktimes.studies.disks.tables import RATE_MARGIN
from kicktimes.studies.disks.versus_null import HAZARD_MARGIN, KS_MARGIN

__all__ = ["controls_figure", "geometries_of", "hazard_figure", "rates_figure",
           "rejection_figure"]

ALPHA = 0.05
HEADLINE = "uniformity_ks"
#: the tests' names on the page
TEST_NAMES = {"uniformity_ks": "uniform times (KS)", "exponential_ad": "exponential intervals (AD)"}
SHOWN_N = (2, 3, 10, 100, 1000)
#: where the hazard figure's log time axis starts (its first bin is [0, 0.01))
X_MIN = 0.003
#: the hazard figure's zoomed rows show these N and more
ZOOM_MIN_N = 10
#: the y limits of the hazard figure's zoomed rows (linear) and full rows (log); a bin or
#: a band beyond them is marked at the edge (`_mark_outside`), never left out silently
ZOOM_LIMITS = (0.75, 1.3)
FULL_LIMITS = (0.05, 20.0)



def _unique_handles(axes):
    """``(handles, labels)`` of every panel's legend entries, each label once, in order."""
    handles, labels = [], []
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    return handles, labels

def geometries_of(table):
    """The table's geometries (``packing 0.02``, ``r = 0.0045``), in order of appearance."""
    return list(dict.fromkeys(table["geometry"]))


def _n_ticks(ax, ns):
    ax.set_xscale("log")
    ax.set_xticks(list(ns))
    ax.set_xticks([], minor=True)
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def rejection_figure(table, tests=(HEADLINE, "exponential_ad"), nulls=None):
    """The share of tagged disks whose first K collision times reject each test at
    alpha = 0.05, against N: one column per geometry, one row per test, log y axis (the
    5 % band stays readable next to the N = 2 shares); mirror and elastic, dodged and with
    different markers; 95 % CIs; alpha +- the KS
    share's margin (`KS_MARGIN`) shaded; with ``nulls``
    (`kicktimes.studies.disks.null.null_rows`), the share of the Poisson null streams
    shaped like each rule's runs (the calibrated level), dotted, and under the elastic rule
    the linear Boltzmann tagged disk's share (the ``"dilute"`` design), dashed."""
    import matplotlib.pyplot as plt

    geos = geometries_of(table)
    ns = sorted(set(table["n_disks"]))
    fig, axes = plt.subplots(len(tests), len(geos), figsize=(4.4 * len(geos), 3.6 * len(tests)),
                             sharex=True, sharey=True, squeeze=False)
    # the speed-rescaled shares are not drawn: the page reads no verdict of them
    styles = (("mirror", "", "mirror", "C0", "o", "C0"),
              ("elastic", "", "elastic", "C3", "s", "C3"))
    for i, test in enumerate(tests):
        for j, geo in enumerate(geos):
            ax = axes[i, j]
            # the KS share's margin around alpha (the share is read against its null's)
            ax.axhspan(100 * (ALPHA - KS_MARGIN), 100 * (ALPHA + KS_MARGIN), color="0.88",
                       zorder=0)
            ax.axhline(100 * ALPHA, color="0.5", lw=0.8, zorder=0)
            for k, (rule, prefix, label, color, marker, face) in enumerate(styles):
                d = table[(table["geometry"] == geo) & (table["rule"] == rule)]
                key = f"{prefix}reject_{test}"
                if d.empty or key not in d:
                    continue
                x = d["n_disks"].to_numpy() * (1.0 + 0.12 * (k - 0.5))
                y = 100 * d[key].to_numpy()
                err = np.abs(100 * d[[f"{key}_low", f"{key}_high"]].to_numpy().T - y)
                ax.errorbar(x, y, yerr=err, color=color, marker=marker, ms=4.5, lw=1,
                            capsize=2, label=label, mfc=face)
                if nulls is not None and not prefix:
                    z = nulls[(nulls["geometry"] == geo) & (nulls["rule"] == rule)
                              & (nulls["design"] == "poisson")]
                    if not z.empty and key in z:
                        ax.plot(z["n_disks"].to_numpy() * (1.0 + 0.12 * (k - 0.5)),
                                100 * z[key].to_numpy(), color=color, ls=":", marker="x",
                                ms=4, lw=1, label=f"Poisson null, {rule} runs")
                    b = nulls[(nulls["geometry"] == geo) & (nulls["rule"] == rule)
                              & (nulls["design"] == "dilute")]
                    if rule == "elastic" and not b.empty and key in b:
                        ax.plot(b["n_disks"].to_numpy() * (1.0 + 0.12 * (k - 0.5)),
                                100 * b[key].to_numpy(), color="0.2", ls="--", marker="+",
                                ms=5, lw=0.9, label="linear Boltzmann, elastic runs")
            _n_ticks(ax, ns)
            ax.set_yscale("log")
            ax.set_ylim(0.5, 100)
            ax.set_yticks([1, 2.5, 5, 7.5, 10, 20, 50, 100])
            ax.set_yticks([], minor=True)
            ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.set_title(f"{geo}: {TEST_NAMES.get(test, test)}", fontsize=9)
            if i == len(tests) - 1:
                ax.set_xlabel("number of disks N")
                ax.tick_params(axis="x", labelsize=7)
            if j == 0:
                ax.set_ylabel("tagged disks rejected (%, log)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=9,
               frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return fig


def hazard_figure(hazard, table, n_shown=SHOWN_N):
    """The hazard of the tagged disk's next collision against the time since its last one,
    both in units of the mean interval, over the constant rate (1 for Poisson): on top one
    row per rule over the whole range (log y), below them one row per rule zoomed near 1
    for N >= ZOOM_MIN_N (linear y,
    ±`HAZARD_MARGIN` shaded; under the elastic rule the linear Boltzmann h(t) dashed; a
    bin beyond the limits is a filled triangle at the edge with its value, a bin whose
    95 % band alone leaves them an open one); one
    column per geometry, one line per N (distinct colours and markers at the bins'
    middles), 95 % bands."""
    import matplotlib.pyplot as plt

    geos = geometries_of(table)
    rules = ("mirror", "elastic")
    exp_of = table.drop_duplicates(["rule", "geometry"]).set_index(["rule", "geometry"])
    # the axis ends where the last bin with an interval in it ends
    t_end = float(hazard.loc[hazard["events"] > 0, "t_high"].max() if "events" in hazard
                  else hazard["t_high"].max())
    fig, axes = plt.subplots(2 * len(rules), len(geos), figsize=(4.4 * len(geos), 11.5),
                             sharex=True, squeeze=False)
    palette = ("C3", "C1", "C2", "C0", "k", "C4", "C5", "C6", "C7", "C8")
    marks = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "*")
    colors = {n: palette[k % 10] for k, n in enumerate(n_shown)}
    markers = {n: marks[k % 10] for k, n in enumerate(n_shown)}
    for i, rule in enumerate(rules):
        for zoom in (False, True):
            for j, geo in enumerate(geos):
                row = zoom * len(rules) + i  # the log rows on top, the linear rows below
                ax = axes[row, j]
                if zoom:
                    ax.axhspan(1 - HAZARD_MARGIN, 1 + HAZARD_MARGIN, color="0.9", zorder=0)
                ax.axhline(1.0, color="0.5", lw=0.8)
                if (rule, geo) not in exp_of.index:
                    continue
                name = exp_of.loc[(rule, geo), "experiment"]
                if rule == "elastic":
                    ax.plot(BOLTZMANN_T, _boltzmann_curve(), color="C4", ls="--", lw=1.6,
                            label="linear Boltzmann h(t)", zorder=4)
                for n in n_shown:
                    d = hazard[(hazard["experiment"] == name) & (hazard["n_disks"] == n)]
                    if d.empty or (zoom and n < ZOOM_MIN_N):
                        continue
                    # log time axis: the first bin, [0, 0.01), is drawn from X_MIN
                    lo_t = np.maximum(d["t_low"].to_numpy(), X_MIN)
                    x = np.r_[lo_t, d["t_high"].to_numpy()[-1]]
                    y = np.r_[d["hazard"].to_numpy(), d["hazard"].to_numpy()[-1]]
                    ax.step(x, y, where="post", color=colors[n], lw=1.1)
                    ax.plot(np.sqrt(lo_t * d["t_high"].to_numpy()), d["hazard"], ls="none",
                            marker=markers[n], ms=3.5, color=colors[n], label=f"N = {n}")
                    ax.fill_between(x, np.r_[d["ci_low"], d["ci_low"].iloc[-1]],
                                    np.r_[d["ci_high"], d["ci_high"].iloc[-1]], step="post",
                                    color=colors[n], alpha=0.15, lw=0)
                ax.set_xscale("log")
                ax.set_xlim(X_MIN, t_end)
                plain_log_ticks(ax.xaxis)
                if zoom:
                    ax.set_ylim(*ZOOM_LIMITS)
                    ax.set_title(f"{rule}, {geo}: N ≥ {ZOOM_MIN_N}, linear y near 1",
                                 fontsize=9, pad=9)  # above the edge marks
                else:
                    ax.set_yscale("log")
                    ax.set_ylim(*FULL_LIMITS)
                    plain_log_ticks(ax.yaxis)
                    ax.set_title(f"{rule}, {geo}: every N, log y", fontsize=9)
                taken = {}
                for n in n_shown:  # nothing leaves the axes unmarked
                    d = hazard[(hazard["experiment"] == name) & (hazard["n_disks"] == n)]
                    if not d.empty and not (zoom and n < ZOOM_MIN_N):
                        _mark_outside(ax, d, colors[n], *ax.get_ylim(), taken=taken)
                if row == 2 * len(rules) - 1:
                    ax.set_xlabel("time since the last collision / mean interval")
                if j == 0:
                    ax.set_ylabel("hazard / rate" + (" (linear)" if zoom else " (log)"))
    handles, labels = axes[len(rules) - 1, 0].get_legend_handles_labels()
    handles += [Line2D([], [], color="0.3", marker="^", ls="none", ms=6),
                Line2D([], [], color="0.3", marker="^", mfc="none", ls="none", ms=6)]
    labels += ["bin beyond the axis (value beside)", "only its 95 % band beyond"]
    fig.legend(handles, labels, loc="upper center", ncol=(len(labels) + 1) // 2, fontsize=9,
               frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return fig


#: the times (mean intervals) at which the hazard figure draws the Boltzmann h(t)
BOLTZMANN_T = np.geomspace(X_MIN, 20.0, 40)


def _boltzmann_curve():
    """The elastic linear Boltzmann tagged disk's hazard over the mean rate at
    `BOLTZMANN_T` (`kicktimes.stats.dilute_tagged_disk`), computed once."""
    global _BOLTZMANN_H
    if _BOLTZMANN_H is None:
        from kicktimes.stats import dilute_tagged_disk

        _BOLTZMANN_H = dilute_tagged_disk("elastic").hazard(BOLTZMANN_T)
    return _BOLTZMANN_H


_BOLTZMANN_H = None


def _mark_outside(ax, d, color, low, high, taken=None):
    """Mark at the edge of ``ax`` every hazard bin of ``d`` beyond ``(low, high)``: a
    filled triangle pointing out with the bin's value beside it, or, where only the bin's
    95 % band leaves, an open one. ``taken`` (a dict shared by the calls on one axis)
    counts the labels already on each edge, so that the next stacks beside them; a
    label near the right edge is set inward. Returns the number of bins marked."""
    lo_t = np.maximum(d["t_low"].to_numpy(float), X_MIN)
    mid = np.sqrt(lo_t * d["t_high"].to_numpy(float))
    h = d["hazard"].to_numpy(float)
    c_lo, c_hi = d["ci_low"].to_numpy(float), d["ci_high"].to_numpy(float)
    marked = 0
    x0, x1 = (np.log(v) for v in ax.get_xlim())
    taken = {} if taken is None else taken
    for x, v, a, b in zip(mid, h, c_lo, c_hi, strict=True):
        for up, out, band_out in ((True, v > high, b > high), (False, v < low, a < low)):
            if not band_out:
                continue
            edge = 1.0 if up else 0.0
            ax.plot([x], [edge], transform=ax.get_xaxis_transform(), clip_on=False,
                    marker="^" if up else "v", ms=6, ls="none", color=color,
                    mfc=color if out else "none", zorder=5)
            if out:
                # inward near the right edge, stacked where another N marks the same bin
                right = (np.log(x) - x0) > 0.8 * (x1 - x0)
                k = taken.get(up, 0)  # every label on this edge gets its own line
                taken[up] = k + 1
                dy = (-3 - 9 * k) if up else (3 + 9 * k)
                ax.annotate(f"{v:.3g}", (x, edge), xycoords=("data", "axes fraction"),
                            xytext=(-6 if right else 5, dy), textcoords="offset points",
                            ha="right" if right else "left", va="top" if up else "bottom",
                            fontsize=7, color=color, zorder=6,
                            bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 0.4})
            marked += 1
    return marked


def rates_figure(table, nulls=None, boltzmann=None):
    """Against N: the collision frequency over Enskog's (at N = 2 also over the two-disk
    kinetic rate, stars: Enskog is not the reference for two disks), the index of
    dispersion of the tagged disks' counts in K mean intervals (log y), and the hazard of a
    collision within 0.01 mean intervals of the last over the constant rate (the first
    hazard bin); 95 % CIs, one line per (geometry, rule), panel titles, one legend below the
    panels; the rate's ±10 % band shaded; with ``nulls`` (`versus_null` rows: ``null_d``,
    ``null_hazard_first``) the same statistic on the Poisson null streams of the same runs,
    crosses; with ``boltzmann`` (``{"dispersion": D, "hazard_first": h}``) the elastic
    linear Boltzmann tagged disk's values, dashed (D) and dash-dotted (h), each named by
    its quantity in the legend."""
    boltzmann = boltzmann or {}
    import matplotlib.pyplot as plt

    panels = (("rate_enskog", "collision frequency / Enskog", "collision rate / Enskog",
               False),
              ("dispersion", "index of dispersion D (log)", "index of dispersion", True),
              ("hazard_first", "hazard in [0, 0.01) mean intervals / rate",
               "first hazard bin, [0, 0.01) mean intervals", False))
    # the Boltzmann level of each panel, named by its quantity, each its own dash
    level_names = {"dispersion": ("D∞", "--"), "hazard_first": ("h(0.005)", "-.")}
    ns = sorted(set(table["n_disks"]))
    fig, axes = plt.subplots(1, len(panels), figsize=(14, 4.6), squeeze=False)
    for ax, (key, label, title, log) in zip(axes[0], panels, strict=True):
        if key == "rate_enskog":
            ax.axhspan(1 - RATE_MARGIN, 1 + RATE_MARGIN, color="0.88", zorder=0)
        ax.axhline(1.0, color="0.5", lw=0.8, zorder=0)
        level = boltzmann.get(key)
        if level is not None:
            what, dash = level_names.get(key, (key, "--"))
            ax.axhline(level, color="0.15", ls=dash, lw=1.0, zorder=1,
                       label=f"linear Boltzmann, elastic: {what} = {level:.3g}")
        for k, ((_, geo, rule), d) in enumerate(table.groupby(
                ["experiment", "geometry", "rule"], sort=False, observed=True)):
            shift = 1.0 + 0.04 * (k - 2.5)
            x = d["n_disks"].to_numpy() * shift
            y = d[key].to_numpy()
            err = np.abs(d[[f"{key}_low", f"{key}_high"]].to_numpy().T - y)
            ax.errorbar(x, y, yerr=err, marker="os"[rule == "elastic"], ms=3.5, lw=1,
                        capsize=2, color=f"C{k // 2}", ls="-" if rule == "mirror" else "--",
                        label=f"{geo}, {rule}")
            null_key = {"dispersion": "null_d", "hazard_first": "null_hazard_first"}.get(key)
            if null_key and nulls is not None:
                z = nulls[(nulls["geometry"] == geo) & (nulls["rule"] == rule)]
                if not z.empty:
                    ax.plot(z["n_disks"].to_numpy() * shift, z[null_key].to_numpy(),
                            ls="none", marker="x", ms=5, mew=1.2, color=f"C{k // 2}")
                    if k == 0:
                        ax.plot([], [], ls="none", marker="x", ms=5, mew=1.2, color="k",
                                label="Poisson null of the same runs (colour: family)")
            if key == "rate_enskog" and "rate_two_disk" in d:
                two = d[(d["n_disks"] == 2) & d["rate_two_disk"].notna()]
                if not two.empty:
                    ax.plot(two["n_disks"] * shift, two["rate_two_disk"], ls="none",
                            marker="*", ms=8, color=f"C{k // 2}", mec="k", mew=0.5)
                    if k == 0:
                        # the legend's star in black: the stars take their family's colour
                        ax.plot([], [], ls="none", marker="*", ms=8, color="k",
                                label="N = 2 over the two-disk rate Γ(r) (colour: family)")
        _n_ticks(ax, ns)
        ax.tick_params(axis="x", labelsize=7)
        if log:
            ax.set_yscale("log")
            ax.set_yticks([0.8, 1, 1.14, 1.5, 2, 3, 5, 8])
            ax.set_yticks([], minor=True)
            ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("number of disks N")
        ax.set_ylabel(label)
    handles, labels = _unique_handles(axes)
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.17, 1, 1))
    return fig


#: the controls figure's findings: (the controls table's diagnostic, y label, margin)
CONTROL_PANELS = (("D − null D", "D − null D", 0.07),
                  ("KS share − null", "KS share − null (share)", 0.01),
                  ("hazard first bin − null", "first hazard bin − null", 0.03))
CONTROL_STYLES = {"primary": ("k", "o"), "seed": ("C0", "s"), "k60": ("C3", "^"),
                  "bulk": ("C2", "D"), "box": ("C4", "v")}


def controls_figure(long, *, n_min=10, names=None):
    """The findings under their controls against N (``N >= n_min``): one row per geometry x
    rule, one column per finding of `CONTROL_PANELS`, the controls dodged sideways with
    their own colours and markers, 95 % CIs, each finding's difference from its own null
    with its margin shaded, one y scale per column, a hollow marker where
    the finding is not robust (`kicktimes.studies.disks.controls.controls_findings`, its
    ``robust``)."""
    import matplotlib.pyplot as plt

    d = long[long["n_disks"] >= n_min]
    if d.empty:
        raise ValueError(f"long: no finding at N >= n_min = {n_min}")
    families = list(dict.fromkeys(d["family"]))
    controls = [c for c in CONTROL_STYLES if c in set(d["control"])]
    ns = sorted(set(d["n_disks"]))
    fig, axes = plt.subplots(len(families), len(CONTROL_PANELS),
                             figsize=(4.3 * len(CONTROL_PANELS), 2.3 * len(families) + 0.8),
                             sharex=True, sharey="col", squeeze=False)
    for i, fam in enumerate(families):
        for j, (finding, label, margin) in enumerate(CONTROL_PANELS):
            ax = axes[i, j]
            scale = 1.0
            ax.axhspan(-margin, margin, color="0.88", zorder=0)
            ax.axhline(0.0, color="0.5", lw=0.8, zorder=0)
            for k, control in enumerate(controls):
                g = d[(d["family"] == fam) & (d["diagnostic"] == finding)
                      & (d["control"] == control)]
                if g.empty:
                    continue
                color, marker = CONTROL_STYLES[control]
                x = g["n_disks"].to_numpy() * (1.0 + 0.09 * (k - (len(controls) - 1) / 2))
                y = scale * g["estimate"].to_numpy()
                err = np.abs(scale * g[["ci_low", "ci_high"]].to_numpy().T - y)
                ax.errorbar(x, y, yerr=err, color=color, marker="none", ls="none", lw=1,
                            capsize=2)
                for rob in (True, False):
                    m = g["robust"].to_numpy() == rob
                    ax.plot(x[m], y[m], ls="none", marker=marker, ms=4.5, color=color,
                            mfc=color if rob else "white",
                            label=(names or {}).get(control, control) if rob else None)
            _n_ticks(ax, ns)
            ax.tick_params(axis="x", labelsize=7)
            ax.set_title(f"{fam}: {finding}", fontsize=8.5)
            ax.set_ylabel(label, fontsize=8)
            if i == len(families) - 1:
                ax.set_xlabel("number of disks N")
    handles, labels = _unique_handles(axes)
    handles.append(axes[0, 0].plot([], [], ls="none", marker="o", mfc="white", color="0.3")[0])
    labels.append("hollow: not robust at that N")
    # at most 3 entries a row: six long control names overflow one row of the figure
    ncol = min(len(labels), 3)
    rows = -(-len(labels) // ncol)
    fig.legend(handles, labels, loc="upper center", ncol=ncol, fontsize=8.5, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.5 * rows / (2.3 * len(families) + 0.8)))
    return fig
