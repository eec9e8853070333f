"""The unequal-disks study's figure: rate, Poisson statistics and FTLE ratios against the
size ratio."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from kicktimes.studies.unequal.tables import ks_interval

__all__ = ["size_ratio_figure"]


def size_ratio_figure(table, n_ics=200):
    """Three panels against the size ratio: the collision rate over the kinetic rate, the
    KS rejection share and the dispersion index, the kicked / two-disk FTLE ratios; from
    `size_ratio_table` (``n_ics``: ICs per ratio). Returns a `matplotlib.figure.Figure`."""
    fig = Figure(figsize=(11, 3.6), layout="constrained")
    ax = fig.subplots(1, 3)
    x = table["size_ratio"]

    err = np.vstack([table["rate_ratio"] - table["rate_low"],
                     table["rate_high"] - table["rate_ratio"]])
    ax[0].errorbar(x, table["rate_ratio"], yerr=err, fmt="o-", color="black", capsize=3)
    ax[0].axhspan(0.9, 1.1, color="0.85", zorder=0, label="±10 % band")
    ax[0].axhline(1.0, color="0.5", lw=0.8)
    ax[0].set_ylim(0.8, 1.2)
    ax[0].legend(fontsize="small")
    ax[0].set_title("collision rate / kinetic Γ(r0, r1)", fontsize="medium")
    ks = np.array([ks_interval(row, n_ics) for _, row in table.iterrows()])
    share = table["ks_reject_share"].to_numpy()
    ax[1].errorbar(x, share, yerr=np.vstack([share - ks[:, 0], ks[:, 1] - share]), fmt="o-",
                   color="tab:blue", capsize=3, label="KS rejection share (Clopper–Pearson)")
    ax[1].axhline(0.05, color="tab:blue", lw=0.8, ls=":", label="Poisson: 0.05")
    ax[1].set_ylim(0, max(0.5, float(ks[:, 1].max()) * 1.1))
    ax[1].set_ylabel("KS rejection share", color="tab:blue")
    twin = ax[1].twinx()
    d = table["dispersion_index"].to_numpy()
    if "disp_low" in table:
        twin.errorbar(x, d, yerr=np.vstack([d - table["disp_low"], table["disp_high"] - d]),
                      fmt="s--", color="tab:red", capsize=3, label="dispersion index (bootstrap)")
    else:
        twin.plot(x, d, "s--", color="tab:red", label="dispersion index (no interval)")
    twin.axhline(1.0, color="tab:red", lw=0.8, ls=":", label="Poisson: 1")
    twin.set_ylim(0, max(6.0, float(np.nanmax(table.get("disp_high", d))) * 1.1))
    twin.set_ylabel("dispersion index", color="tab:red")
    ax[1].set_title("non-Poisson collision statistics", fontsize="medium")
    h1, l1 = ax[1].get_legend_handles_labels()
    h2, l2 = twin.get_legend_handles_labels()
    ax[1].legend(h1 + h2, l1 + l2, fontsize="x-small", loc="upper left")
    for disk, color in ((0, "tab:orange"), (1, "tab:green")):
        for kind, fmt in (("partner", "o-"), ("own", "s:")):
            est = table[f"ftle_{kind}_ratio_disk{disk}"]
            err = np.vstack([est - table[f"ftle_{kind}_low_disk{disk}"],
                             table[f"ftle_{kind}_high_disk{disk}"] - est])
            label = (f"disk {disk} ({'r0 = 0.01' if disk == 0 else 'r1'}), "
                     f"{'the other disk as partner' if kind == 'partner' else 'own-size partner'}")
            ax[2].errorbar(x, est, yerr=err, fmt=fmt, color=color, capsize=3, label=label,
                           alpha=1.0 if kind == "partner" else 0.6)
    ax[2].axhspan(0.9, 1.1, color="0.85", zorder=0)
    ax[2].axhline(1.0, color="0.5", lw=0.8)
    ax[2].set_title("FTLE: kicked (scatter) / two-disk", fontsize="medium")
    ax[2].legend(fontsize="x-small")
    for a in ax:
        a.set_xlabel("size ratio r1 / r0")
    return fig
