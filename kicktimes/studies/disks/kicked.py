"""docs/results/disks.md: the kicked single disk against the gas, and the gas's FTLE checks.

The page's sections on the paper's question for a gas
(`kicktimes.studies.disks.tables.kicked_table`: one disk of the gas against one disk
kicked with uniform new directions at Poisson times of its rate or at its collision times,
or scattered off virtual partners from the collision kernel at Poisson times) and on the
checks of the gas's FTLE (``disks_ftle_check.csv``, written beside the page by
`kicktimes.studies.disks.ftle_check`) and on its kinetic-theory form against density
(``disks_lyapunov_density*.csv``, by `kicktimes.studies.disks.density`), each rendered when
its table exists.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from kicktimes.experiment.disks_tasks import KICKED_THEILER
from kicktimes.stats import format_interval, ratio_interval, ratio_verdict

__all__ = ["FTLE_CHECK_COLUMNS", "KICKED_NAMES", "RATE_MARGIN", "ftle_check_lines",
           "kicked_answer", "kicked_ftle_cells", "kicked_not_chaotic", "kicked_rate_check",
           "kicked_rate_lines", "kicked_section", "scatter_answer"]

KICKED_NAMES = {"ftle": "FTLE λ", "acf@1": "boundary-angle ACF R₁", "rr": "recurrence rate"}
#: the kicked systems the tables show, in order, with their page names
SYSTEM_NAMES = {"poisson": "Poisson-kicked", "actual": "actual-kicked",
                "scatter": "scatter-kicked"}
#: the columns of disks_ftle_check.csv
FTLE_CHECK_COLUMNS = ("check", "n_disks", "rule", "packing", "n_ics", "t_max", "estimate",
                      "lo", "hi", "margin", "verdict")


#: the margin, stated before the run, within which the kicked comparison's rate must equal
#: the density table's (disks.csv) at every N
RATE_MARGIN = 0.02


def _systems(kicked):
    return [s for s in SYSTEM_NAMES if (kicked["system"] == f"{s}/gas").any()]


def kicked_not_chaotic(kicked, system="poisson"):
    """The N at which a kicked disk's own FTLE has its interval at or below 0."""
    if kicked.empty or "value_high" not in kicked:
        return []
    f = kicked[(kicked["system"] == f"{system}/gas") & (kicked["diagnostic"] == "ftle")]
    return [int(n) for n in f[f["value_high"] <= 0.0]["n_disks"]]


def _ratio_of(row):
    return f"{format_interval(row['ratio'], row['ratio_low'], row['ratio_high'])} {row['verdict']}"


def _kicked_cell(row, diag):
    """A kicked/gas ratio, or "—" where no ratio is meaningful: the gas's mean is
    indistinguishable from 0, the ratio's interval contains 0 (the gas's value too near 0
    for its noise), or (FTLE) the kicked disk's own exponent has its interval at or below 0."""
    gas = format_interval(row["reference"], row["reference_low"], row["reference_high"],
                          edges=(0.0,))
    if row["reference_low"] <= 0.0 <= row["reference_high"]:
        return f"— (gas: {gas})"
    if row["ratio_low"] <= 0.0 <= row["ratio_high"]:
        return f"— (gas near 0: {gas})"
    if diag == "ftle" and "value_low" in row and row["value_low"] <= 0.0:
        return "— (kicked FTLE ≤ 0)"
    if diag == "ftle":
        # a single disk's exponent over the whole gas's largest: not like-for-like, so the
        # ratio is printed and no verdict is read from it
        return format_interval(row["ratio"], row["ratio_low"], row["ratio_high"])
    return _ratio_of(row)


def _per_collision(row):
    return format_interval(row["ratio"], row["ratio_low"], row["ratio_high"], edges=(0.0,))


def _ftle(row):
    return format_interval(row["value"], row["value_low"], row["value_high"], edges=(0.0,))


def _states_words(kicked):
    """The kicked states per N, in words: ``"16"`` or ``"1000 (N = 2) to 16 (N = 1000)"``."""
    f = kicked[(kicked["system"] == "gas/gas") & (kicked["diagnostic"] == "ftle/rate")]
    states = f.set_index("n_disks")["n_runs"].sort_index()
    if states.empty:
        return "0"
    if states.nunique() == 1:
        return str(int(states.iloc[0]))
    return (f"{int(states.iloc[0])} (N = {states.index[0]}) to {int(states.iloc[-1])} "
            f"(N = {states.index[-1]})")


def _method(exp):
    """How the store measured the gas's FTLE, in words (`DisksExperiment.gas_ftle`)."""
    return ("tangent vectors" if exp.gas_ftle == "tangent" else "a Benettin twin")


def _rate_words(exp):
    """What the kicked comparison's rate ν is (`DisksExperiment.kicked_rate`)."""
    if exp.kicked_rate == "gas":
        return ("the whole gas's collision frequency per disk, 2 n_pp / (N T), the rate of "
                "disks.csv")
    return "the followed gas disk's own collisions over T"


def scatter_answer(kicked) -> str:
    """The first screen's sentence on the scatter-kicked disk's FTLE over the gas's."""
    if "scatter" not in _systems(kicked):
        return ""
    k = kicked.set_index(["n_disks", "system", "diagnostic"])
    ns = sorted(set(kicked["n_disks"]))
    cells = [f"N = {n}: " + format_interval(*k.loc[(n, "scatter/gas", "ftle")][
        ["ratio", "ratio_low", "ratio_high"]]) for n in ns]
    bad = kicked_not_chaotic(kicked, "scatter")
    return ("The single disk scattered off virtual partners from the collision kernel, at "
            "Poisson times of the gas's collision rate, has a positive FTLE "
            + (f"at every N but {', '.join(map(str, bad))}" if bad else "at every N")
            + "; its FTLE over the gas's (the whole gas's largest exponent, not a "
            "like-for-like reference, so no verdict is read): " + "; ".join(cells) + ".")


def kicked_answer(kicked, exp) -> list:
    """The answers' paragraph on the kicked comparison."""
    k = kicked.set_index(["n_disks", "system", "diagnostic"])
    ns = sorted(set(kicked["n_disks"]))
    systems = _systems(kicked)

    def side(n):
        return (f"N = {n}: Poisson-kicked {_per_collision(k.loc[(n, 'poisson/gas', 'ftle/rate')])}"
                + (f", scatter-kicked "
                   f"{_per_collision(k.loc[(n, 'scatter/gas', 'ftle/rate')])}"
                   if "scatter" in systems else "")
                + f", gas {_per_collision(k.loc[(n, 'gas/gas', 'ftle/rate')])}")

    check = (" The gas's FTLE at N = 2 against the two-disk simulator's: the dedicated "
             "check's table below (\"The gas's FTLE: tangent vectors against a twin\")."
             if (2, "gas/two_particle", "ftle") in k.index else "")

    def within(diag):
        ok = [n for n in ns if all(
            (n, f"{sy}/gas", diag) in k.index
            and k.loc[(n, f"{sy}/gas", diag), "verdict"] == "within 10 %"
            for sy in systems)]
        return ", ".join(str(n) for n in ok) or "no N"

    names = ", ".join(SYSTEM_NAMES[s] for s in systems)
    return [f"**Does a kicked disk reproduce a gas better than a partner?** ({exp.geometry_label}, "
            f"{exp.rule}; below, \"Does a kicked disk reproduce a gas?\") The FTLE per "
            f"collision of the disk (λ / ν, ν {_rate_words(exp)}), the kicked "
            f"disks' own beside the gas's: {'; '.join(side(n) for n in (ns[0], ns[-1]))}. "
            "The Poisson-kicked FTLE's interval is at or below 0 at "
            + (f"N = {', '.join(str(n) for n in kicked_not_chaotic(kicked))}"
               if kicked_not_chaotic(kicked) else "no N")
            + " (not chaotic; no ratio stated)"
            + ((", the scatter-kicked one's at N = " + ", ".join(
                str(n) for n in kicked_not_chaotic(kicked, "scatter"))
                if kicked_not_chaotic(kicked, "scatter") else
                ", the scatter-kicked one's at no N") if "scatter" in systems else "")
            + ". The gas's reference is the whole gas's largest exponent, which per collision "
            f"grows with N, so a kicked/gas FTLE ratio is not a like-for-like comparison."
            f"{check} Every kicked disk ({names}) is within 10 % of the gas's recurrence "
            f"rate at N = {within('rr')}, and of its boundary-angle ACF R₁ at N = "
            f"{within('acf@1')}. The recurrence rate is weak evidence: for positions drawn "
            "independently and uniformly over the table it is about ε² (the share of the "
            "table within ε of a point), whatever the dynamics, so a rate near the gas's "
            "says that both cover the table alike, not that they move alike.", ""]


def _ftle_table(kicked, systems):
    """Three tables: the FTLE λ, λ per collision (λ / ν) and the kicked/gas FTLE ratio."""
    k = kicked.set_index(["n_disks", "system", "diagnostic"])
    names = [SYSTEM_NAMES[s] for s in systems]
    parts = {"**FTLE λ**": ["gas", *names], "**FTLE per collision, λ / ν**": ["gas", *names],
             "**FTLE λ over the gas's** (no verdict: not like-for-like)": names}
    tables = {t: ["| N | " + " | ".join(h) + " |", "|---|" + "---|" * len(h)]
              for t, h in parts.items()}
    lam, per, ratio = tables.values()
    for n in sorted(set(kicked["n_disks"])):
        g = k.loc[(n, "poisson/gas", "ftle")]
        lam.append("| " + " | ".join(
            [str(n), format_interval(g["reference"], g["reference_low"], g["reference_high"],
                                     edges=(0.0,))]
            + [_ftle(k.loc[(n, f"{s}/gas", "ftle")]) for s in systems]) + " |")
        per.append("| " + " | ".join(
            [str(n), _per_collision(k.loc[(n, "gas/gas", "ftle/rate")])]
            + [_per_collision(k.loc[(n, f"{s}/gas", "ftle/rate")]) for s in systems]) + " |")
        ratio.append("| " + " | ".join(
            [str(n)] + [_kicked_cell(k.loc[(n, f"{s}/gas", "ftle")], "ftle")
                        for s in systems]) + " |")
    out = []
    for title, rows in tables.items():
        out += [title, "", *rows, ""]
    return out


def _other_table(kicked, systems):
    """Two tables, the boundary-angle ACF R₁ and the recurrence rate, kicked over gas."""
    k = kicked.set_index(["n_disks", "system", "diagnostic"])
    out = []
    for d in ("acf@1", "rr"):
        out += [f"**{KICKED_NAMES[d]}, kicked over gas**", "",
                "| N | " + " | ".join(SYSTEM_NAMES[s] for s in systems) + " |",
                "|---|" + "---|" * len(systems)]
        for n in sorted(set(kicked["n_disks"])):
            out.append("| " + " | ".join([str(n)] + [_kicked_cell(k.loc[(n, f"{s}/gas", d)], d)
                                                     for s in systems]) + " |")
        out.append("")
    return out


def kicked_ftle_cells(kicked, n) -> list:
    """The kicked cells at ``n``: the Poisson-kicked disk's FTLE per collision and the
    gas's, both printed (``"Poisson-kicked x [..]; gas y [..]"``, not a ratio), and the
    scatter-kicked/gas FTLE ratio (if it was run; printed without a verdict)."""
    k = kicked.set_index(["n_disks", "system", "diagnostic"])
    out = [f"Poisson-kicked {_per_collision(k.loc[(n, 'poisson/gas', 'ftle/rate')])}; "
           f"gas {_per_collision(k.loc[(n, 'gas/gas', 'ftle/rate')])}"]
    if "scatter" in _systems(kicked):
        out.append(_kicked_cell(k.loc[(n, "scatter/gas", "ftle")], "ftle"))
    return out


def kicked_rate_check(kicked, table, exp) -> pd.DataFrame:
    """The kicked comparison's rate against the density table's, N by N.

    The Poisson and scatter kicks, and λ / ν, use the kicked states' own gas collision
    frequency (`DisksExperiment.kicked_rate`); the density table (``disks.csv``) measures
    the same gas (N, packing, rule) in independent runs. Their ratio's 95 % interval
    combines the two intervals (`kicktimes.stats.ratio_interval`: independent seeds) and
    gets `kicktimes.stats.ratio_verdict` at `RATE_MARGIN`.

    Parameters
    ----------
    kicked : DataFrame
        `kicktimes.studies.disks.tables.kicked_table` (its ``gas/gas``, ``ftle/rate`` rows
        carry the kicks' rate as ``reference``).
    table : DataFrame
        `kicktimes.studies.disks.tables.disks_table` rows (``disks.csv``).
    exp : DisksExperiment
        The kicked store's experiment: its rule and geometry pick the density rows.

    Returns
    -------
    DataFrame
        One row per N: ``n_disks``, ``states``, ``kicked_rate`` (``_low``, ``_high``),
        ``density_rate`` (``_low``, ``_high``), ``ratio`` (``_low``, ``_high``),
        ``verdict``. Empty when disks.csv has no sweep of the same gas.
    """
    k = kicked[(kicked["system"] == "gas/gas") & (kicked["diagnostic"] == "ftle/rate")]
    d = table[(table["rule"] == exp.rule) & (table["geometry"] == exp.geometry_label)]
    d = d.drop_duplicates("n_disks").set_index("n_disks")
    rows = []
    for _, row in k.iterrows():
        n = int(row["n_disks"])
        if n not in d.index:
            continue
        dens = d.loc[n]
        rate = float(dens["rate"])
        low, high = (float(dens["rate_enskog_low"] * dens["enskog"]),
                     float(dens["rate_enskog_high"] * dens["enskog"]))
        ratio, r_low, r_high = ratio_interval(row["reference"], row["reference_low"],
                                              row["reference_high"], rate, low, high)
        rows.append({"n_disks": n, "states": int(row["n_runs"]),
                     "kicked_rate": row["reference"], "kicked_rate_low": row["reference_low"],
                     "kicked_rate_high": row["reference_high"], "density_rate": rate,
                     "density_rate_low": low, "density_rate_high": high, "ratio": ratio,
                     "ratio_low": r_low, "ratio_high": r_high,
                     "verdict": ratio_verdict(r_low, r_high, tolerance=RATE_MARGIN)})
    return pd.DataFrame(rows)


def kicked_rate_lines(check) -> list:
    """The kicked section's table of `kicked_rate_check`, and one sentence reading it."""
    if check.empty:
        return []
    off = check[np.abs(check["ratio"] - 1.0) > RATE_MARGIN]["n_disks"].tolist()
    within = check[check["verdict"] == f"within {100 * RATE_MARGIN:g} %"]["n_disks"].tolist()
    lines = ["**The kicks' rate against the density table's** "
             "([disks_kicked_rate.csv](disks_kicked_rate.csv); the same gas in independent "
             f"runs; margin {100 * RATE_MARGIN:g} %, stated before the run)", "",
             "| N | states | kicks' rate | disks.csv | ratio |", "|---|---|---|---|---|"]
    for _, r in check.iterrows():
        kicked, density, ratio = (format_interval(r[c], r[f"{c}_low"], r[f"{c}_high"])
                                  for c in ("kicked_rate", "density_rate", "ratio"))
        lines.append(f"| {r['n_disks']} | {r['states']} | {kicked} | {density} | {ratio} "
                     f"{r['verdict']} |")
    lines += ["", ("The ratio's estimate is within "
                   f"{100 * RATE_MARGIN:g} % at every N" if not off else
                   f"The ratio's estimate is more than {100 * RATE_MARGIN:g} % from 1 at N = "
                   + ", ".join(map(str, off)))
              + "; its interval lies inside the margin at N = "
              + (", ".join(map(str, within)) or "no N")
              + (" (elsewhere the two rates' noise is wider than the margin: a state's rate "
                 "varies most among few disks)" if len(within) < len(check) else "") + ".", ""]
    return lines


def kicked_section(kicked, exp, rate_check=None) -> list:
    """The section "Does a kicked disk reproduce a gas?"."""
    systems = _systems(kicked)
    scatter = (
        " The scatter-kicked disk (system scatter) is kicked at Poisson times of the same "
        "rate, each kick a mirror collision with a virtual partner of the gas's radius "
        "(`kick_angle=\"scatter\"`, `partner=\"weighted\"`, `rule=\"mirror\"`; "
        "docs/scatter.md): the partner's direction at angle D from the disk's with density "
        "∝ |v − u| ∝ |sin(D/2)|, the contact normal at angle φ from v − u with density "
        "cos φ / 2. In a mirror gas every disk has unit speed and, at equilibrium, a uniform "
        "direction, so a collision's pre-collision pair (v, u, n) has density ∝ (w·n)⁺ "
        "(kinetic theory, molecular chaos): the scatter kick draws the gas's collision "
        "kernel, as `kicktimes.billiard.scatter` documents. What it leaves out: correlations "
        "between successive partners (recollisions, the dense gas's ring events), the "
        "density's variation near the wall (Enskog's contact factor sets the gas's rate, "
        "which the kicks take from the gas disk, not the kernel's shape), and it allows a "
        "virtual partner beyond the wall." if "scatter" in systems else "")
    return [
        "## Does a kicked disk reproduce a gas?", "",
        f"The paper's question for a gas ({exp.geometry_label}, {exp.rule} rule; store "
        f"`{exp.name}`): one disk of a gas, followed for {exp.kicked_time:g} mean free "
        f"times in {_states_words(kicked)} states per N, against one disk from its initial state "
        f"kicked with uniform new directions at Poisson times of ν, {_rate_words(exp)} "
        "(poisson), or at its "
        f"collision times (actual).{scatter} The gas's FTLE is the whole gas's largest "
        f"exponent (`disks_lyapunov`, {_method(exp)}, renormalised every mean free time); "
        "the kicked disk's "
        "from tangent vectors; the ACF is of the disk's boundary angles θ (lag 1), the "
        "recurrence rate of its positions sampled every 0.1 mean free times at ε = 0.05, "
        f"pairs less than {KICKED_THEILER / 10:g} mean free times apart left out (a "
        f"Theiler window of {KICKED_THEILER} samples: the diagonal and one flight's "
        "successive samples would make every system's rate alike); "
        "λ / ν is an FTLE over that ν (at fixed packing the reduced "
        "density ñ = n σ² is the same for every N; the comparison with the kinetic theory "
        "of the largest exponent, van Zon, van Beijeren & Dellago 1998, is not made here). "
        "Ratios of the means over states, 95 % percentile bootstrap over states, "
        "`ratio_verdict` (within 10 %; the FTLE ratios get none); —: no ratio is stated "
        "where the gas's mean is "
        "indistinguishable from 0, where the ratio's interval contains 0 (the gas's value "
        "too near 0 for its noise), or, for the FTLE, where the kicked disk's own exponent "
        "has its interval at or below 0 (not chaotic). The gas's FTLE is the whole gas's "
        "largest exponent, whose value per collision grows with N: a kicked/gas FTLE ratio "
        "is not a like-for-like comparison (a single disk's exponent against an N-disk "
        "system's). An ACF needs enough wall hits: at large N the disk seldom reaches the "
        "wall in this time, and states without a value are left out "
        "([disks_kicked.csv](disks_kicked.csv), column n_runs).", "",
        *(kicked_rate_lines(rate_check) if rate_check is not None else []),
        *_ftle_table(kicked, systems),
        *_other_table(kicked, systems)]


def ftle_check_lines(path) -> list:
    """The section on the gas's FTLE checks from ``disks_ftle_check.csv`` (columns
    `FTLE_CHECK_COLUMNS`), each verdict recomputed (`kicktimes.stats.ratio_verdict` at the
    row's margin; the file's own word shown beside it where it differs); one line saying it
    is absent if ``path`` does not exist.

    Examples
    --------
    >>> ftle_check_lines("/nonexistent/disks_ftle_check.csv")[-2].startswith("Not run")
    True
    """
    title = ["## The gas's FTLE: tangent vectors against a twin, and N = 2 against the "
             "two-disk simulator", ""]
    path = Path(path)
    if not path.exists():
        return title + [f"Not run here: no {path.name} beside the page "
                        "(`kicktimes.studies.disks.ftle_check.write_ftle_check` writes it).",
                        ""]
    tab = pd.read_csv(path)
    missing = [c for c in FTLE_CHECK_COLUMNS if c not in tab.columns]
    if missing:
        raise ValueError(f"{path.name}: missing columns {missing}")
    out = title + [
        f"From [{path.name}]({path.name}): each check's ratio (tangent over twin FTLE of the "
        "same gas states; the engine's N = 2 FTLE over the two-disk simulator's) with its "
        "95 % interval, and its verdict at the check's margin, stated in advance "
        "(`stats.ratio_verdict` with that tolerance: within when the whole interval lies "
        "in [1 − margin, 1 + margin]).", "",
        "| check (packing) | N | rule | states | t_max | ratio | margin | verdict |",
        "|---|---|---|---|---|---|---|---|"]
    for _, r in tab.iterrows():
        m = float(r["margin"])
        verdict = ratio_verdict(r["lo"], r["hi"], tolerance=m)
        if str(r["verdict"]) != verdict:
            # the page's verdict is the rule's; the file's other wording is shown beside it
            verdict += f" (the file: {r['verdict']})"
        out.append(f"| {r['check']} ({r['packing']:g}) | {int(r['n_disks'])} | {r['rule']} | "
                   f"{int(r['n_ics'])} | {r['t_max']:g} | "
                   f"{format_interval(r['estimate'], r['lo'], r['hi'], edges=(1 - m, 1, 1 + m))}"
                   f" | {m:g} | {verdict} |")
    return out + [""]


def density_form_reading(c_low, c_high, local_verdicts, margin) -> str:
    """The reading of the kinetic-theory form from the curvature ``c``'s interval and the
    local slopes' `ratio_verdict` words: curvature detected (``c``'s interval excludes 0),
    the form holds (no curvature and every local slope within ``margin`` of ``b``), or
    inconclusive.

    Examples
    --------
    >>> density_form_reading(0.1, 0.3, ["within 10 %"], 0.1)[:18]
    'curvature detected'
    """
    if not c_low <= 0.0 <= c_high:
        return "curvature detected: λ/ν is not linear in ln(1/ñ) over this range"
    if all(v.startswith("within") for v in local_verdicts):
        return (f"no curvature detected and every local slope within {margin * 100:g} % of "
                "b: the form holds over this range")
    return "inconclusive"


def density_lines(table_path, fit_path) -> list:
    """The section on the gas's FTLE against density (the kinetic-theory form
    ``λ/ν = a + b ln(1/ñ)``) from ``disks_lyapunov_density.csv`` and its ``_fit.csv``
    (`kicktimes.studies.disks.density`); each local slope's verdict recomputed
    (`kicktimes.stats.ratio_verdict` at the file's margin); one line if a file is absent.

    Examples
    --------
    >>> density_lines("/nonexistent/a.csv", "/nonexistent/b.csv")[-2].startswith("Not run")
    True
    """
    title = ["## The gas's FTLE against density: the kinetic-theory form", ""]
    table_path, fit_path = Path(table_path), Path(fit_path)
    if not (table_path.exists() and fit_path.exists()):
        return title + [f"Not run here: no {table_path.name} and {fit_path.name} beside the "
                        "page (`kicktimes.studies.disks.density.write_lyapunov_density` "
                        "writes them).", ""]
    tab, fits = pd.read_csv(table_path), pd.read_csv(fit_path)
    out = title + [
        "Kinetic theory gives a dilute gas's largest exponent per collision as linear in the "
        "logarithm of the reduced density, λ/ν = a + b ln(1/ñ), ñ = nσ² = 4φ/π in the unit "
        "table (van Zon, van Beijeren & Dellago, Phys. Rev. Lett. 80, 2035 (1998), with "
        "corrections of order ñ and a slow growth with N). Measured with tangent vectors "
        "(`disks_lyapunov`, mirror rule), ν each run's own collision rate per disk; 95 % "
        f"bootstrap over states ([{table_path.name}]({table_path.name}), "
        f"[{fit_path.name}]({fit_path.name})). The prefactors a and b of the theory are not "
        "computed here: only the form is tested, by the curvature c of a quadratic fit and "
        "by each local slope over b, within the margin stated before the run.", "",
        "| N | packing φ | ñ | ln(1/ñ) | states | λ / ν |", "|---|---|---|---|---|---|"]
    for _, r in tab.iterrows():
        out.append(f"| {int(r['n_disks'])} | {r['packing']:g} | {r['reduced_density']:.3g} | "
                   f"{r['ln_inv_density']:.3g} | {int(r['n_states'])} | "
                   f"{format_interval(r['lam_per_coll'], r['lo'], r['hi'])} |")
    out.append("")
    for _, f in fits.iterrows():
        m = float(f["margin"])
        local = [(float(e), float(lo), float(hi)) for e, lo, hi in zip(
            str(f["local_over_b"]).split(";"), str(f["local_lo"]).split(";"),
            str(f["local_hi"]).split(";"), strict=True)]
        verdicts = [ratio_verdict(lo, hi, tolerance=m) for _, lo, hi in local]
        reading = density_form_reading(f["c_lo"], f["c_hi"], verdicts, m)
        reading = reading[0].upper() + reading[1:]
        out.append(
            f"- N = {int(f['n_disks'])}, fitted at φ ≤ {f['fit_max_packing']:g}: "
            f"a = {format_interval(f['a'], f['a_lo'], f['a_hi'])}, "
            f"b = {format_interval(f['b'], f['b_lo'], f['b_hi'])}, curvature "
            f"c = {format_interval(f['c'], f['c_lo'], f['c_hi'], edges=(0.0,))}; local "
            "slopes over b, from dilute to dense: " + "; ".join(
                f"{format_interval(e, lo, hi, edges=(1 - m, 1, 1 + m))} {v}"
                for (e, lo, hi), v in zip(local, verdicts, strict=True)) + f". {reading}.")
    return out + [*_slopes_across_n(fits), ""]


def _slopes_across_n(fits) -> list:
    """The fitted slopes b at consecutive N compared: disjoint 95 % intervals are a
    difference, overlapping ones are not resolved (overlap is no agreement)."""
    fits = fits.sort_values("n_disks")
    out = []
    for (_, f0), (_, f1) in zip(fits.iloc[:-1].iterrows(), fits.iloc[1:].iterrows(),
                                strict=True):
        n0, n1 = int(f0["n_disks"]), int(f1["n_disks"])
        b0 = format_interval(f0["b"], f0["b_lo"], f0["b_hi"])
        b1 = format_interval(f1["b"], f1["b_lo"], f1["b_hi"])
        if f0["b_hi"] < f1["b_lo"] or f1["b_hi"] < f0["b_lo"]:
            side = "higher" if f1["b"] > f0["b"] else "lower"
            out.append(f"- The slope b at N = {n0} ({b0}) and at N = {n1} ({b1}): disjoint "
                       f"intervals, so b differs; it is {side} at N = {n1}. The theory's "
                       "form has no N in b; its corrections grow slowly with N (van Zon, van "
                       "Beijeren & Dellago 1998), and the table's wall is another N-dependent "
                       "effect: the difference is not decomposed here.")
        else:
            out.append(f"- The slope b at N = {n0} ({b0}) and at N = {n1} ({b1}): the "
                       "intervals overlap, so the difference is not resolved (no equivalence "
                       "test is made).")
    return out
