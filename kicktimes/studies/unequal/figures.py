"""The unequal-disks study's figure: rate, Poisson statistics and FTLE ratios against the
size ratio."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from kicktimes.stats import margin_of
from kicktimes.studies.unequal.tables import ks_interval

__all__ = ["size_ratio_figure"]


def size_ratio_figure(table, n_ics=200):
    """Four panels against the size ratio, each on its own y scale: (a) the collision rate
    over the kinetic rate, (b) the KS rejection share against α (exact for this test),
    (c) the rate dispersion across ICs against its null band (Poisson counts over the
    same run lengths), (d) the kicked / two-disk FTLE ratios, each series shifted a little
    along x so that coinciding points stay apart, with the 10 % and 5 % bands; from
    `size_ratio_table` (``n_ics``: ICs per ratio). Returns a `matplotlib.figure.Figure`.

    The KS share and the rate dispersion are apart (one y axis each): on twin axes of one
    panel, two scales made their curves look comparable where they are not.
    """
    fig = Figure(figsize=(10.5, 7.0), layout="constrained")
    ax = fig.subplots(2, 2).ravel()
    x = table["size_ratio"]

    err = np.vstack([table["rate_ratio"] - table["rate_low"],
                     table["rate_high"] - table["rate_ratio"]])
    ax[0].errorbar(x, table["rate_ratio"], yerr=err, fmt="o-", color="black", capsize=3,
                   label="rate / Γ (95 % CI)")
    band = margin_of("counts")
    ax[0].axhspan(1 - band, 1 + band, color="0.85", zorder=0,
                  label=f"±{100 * band:g} % band (the counts' margin)")
    ax[0].axhline(1.0, color="0.5", lw=0.8)
    ax[0].set_ylim(0.8, 1.2)
    ax[0].legend(fontsize="small")
    ax[0].set_ylabel("collision rate / kinetic rate")
    ax[0].set_title("(a) collision rate / kinetic Γ(r0, r1)", fontsize="medium")
    ks = np.array([ks_interval(row, n_ics) for _, row in table.iterrows()])
    share = table["ks_reject_share"].to_numpy()
    ax[1].errorbar(x, share, yerr=np.vstack([share - ks[:, 0], ks[:, 1] - share]), fmt="o-",
                   color="tab:blue", capsize=3,
                   label="KS rejection share (95 % Clopper–Pearson)")
    if "ks_null" in table:
        # read against its null streams' share (the page's reading), not against α
        ax[1].fill_between(x, table["ks_null_low"], table["ks_null_high"], color="0.8",
                           label="null streams' share (Poisson, same rates and windows; 95 %)")
        ax[1].plot(x, table["ks_null"], color="0.4", lw=0.8)
    else:
        ax[1].axhline(0.05, color="tab:blue", lw=0.8, ls=":",
                      label="α = 0.05 (the test's exact level under Poisson)")
    # room above the highest bar for the legend, which covers no bar end
    ax[1].set_ylim(0, max(0.5, float(ks[:, 1].max()) * 1.35))
    ax[1].set_ylabel("share of ICs the KS test rejects")
    ax[1].set_title("(b) KS rejection share", fontsize="medium")
    ax[1].legend(fontsize="x-small", loc="upper left")
    d = table["dispersion_index"].to_numpy()
    if "disp_low" in table:
        ax[2].errorbar(x, d, yerr=np.vstack([d - table["disp_low"], table["disp_high"] - d]),
                       fmt="s--", color="tab:red", capsize=3,
                       label="rate dispersion across ICs (bootstrap 95 % CI)")
    else:
        ax[2].plot(x, d, "s--", color="tab:red", label="rate dispersion across ICs (no interval)")
    if "d_null" in table:
        # read against its null (Poisson counts over the same run lengths), not against 1
        ax[2].fill_between(x, table["d_null_low"], table["d_null_high"], color="0.8",
                           zorder=0, label="null: Poisson counts, same run lengths (95 %)")
        ax[2].plot(x, table["d_null"], color="0.3", lw=1.0, ls=":", label="null mean")
    else:
        ax[2].axhline(1.0, color="tab:red", lw=0.8, ls=":", label="Poisson: 1")
    ax[2].set_ylim(0, max(6.0, float(np.nanmax(table.get("disp_high", d))) * 1.3))
    ax[2].set_ylabel("var / mean of the whole-run counts over ICs")
    ax[2].set_title("(c) rate dispersion across ICs", fontsize="medium")
    ax[2].legend(fontsize="x-small", loc="upper right")
    # each series a little apart along x: at ratio 1 the two partners are the same kick
    shift = 0.04 * (float(x.max()) - float(x.min()) or 1.0)
    for k, (disk, color) in enumerate(((0, "tab:orange"), (1, "tab:green"))):
        for j, (kind, fmt) in enumerate((("partner", "o-"), ("own", "s:"))):
            est = table[f"ftle_{kind}_ratio_disk{disk}"]
            err = np.vstack([est - table[f"ftle_{kind}_low_disk{disk}"],
                             table[f"ftle_{kind}_high_disk{disk}"] - est])
            label = (f"disk {disk} ({'r0 = 0.01' if disk == 0 else 'r1'}), "
                     f"{'the other disk as partner' if kind == 'partner' else 'own-size partner'}")
            ax[3].errorbar(x + (2 * k + j - 1.5) * shift, est, yerr=err, fmt=fmt, color=color,
                           capsize=3, label=label, alpha=1.0 if kind == "partner" else 0.6)
    ax[3].axhspan(0.9, 1.1, color="0.9", zorder=0)
    ax[3].axhspan(0.95, 1.05, color="0.8", zorder=0)
    ax[3].axhline(1.0, color="0.5", lw=0.8)
    ax[3].set_ylabel("FTLE ratio kicked / two-disk")
    ax[3].set_title("(d) FTLE: kicked (scatter) / two-disk; bands ±10 %, ±5 %",
                    fontsize="medium")
    # below the panel: inside, it covered the own-size points
    ax[3].legend(fontsize="x-small", loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2,
                 frameon=False, title="bars: 95 % bootstrap CI over ICs",
                 title_fontsize="x-small")
    for a in ax:
        a.set_xlabel("size ratio r1 / r0")
    return fig
