"""The figures of the mechanism study (docs/results/mechanism.md).

Each ``fig_*`` takes the per-group results of
`kicktimes.studies.mechanism.analysis.analyse` (a dict keyed by (IC family, radius)) and
returns a `matplotlib.figure.Figure`; `write_figures` saves them.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from kicktimes import stats  # noqa: E402
from kicktimes.studies.mechanism.twins import dispersion  # noqa: E402

__all__ = ["BATTERY_DISPERSION_YLIM", "BATTERY_SHARE_YLIM", "NORMALISED_YLIM", "fig_battery",
           "fig_hazard", "fig_hazard_normalised",
           "fig_impact", "fig_rate_prediction", "fig_recollisions", "fig_state_rates",
           "fig_survival", "write_figures"]

TWIN_LABELS = {"poisson": "Poisson\n(pooled\nrate)",
               "mixed_poisson": "mixed\nPoisson\nΓ(initial)",
               "cox_iid": "Cox, iid\npost-\ncollision",
               "cox_sequence": "Cox, run's\nown states\n(in sample)",
               "cox_markov_oos": "rate chain,\nother half\n(out of\nsample)",
               "observed": "observed"}


def _groups(results):
    """The IC families and radii of the results, in order."""
    methods = list(dict.fromkeys(m for m, _ in results))
    radii = list(dict.fromkeys(r for _, r in results))
    return methods, radii


def _panels(results, fn, title, *, sharey=False, sharex=False, figsize=(10, 7.5)):
    methods, radii = _groups(results)
    fig, axes = plt.subplots(len(methods), len(radii), figsize=figsize, sharey=sharey,
                             sharex=sharex, squeeze=False)
    for i, method in enumerate(methods):
        for j, r in enumerate(radii):
            ax = axes[i, j]
            fn(ax, (method, r), results[method, r])
            ax.set_title(f"{'paper' if method == 'paper' else 'invariant'} ICs, r = {r:g}",
                         fontsize=10)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


#: one y-range for the rescaled hazard under every rule (mirror and elastic figures alike)
NORMALISED_YLIM = (1e-3, 10.0)
#: the battery's y ranges under every rule (so that the mirror and elastic figures read
#: alike): rejection shares, and the rate dispersion across ICs (log); a value beyond one
#: widens it rather than being cut off
BATTERY_SHARE_YLIM = (0.0, 0.65)
BATTERY_DISPERSION_YLIM = (0.5, 100.0)


def _hazard_steps(ax, haz, *, scale=1.0, label, color, hollow=False, zorder=2):
    tab = haz.table
    mid = tab["t_mid"].to_numpy()
    ax.errorbar(mid, tab["hazard"] / scale, yerr=[(tab["hazard"] - tab["ci_low"]) / scale,
                (tab["ci_high"] - tab["hazard"]) / scale], fmt="o", ms=7 if hollow else 4,
                color=color, capsize=2, label=label, zorder=zorder,
                mfc="none" if hollow else color)


def _log_log(ax, xlabel, ylabel):
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7)


def fig_hazard(results):
    def draw(ax, key, d):
        haz = d["hazard"]
        _hazard_steps(ax, d["hazard_nonsticky"], label="sticky runs left out", color="C3")
        _hazard_steps(ax, haz, label="two disks, all runs (95 % CI, open)", color="k",
                      hollow=True, zorder=3)
        ax.axhline(haz.rate, color="grey", ls="--", label="Poisson (flat, same rate)")
        t = np.geomspace(0.1, haz.table["t_high"].iloc[-1], 300)
        if "hyper" in d:
            ax.plot(t, d["hyper"].dist.pdf(t) / d["hyper"].dist.sf(t), color="C1",
                    label="hyperexponential fit")
            ax.plot(t, d["mixture"].hazard(t), color="C0", label="mixture over post-collision L")
        _log_log(ax, "time since the last collision (table radii / speed)",
                 "hazard (collisions per unit time)")
    return _panels(results, draw, "Hazard of the next collision (one y scale)", sharey=True)


def fig_hazard_normalised(results):
    def draw(ax, key, d):
        _hazard_steps(ax, d["hazard_own"], scale=d["hazard_own"].rate, color="C2",
                      label="time in units of the run's own mean interval")
        if "hazard_rescaled" in d:
            _hazard_steps(ax, d["hazard_rescaled"], color="C0",
                          label="time rescaled by Γ(state after the last collision)")
        ax.axhline(1.0, color="grey", ls="--", label="Poisson")
        _log_log(ax, "rescaled time since the last collision (dimensionless)",
                 "hazard / mean rate")
        ax.set_ylim(*NORMALISED_YLIM)
    return _panels(results, draw, "Hazard after removing the rate differences (one y scale)",
                   sharey=True)


def fig_recollisions(results):
    def draw(ax, key, d):
        tab = d["table"]
        obs = tab.loc[tab["interval"].notna(), ["wall_hits0", "wall_hits1"]].max(axis=1)
        k = np.arange(1, 16)
        for vals, label, color in ((obs.to_numpy(), "disk-disk collisions", "k"),
                                   (d["wall_hits_null"], "randomly placed events", "grey")):
            share = np.array([(vals == v).mean() for v in k])
            ax.plot(k, share, "o-", color=color, ms=3, label=label)
        rec, null = d["recollision"], d["recollision_null"]
        ax.set_yscale("log")
        ax.set_xlabel("max wall hits of the two disks since the previous event")
        ax.set_ylabel("share of events")
        # all runs here; the page's table leaves the sticky runs out
        ax.text(0.3, 0.9, f"re-collisions (≤ 1 each), all runs: {rec.share:.3f} "
                f"[{rec.ci_low:.3f}, {rec.ci_high:.3f}]\nrandom placement: {null.share:.3f} "
                f"[{null.ci_low:.3f}, {null.ci_high:.3f}]",
                transform=ax.transAxes, fontsize=8, va="top")
        ax.legend(fontsize=7, loc="lower left")
    return _panels(results, draw, "Re-collisions: returns after at most one wall hit "
                   "(one x and y scale)", sharex=True, sharey=True)


def fig_rate_prediction(results):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    for ax, which, xlabel in ((axes[0], "pred", "predicted from the initial (L0, L1)"),
                              (axes[1], "comp_rate", "time average of Γ(L(t)) along the run")):
        lo, hi = np.inf, 0
        for (method, r), d in results.items():
            x, y = d[which], np.maximum(d["obs_rate"], 0.5 / 2000)
            ax.scatter(x, y, s=8, alpha=0.6,
                       marker="o" if method == "paper" else "^",
                       label=f"{'paper' if method == 'paper' else 'invariant'}, r = {r:g}")
            lo, hi = min(lo, x.min(), y.min()), max(hi, x.max(), y.max())
        ax.plot([lo, hi], [lo, hi], color="grey", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"rate {xlabel} (per unit time)")
        ax.set_ylabel("observed rate n_pp / t_max (0 shown at 1 / (2 t_max))")
        ax.legend(fontsize=7)
    fig.suptitle("Each IC's collision rate: predicted against observed")
    fig.tight_layout()
    return fig


def fig_survival(results):
    def draw(ax, key, d):
        t, sf = d["km"]
        if "km_ci" in d:
            lo, hi = d["km_ci"]
            ax.fill_between(t, np.maximum(lo, 1e-12), hi, step="post", color="k", alpha=0.2,
                            lw=0, label="Kaplan-Meier 95 % CI")
        ax.step(t, sf, where="post", color="k", label="pooled intervals (Kaplan-Meier)")
        grid = np.linspace(0, t.max(), 300)
        ax.plot(grid, d["mixture"].sf(grid), color="C0", label="mixture over post-collision L")
        ax.plot(grid, d["hyper"].dist.sf(grid), color="C1", ls="--", label="hyperexponential fit")
        ax.plot(grid, d["expo"].dist.sf(grid), color="grey", ls=":", label="exponential fit")
        ax.set_yscale("log")
        ax.set_ylim(1e-4, 1.05)
        back = d["return_time"]
        s_obs = sf[t >= back][0]
        ax.text(0.97, 0.97, f"S({back:g}): observed {s_obs:.3f}, mixture "
                f"{float(d['mixture'].sf(back)):.3f}\n(the returns within a wall round "
                "trip)", transform=ax.transAxes, fontsize=8, ha="right", va="top")
        ax.set_xlabel("interval between collisions")
        ax.set_ylabel("survival")
        if key == next(iter(results)):      # one legend, clear of the tails
            ax.legend(fontsize=7, loc="center right", framealpha=0.9)
    return _panels(results, draw, "The pooled interval law (one x and y scale)", sharex=True,
                   sharey=True)


def fig_battery(results):
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.2))
    twins = tuple(next(iter(results.values()))["twins"])
    names = (*twins, "observed")
    width = 0.8 / len(results)
    panels = (("uniformity_ks", "share of runs rejected, uniformity KS (α = 0.05)"),
              ("exponential_ad", "share of runs rejected, exponential AD (α = 0.05)"),
              ("dispersion_index", "rate dispersion across ICs: var / mean of the\n"
               "whole-run counts over ICs (sticky runs left out)"))
    for k, ((method, r), d) in enumerate(results.items()):
        x = np.arange(len(names)) + (k - (len(results) - 1) / 2) * width
        label = f"{'paper' if method == 'paper' else 'invariant'}, r = {r:g}"
        calm = d["calm_ic"]
        for ax, (what, _) in zip(axes, panels, strict=True):
            if what == "dispersion_index":
                vals = [[dispersion(b["counts"][calm]) for b in d["twins"][n]] for n in twins]
                counts = np.asarray(d["observed"]["counts"][calm], float)
                obs = dispersion(counts)
                picks = stats.resample_indices(counts.size, n_boot=1000, rng=0)
                obs_ci = stats.percentile_interval([dispersion(counts[p]) for p in picks])
            else:
                vals = [[b["reject"][what].mean() for b in d["twins"][n]] for n in twins]
                obs = d["observed"]["reject"][what].mean()
                obs_ci = d["observed"]["ci"][what]
            mean = [np.mean(v) for v in vals] + [obs]
            low = [np.quantile(v, 0.025) for v in vals] + [obs_ci[0]]
            high = [np.quantile(v, 0.975) for v in vals] + [obs_ci[1]]
            err = np.nan_to_num([np.subtract(mean, low), np.subtract(high, mean)])
            ax.bar(x, mean, width, yerr=err, capsize=2, label=label)
    for ax, (what, ylabel) in zip(axes, panels, strict=True):
        ax.axhline(1.0 if what == "dispersion_index" else 0.05, color="grey", ls="--", lw=1)
        lo, hi = BATTERY_DISPERSION_YLIM if what == "dispersion_index" else BATTERY_SHARE_YLIM
        if what == "dispersion_index":
            ax.set_yscale("log")       # the twins reach tens, the observed lie at a few
        drawn = ax.get_ylim()
        ax.set_ylim(min(lo, drawn[0]), max(hi, drawn[1]))
        ax.set_xticks(np.arange(len(names)), [TWIN_LABELS[n] for n in names], fontsize=7)
        ax.set_ylabel(ylabel, fontsize=9)
    axes[0].legend(fontsize=7)
    fig.suptitle("The Poisson battery on twins of the runs (bars: twins' 95 % range over "
                 "ensembles; observed: Clopper-Pearson; rate dispersion across ICs: bootstrap "
                 "over ICs, dashed: its Poisson value)", fontsize=11)
    fig.tight_layout()
    return fig


def fig_state_rates(cells, rate):
    """``cells``: {r: (edges, observed, predicted, events)} per (L0, L1) cell; ``rate``:
    ``rate(r, L0, L1)``."""
    fig, axes = plt.subplots(len(cells), 3, figsize=(15, 4.6 * len(cells)), squeeze=False,
                             layout="constrained")
    for row, (r, (edges, emp, pred, events)) in zip(axes, cells.items(), strict=True):
        gamma = stats.kinetic_rate(r)
        grid = np.linspace(-(1 - r) * 0.999, (1 - r) * 0.999, 81)
        g0, g1 = np.meshgrid(grid, grid, indexing="ij")
        theory = rate(r, g0.ravel(), g1.ravel()).reshape(g0.shape) / gamma
        norm = matplotlib.colors.LogNorm(0.25, 8)
        im = row[0].pcolormesh(grid, grid, theory.T, norm=norm, cmap="magma", shading="auto")
        row[0].set_title(f"predicted Γ(r; L0, L1) / Γ(r), r = {r:g}", fontsize=10)
        row[1].pcolormesh(edges, edges, np.where(events >= 10, emp, np.nan).T / gamma,
                          norm=norm, cmap="magma")
        row[1].set_title("observed rate after collisions in the cell / Γ(r)", fontsize=10)
        fig.colorbar(im, ax=row[1], label="rate / kinetic rate Γ(r)")
        for ax in row[:2]:
            ax.set_xlabel("L0 after the collision")
            ax.set_ylabel("L1 after the collision")
            ax.set_aspect("equal")
        ok = events >= 10
        se = np.sqrt(events[ok]) / events[ok]       # relative SE of a Poisson count
        row[2].errorbar(pred[ok] / gamma, emp[ok] / gamma, yerr=1.96 * se * emp[ok] / gamma,
                        fmt="o", ms=3, alpha=0.7)
        lim = [0.3, np.nanmax(emp[ok] / gamma, initial=8.0)]
        row[2].plot(lim, lim, color="grey", lw=1)
        row[2].set_xscale("log")
        row[2].set_yscale("log")
        _plain_log_ticks(row[2])
        row[2].set_xlabel("predicted rate, mean over the cell / Γ(r)")
        row[2].set_ylabel("observed rate / Γ(r) (95 % CI)")
        row[2].set_title(f"one point per cell, r = {r:g}", fontsize=10)
    fig.suptitle("The rate after a collision depends on the angular momenta it leaves "
                 "(paper and invariant ICs pooled; cells with ≥ 10 collisions)")
    return fig


def _plain_log_ticks(ax):
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(matplotlib.ticker.FixedLocator([0.3, 0.5, 1, 2, 3, 5, 10]))
        axis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def fig_impact(results):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    methods, radii = _groups(results)
    for r in radii:
        tab = pd.concat([results[m, r]["table"] for m in methods])
        calm = ~pd.concat([results[m, r]["sticky"] for m in methods]).to_numpy()
        tab = tab[calm & tab["interval"].notna().to_numpy()]
        again = (tab["wall_hits0"] <= 1) & (tab["wall_hits1"] <= 1)
        for mask, label, ls in ((again, "re-collisions", "-"), (~again, "others", "--")):
            axes[0].hist(tab.loc[mask, "impact_ratio_before"], bins=np.linspace(0, 1, 21),
                         density=True, histtype="step", ls=ls, label=f"{label}, r = {r:g}")
            axes[1].hist(tab.loc[mask, "contact_radius"], bins=np.linspace(0, 1, 21),
                         density=True, histtype="step", ls=ls, label=f"{label}, r = {r:g}")
    axes[0].set_xlabel("impact parameter b / 2r of the collision before (0 head-on, 1 grazing)")
    axes[1].set_xlabel("distance of the collision from the table's centre")
    for ax in axes:
        ax.set_ylabel("density")
        ax.legend(fontsize=7)
    fig.suptitle("Re-collisions against other collisions (both IC families, sticky runs "
                 "left out)")
    fig.tight_layout()
    return fig


def write_figures(results, out, *, cells=None, rate=None):
    """Save every figure as ``out/mechanism_<name>.png``; the predicted-rate figures need
    ``cells`` (`fig_state_rates`) and results with the rate columns."""
    figures = {"hazard": fig_hazard, "hazard_normalised": fig_hazard_normalised,
               "recollisions": fig_recollisions, "impact": fig_impact}
    if cells is not None:
        figures.update(rate_prediction=fig_rate_prediction, survival=fig_survival,
                       battery=fig_battery)
    for name, fn in figures.items():
        fig = fn(results)
        fig.savefig(Path(out) / f"mechanism_{name}.png", dpi=110)
        plt.close(fig)
    if cells is not None:
        fig = fig_state_rates(cells, rate)
        fig.savefig(Path(out) / "mechanism_state_rates.png", dpi=110)
        plt.close(fig)
