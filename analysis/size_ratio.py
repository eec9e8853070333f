"""Unequal disks: how the collision statistics and the kicked-disk agreement change with the
size ratio.

Disk 0 keeps r0 = 0.01; disk 1 has r1 = 0.01, 0.015, 0.025, 0.04 (size ratio 1 to 4). Per
ratio, 200 ICs from the pair's invariant measure (mirror rule), run for 10 000 steps of
0.3 with the tangent FTLE of each disk:

* the collision rate against the exact kinetic rate Γ(r0, r1) (ratio of means, 95 % CI);
* the Poisson battery on each IC's collision times (share rejecting exponential
  uniformity, dispersion index of the counts);
* per disk, the FTLE of the two-disk system against the disk alone with scattering kicks
  at Poisson times at its own IC's collision rate (the best one-disk model of
  docs/results), as a ratio of means with a bootstrap CI over ICs: with the proper
  partner (the other disk's radius, ``partner_radius``; columns ``ftle_partner_*``) and,
  as the control, a partner of the kicked disk's own size (the equal-disk kick; columns
  ``ftle_own_*``). Both use the same kick times and scattering numbers (common random
  numbers), so they differ only in the contact distance ``r_d + r_partner``.

Writes ``size_ratio.csv`` and ``size_ratio.png`` into ``--out`` and the page
``unequal.md`` beside it: every ratio with its `kicktimes.stats.ratio_verdict` (10 %).

Run: python analysis/size_ratio.py [--n-ics 200] [--out docs/results/size_ratio]
     python analysis/size_ratio.py --page-only   (the page from the CSV, nothing simulated)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes import initial_conditions, schedules
from kicktimes.diagnostics import lyapunov
from kicktimes.diagnostics.lyapunov import lyapunov_pass
from kicktimes.stats import kinetic_rate, poisson_group

R0 = 0.01
R1 = (0.01, 0.015, 0.025, 0.04)


def ratio_ci(x, y, rng, n_boot=2000):
    """Ratio of means ``sum x / sum y`` and its percentile bootstrap CI over pairs."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    idx = rng.integers(0, x.size, size=(n_boot, x.size))
    boot = x[idx].sum(1) / y[idx].sum(1)
    return x.sum() / y.sum(), *np.quantile(boot, [0.025, 0.975])


def dispersion_ci(counts, rng, n_boot=2000):
    """95 % bootstrap interval over ICs of the dispersion index var / mean of the counts."""
    counts = np.asarray(counts, float)
    b = counts[rng.integers(0, counts.size, (n_boot, counts.size))]
    lo, hi = np.percentile(b.var(1, ddof=1) / b.mean(1), [2.5, 97.5])
    return float(lo), float(hi)


def add_dispersion_intervals(table, args):
    """The dispersion index's bootstrap interval for a table written without it: the
    per-IC collision counts again from the two-disk runs alone (the same ICs, the same
    trajectories to t = n_steps x tau, no tangent), checked against the stored index."""
    from kicktimes import simulate_two_particle

    rng = np.random.default_rng(args.seed)
    lows, highs = [], []
    for _, row in table.iterrows():
        radii = (R0, float(row["r1"]))
        ics = initial_conditions(args.n_ics, radii, seed=args.seed, method="uniform")
        counts = np.array([simulate_two_particle(ic, radii, t_max=args.n_steps * args.tau).n_pp
                           for ic in ics], float)
        d = counts.var(ddof=1) / counts.mean()
        if not np.isclose(d, row["dispersion_index"], rtol=1e-9):
            raise RuntimeError(f"counts at r1 = {row['r1']} give dispersion {d}, the table "
                               f"{row['dispersion_index']}")
        lo, hi = dispersion_ci(counts, rng)
        lows.append(lo)
        highs.append(hi)
    return table.assign(disp_low=lows, disp_high=highs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n-ics", type=int, default=200)
    ap.add_argument("--n-steps", type=int, default=10000)
    ap.add_argument("--tau", type=float, default=0.3)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--out", default="docs/results/size_ratio")
    ap.add_argument("--page-only", action="store_true",
                    help="write unequal.md from OUT/size_ratio.csv without simulating")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    command = ("python analysis/size_ratio.py --page-only" if args.page_only else
               f"python analysis/size_ratio.py --n-ics {args.n_ics} --n-steps {args.n_steps}")
    if args.page_only:
        table = pd.read_csv(out / "size_ratio.csv")
        if "disp_low" not in table:
            table = add_dispersion_intervals(table, args)
            table.to_csv(out / "size_ratio.csv", index=False)
        figure(table, args.n_ics).savefig(out / "size_ratio.png", dpi=110)
        write_page(table, out.parent / "unequal.md", command, args)
        return
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    rows = []
    for r1 in R1:
        radii = (R0, r1)
        gamma = kinetic_rate(radii)
        ics = initial_conditions(args.n_ics, radii, seed=args.seed, method="uniform")
        times, windows, lam = [], [], {0: [], 1: []}
        kicked = {(kind, disk): [] for kind in ("partner", "own") for disk in (0, 1)}
        for i, ic in enumerate(ics):
            for disk in (0, 1):
                res, run, _ = lyapunov_pass(ic, radii, n_steps=args.n_steps, tau=args.tau,
                                            track=disk)
                lam[disk].append(res.lam)
            times.append(run.pp_times)
            windows.append(run.t_max)
            rate = max(run.n_pp, 1) / run.t_max
            for disk in (0, 1):
                partners = {"partner": radii[1 - disk], "own": radii[disk]}
                for kind, partner_radius in partners.items():
                    one = lyapunov(ic[disk], radii[disk], n_steps=args.n_steps, tau=args.tau,
                                   kicks=schedules.Poisson(rate), kick_angle="scatter",
                                   partner_radius=partner_radius,
                                   rng=np.random.default_rng((args.seed, i, disk)))
                    kicked[kind, disk].append(one.lam)
        counts = np.array([t.size for t in times])
        group = poisson_group(times, windows, rng=rng)
        rej = group.rejections.set_index("test")
        rate_ratio = ratio_ci(counts, gamma * np.asarray(windows), rng)
        disp_low, disp_high = dispersion_ci(counts, rng)
        row = {"r0": R0, "r1": r1, "size_ratio": r1 / R0, "kinetic_rate": gamma,
               "rate_ratio": rate_ratio[0], "rate_low": rate_ratio[1],
               "rate_high": rate_ratio[2],
               "ks_reject_share": float(rej.loc["uniformity_ks", "rate"]),
               "dispersion_index": float(group.homogeneity["dispersion_index"]),
               "disp_low": disp_low, "disp_high": disp_high}
        for disk in (0, 1):
            for kind in ("partner", "own"):
                est, lo, hi = ratio_ci(kicked[kind, disk], lam[disk], rng)
                row[f"ftle_{kind}_ratio_disk{disk}"] = est
                row[f"ftle_{kind}_low_disk{disk}"] = lo
                row[f"ftle_{kind}_high_disk{disk}"] = hi
            row[f"ftle_two_disk{disk}"] = float(np.mean(lam[disk]))
        rows.append(row)
        print(f"r1 = {r1}: done at {time.perf_counter() - t0:.0f} s")
    table = pd.DataFrame(rows)
    table.to_csv(out / "size_ratio.csv", index=False)
    figure(table, args.n_ics).savefig(out / "size_ratio.png", dpi=110)
    print(table.round(4).to_string())
    write_page(table, out.parent / "unequal.md", command, args)


def write_page(table, page, command, args):
    """docs/results/unequal.md: the size-ratio table with a verdict beside every ratio."""
    from generated import MARGIN, header

    from kicktimes.stats import format_interval, ratio_rule, ratio_verdict

    lines = header("Unequal disks: the size ratio", command,
                   ["the direct simulations of `analysis/size_ratio.py` (`size_ratio.csv`; "
                    "no store)"])
    lines += [f"Definitions and methods: [../unequal.md](../unequal.md). Disk 0 keeps "
              f"r0 = {R0:g}; {args.n_ics} invariant ICs per ratio, {args.n_steps} steps of "
              f"{args.tau:g}, mirror rule; the kicked disk gets scattering kicks at Poisson "
              "times at its IC's own collision rate. Ratios of means with 95 % bootstrap "
              f"intervals over ICs; verdicts: {ratio_rule(MARGIN)}.", "",
              "The four FTLE columns are ratios of the **finite-time Lyapunov exponent** "
              "(tangent FTLE of the named disk, mean over ICs): the kicked disk's over the "
              "same disk's in the two-disk system, with the partner radius of the scattering "
              "kicks as named. KS rejections: share of the two-disk runs whose collision "
              "times reject uniformity at α = 0.05 (Clopper–Pearson interval; 0.05 for a "
              "Poisson process); dispersion: variance / mean of the collision counts over ICs "
              "(1 for a Poisson process), with a 95 % bootstrap interval over ICs"
              + ("" if "disp_low" in table else " where the per-IC counts are stored (not "
                 "for this table)") + ".", "",
              "| r1 / r0 | rate / Γ(r0, r1) | KS rejections | dispersion | small disk FTLE, "
              "partner r1 | own-size partner | large disk FTLE, partner r0 | own-size partner |",
              "|---|---|---|---|---|---|---|---|"]
    cols = [("ftle_partner_ratio_disk0", "ftle_partner_low_disk0", "ftle_partner_high_disk0"),
            ("ftle_own_ratio_disk0", "ftle_own_low_disk0", "ftle_own_high_disk0"),
            ("ftle_partner_ratio_disk1", "ftle_partner_low_disk1", "ftle_partner_high_disk1"),
            ("ftle_own_ratio_disk1", "ftle_own_low_disk1", "ftle_own_high_disk1")]

    def cell(row, c):
        return (f"{format_interval(row[c[0]], row[c[1]], row[c[2]])}, "
                f"{ratio_verdict(row[c[1]], row[c[2]], MARGIN)}")

    for _, row in table.iterrows():
        rate = cell(row, ("rate_ratio", "rate_low", "rate_high"))
        ks_lo, ks_hi = _ks_ci(row, args.n_ics)
        disp = (format_interval(row["dispersion_index"], row["disp_low"], row["disp_high"],
                                edges=(1.0,)) if "disp_low" in row else
                f"{row['dispersion_index']:.1f} (no interval)")
        lines.append(f"| {row['size_ratio']:g} | {rate}"
                     f" | {100 * row['ks_reject_share']:.1f} % [{100 * ks_lo:.1f}, "
                     f"{100 * ks_hi:.1f}] | {disp} | "
                     + " | ".join(cell(row, c) for c in cols) + " |")
    lines.append("")
    for c, name in ((("rate_ratio", "rate_low", "rate_high"), "collision rate / kinetic rate"),
                    (cols[0], "small disk, partner of the other disk's size"),
                    (cols[2], "large disk, partner of the other disk's size")):
        v = [ratio_verdict(lo, hi, MARGIN) for lo, hi in zip(table[c[1]], table[c[2]],
                                                             strict=True)]
        counts = pd.Series(v).value_counts()
        odd = [f"ratio {x:g}: {vv}" for x, vv in zip(table["size_ratio"], v, strict=True)
               if vv != counts.index[0]]
        lines.append(f"- {name}: {counts.index[0]} at {counts.iloc[0]} of {len(v)} ratios"
                     + (f" (not at {', '.join(odd)})" if odd else "") + ".")
    lines += ["", "![size ratio](size_ratio/size_ratio.png)", ""]
    Path(page).write_text("\n".join(lines), encoding="utf-8")
    print(f"{page} written")


def _ks_ci(row, n):
    """Clopper-Pearson interval of the KS rejection share over ``n`` runs."""
    from kicktimes.stats.findings import clopper_pearson

    return clopper_pearson(round(row["ks_reject_share"] * n), n)


def figure(table, n_ics=200):
    from matplotlib.figure import Figure

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
    ks = np.array([_ks_ci(row, n_ics) for _, row in table.iterrows()])
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


if __name__ == "__main__":
    main()
