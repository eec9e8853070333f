"""Specification of the report's section modules on a synthetic store with the new rows
(RR/off-diagonal RR/DET at several eps, ACF curves, stretching per perturbation) and of
the effect sizes and verdict rules of the Findings."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from kicktimes import stats
from kicktimes.render.figures import system_label
from kicktimes.report import autocorrelation, counts, findings, lyapunov, recurrence, summary
from kicktimes.report.context import Context
from kicktimes.stats import clopper_pearson, paired_ratio, ratio_verdict, share_verdict

RADII = (0.008, 0.014, 0.02)
EPS = (0.001, 0.01)
LAGS = 6
SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter")


def synthetic_store(n_ics=16, seed=0, sticky=(0.014, 3)):
    """Tidy rows as the sweep writes them (store contract of H4/H1), with known effects:
    kicked FTLE = 1/3 of the two-particle FTLE, DET identical in 'actual', off-diagonal RR
    1.5x in 'poisson'; one sticky IC (collision rate 20x kinetic)."""
    rng = np.random.default_rng(seed)
    rows, coll = [], []
    t = 1000.0
    for r in RADII:
        gamma = float(stats.kinetic_rate(r))
        for ic in range(n_ics):
            n_pp = rng.poisson(gamma * t) + 1
            if (r, ic) == sticky:
                n_pp = int(20 * gamma * t)
            coll.append((r, ic, t, n_pp, np.sort(rng.uniform(0, t, n_pp))))
            lam2 = 0.1 * (1 + 10 * r) * rng.lognormal(0, 0.1)
            det2 = rng.uniform(0.2, 0.4)
            off2 = 1e-5 * rng.lognormal(0, 0.2)
            for system in SYSTEMS:
                n = n_pp
                lam = lam2 if system == "two_particle" else lam2 / 3
                add = [("t_max", t), ("n_boundary", 500.0)]
                add.append(("n_pp" if system == "two_particle" else "n_kicks", float(n)))
                add += [("lyapunov", lam), ("lyapunov_per_perturbation", lam * t / n)]
                for e in EPS:
                    off = off2 * (1.5 if system == "poisson" else 1.0) * (10 if e > 0.005 else 1)
                    nn = 3001
                    add += [
                        (f"rr@{e:g}", (1 + (nn - 1) * off) / nn),
                        (f"rr_offdiag@{e:g}", off),
                        (f"det@{e:g}", det2),
                        (f"l_mean@{e:g}", 2.5),
                        (f"l_max@{e:g}", 7.0),
                    ]
                # the paper's RR at eps[0], as the old row
                add.append(("recurrence_rate", dict(add)[f"rr@{EPS[0]:g}"]))
                r1 = 1 - n / 500.0
                add += [(f"acf@{lag}", r1**lag) for lag in range(1, LAGS + 1)]
                add += [("autocorrelation", r1), ("decorrelation_lag", np.nan), ("tau_int", 9.0)]
                rows += [(r, ic, system, d, float(v), "") for d, v in add]
    results = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value", "note"])
    collisions = pd.DataFrame(coll, columns=["radius", "ic", "t_window", "n_pp", "pp_times"])
    exp = SimpleNamespace(
        name="synthetic",
        radii=list(RADII),
        n_ics=n_ics,
        n_steps=3000,
        tau=0.3,
        seed=5,
        sampling="paper",
        rr_sampling="run",
        rule="mirror",
        eps=EPS,
        lag=1,
        ic_method="paper",
        lyapunov_variant="tangent",
    )
    return SimpleNamespace(experiment=exp, results=results, collisions=collisions)


@pytest.fixture(scope="module")
def ctx():
    context = Context(synthetic_store(), n_boot=300)
    context.sections = {}
    for module in (counts, summary, lyapunov, recurrence, autocorrelation):
        context.sections[module.__name__.rsplit(".", 1)[1]] = module.sections(context)
    context.findings = findings.section(context)
    return context


def _effect(ctx, question, system):
    matches = [e for e in ctx.found.effects if e.question == question and e.system == system]
    assert len(matches) == 1, (question, system)
    return matches[0]


# ------------------------------------------------------------------- effect sizes


def test_ratio_verdict_follows_the_printed_rule():
    assert ratio_verdict(0.91, 1.09) == "within 10 %"
    assert ratio_verdict(0.2, 0.89) == "lower" and ratio_verdict(1.11, 3.0) == "higher"
    assert ratio_verdict(0.85, 1.05) == "inconclusive"
    assert ratio_verdict(np.nan, 1.0) == "inconclusive"
    assert ratio_verdict(0.75, 1.2, tolerance=0.25) == "within 25 %"


def test_share_verdict_and_clopper_pearson():
    low, high = clopper_pearson(30, 100)
    assert low < 0.3 < high and share_verdict(low, high, level=0.05) == "above"
    assert share_verdict(*clopper_pearson(5, 100), level=0.05) == "inconclusive"
    assert clopper_pearson(0, 10)[0] == 0.0 and clopper_pearson(10, 10)[1] == 1.0


def test_paired_ratio_covers_the_true_ratio_and_is_seeded():
    idx = pd.MultiIndex.from_product([[0.01, 0.02], range(200)], names=["radius", "ic"])
    rng = np.random.default_rng(0)
    y = pd.Series(rng.lognormal(0, 0.5, idx.size), index=idx)
    x = 0.7 * y * rng.lognormal(0, 0.3, idx.size) / np.exp(0.045)  # E[x/y] = 0.7
    a = paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=500)
    b = paired_ratio(x, y, rng=np.random.default_rng(1), n_boot=500)
    assert a[1] == b[1]
    assert a[1]["ci_low"] < 0.7 < a[1]["ci_high"]
    assert a[1]["ci_high"] - a[1]["ci_low"] < 0.2
    assert list(a[0]["n_pairs"]) == [200, 200]


def test_paired_ratio_shares_its_resamples_between_calls():
    # the Findings draw the bootstrap once per store: a second ratio over as many ICs
    # reuses the first call's resamples, and gets the CI a fresh draw from the same stream
    # would give it
    idx = pd.MultiIndex.from_product([[0.01, 0.02], range(50)], names=["radius", "ic"])
    rng = np.random.default_rng(4)
    y = pd.Series(rng.lognormal(0, 0.5, idx.size), index=idx)
    x, z = 0.5 * y * rng.lognormal(0, 0.2, idx.size), y * rng.lognormal(0, 0.4, idx.size)
    shared = {}
    paired_ratio(x, y, rng=np.random.default_rng(9), n_boot=300, resamples=shared)
    assert list(shared) == [(50, 300)] and shared[(50, 300)].sum(axis=1).tolist() == [50] * 300
    # the stream is no longer read: any generator gives the shared resamples' CI
    second = paired_ratio(z, y, rng=np.random.default_rng(123), n_boot=300, resamples=shared)
    alone = paired_ratio(z, y, rng=np.random.default_rng(9), n_boot=300)
    assert second[1] == alone[1]
    pd.testing.assert_frame_equal(second[0], alone[0])
    # another number of ICs or of resamples draws (and keeps) its own
    paired_ratio(x, y, rng=np.random.default_rng(9), n_boot=100, resamples=shared)
    assert sorted(shared) == [(50, 100), (50, 300)]
    with pytest.raises(TypeError, match="resamples must be None or a dict"):
        paired_ratio(x, y, rng=np.random.default_rng(9), resamples=[])


def test_paired_ratio_skips_pairs_with_a_missing_value():
    idx = pd.MultiIndex.from_product([[0.01], range(4)], names=["radius", "ic"])
    x = pd.Series([1.0, 2.0, np.nan, 4.0], index=idx)
    y = pd.Series([1.0, 1.0, 100.0, 2.0], index=idx)
    per_radius, overall = paired_ratio(x, y, rng=np.random.default_rng(0), n_boot=100)
    assert per_radius.loc[0, "n_pairs"] == 3
    assert overall["ratio"] == pytest.approx(7.0 / 4.0)


# ------------------------------------------------------------------- sections


def test_findings_compare_every_kicked_system_including_new_ones(ctx):
    systems = {e.system for e in ctx.found.effects if e.system}
    assert systems == {"poisson", "actual", "poisson_scatter"}


def test_ftle_finding_recovers_the_built_in_third_and_says_lower(ctx):
    e = _effect(ctx, "FTLE", "poisson")
    assert e.estimate == pytest.approx(1 / 3, rel=1e-9)
    assert e.verdict == "lower"
    assert "stretching per perturbation" in e.detail


def test_recurrence_findings_at_every_eps_off_diagonal_and_det(ctx):
    for eps in ("0.001", "0.01"):
        off = _effect(ctx, f"Off-diagonal RR (ε = {eps})", "poisson")
        assert off.estimate == pytest.approx(1.5, rel=1e-9) and off.verdict == "higher"
        det = _effect(ctx, f"DET (ε = {eps})", "actual")
        assert det.estimate == pytest.approx(1.0) and det.verdict == "within 10 %"


def test_acf_finding_is_marked_built_in(ctx):
    e = _effect(ctx, "Lag-1 ACF of boundary angles", "actual")
    assert e.verdict.startswith("within 10 %") and "built in" in e.verdict
    assert "rate-matching prediction" in e.detail


def test_recurrence_figure_has_a_row_per_eps_and_rr_offdiag_det_columns(ctx):
    (sec,) = ctx.sections["recurrence"]
    name, fig, caption = sec.figures[0]
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == len(EPS) * 3
    titles = [ax.get_title() for ax in axes]
    assert any("off-diagonal" in t and "ε = 0.01" in t for t in titles)
    assert any(t.startswith("DET") for t in titles)
    rr_axes = [ax for ax in axes if ax.get_title().startswith("paper's RR")]
    assert all(ax.get_ylim()[0] == 0 for ax in rr_axes)  # no zoom into 1 % of 1/N
    assert "1/N" in caption and "collision-truncated" in caption


def _with_uniform(store):
    res = store.results
    rec = res[res["diagnostic"].str.match(r"^(rr|rr_offdiag|det)@")]
    uni = rec.assign(diagnostic="uniform_" + rec["diagnostic"].astype(str),
                     value=rec["value"] * 2)
    store.results = pd.concat([res, uni], ignore_index=True)
    return store


def test_recurrence_figure_puts_the_uniform_samples_first_and_the_run_as_control():
    store = _with_uniform(synthetic_store(n_ics=6))
    rows, _ = recurrence.recurrence_rows(store.results, store.experiment)
    assert "uniform_rr_offdiag@0.001" in set(rows["diagnostic"])
    fig = recurrence.rr_figure(rows, store.experiment)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    # the uniform-time DET in two panels (uniform-angle, scattering kicks): 6 columns
    assert len(axes) == len(EPS) * 6
    titles = [ax.get_title() for ax in axes[:6]]
    assert "uniform-time samples" in titles[0] and titles[0].startswith("off-diagonal")
    assert "uniform-time samples" in titles[1] and titles[1].startswith("DET")
    assert titles[1].endswith("uniform kick angles")
    assert titles[2].startswith("DET") and titles[2].endswith("scattering kick angles")
    assert all("control" in t for t in titles[3:])
    assert axes[1].get_ylim() == axes[2].get_ylim()  # read side by side
    # each split panel: the two-disk billiard beside its group's systems
    shown = {1: ["Two-particle", "Poisson", "Actual"], 2: ["Two-particle", "Poisson, scatter"]}
    assert fig.get_size_inches()[0] <= 3 * 4.6 + 0.01  # at most three panels a row
    for k, ax in enumerate(axes):
        offdiag = ax.get_title().startswith("off-diagonal")
        # every axis from 0 but the off-diagonal RR's, which sits near its data and its
        # guide eps^2 / (1 - r)^2 (a dotted line; no other panel has one)
        assert (ax.get_ylim()[0] > 0) if offdiag else (ax.get_ylim()[0] == 0)
        dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
        assert len(dotted) == (1 if offdiag else 0)
        # one series per system (mean with bars): no more than the systems
        labels = shown.get(k % 6, [system_label(s) for s in SYSTEMS])
        assert len(ax.containers) == 2 * len(labels)
        assert [c.get_label() for c in ax.containers[1::2]] == labels


def test_recurrence_figure_counts_the_means_above_the_axis():
    store = synthetic_store(n_ics=6)
    res = store.results
    far = (res["radius"] == 0.014) & (res["system"] == "actual") & (
        res["diagnostic"] == "rr_offdiag@0.001")
    store.results = res.assign(value=np.where(far, 1.0, res["value"]))
    rows, _ = recurrence.recurrence_rows(store.results, store.experiment)
    fig = recurrence.rr_figure(rows, store.experiment)
    (ax,) = [ax for ax in fig.axes if ax.get_title().startswith("off-diagonal RR (pairs i ≠ j)"
                                                                 ", ε = 0.001")]
    assert "1 mean(s) above the axis (r = 0.014: 1)" in ax.get_title()
    assert 0 < ax.get_ylim()[0] and ax.get_ylim()[1] < 1.0
    # a mean a little above the rest, from 0 no outlier, is drawn inside the axis
    near = res["value"].where(~far, 2 * res.loc[far, "value"].max())
    store.results = res.assign(value=near)
    rows, _ = recurrence.recurrence_rows(store.results, store.experiment)
    fig = recurrence.rr_figure(rows, store.experiment)
    (ax,) = [ax for ax in fig.axes if ax.get_title().startswith("off-diagonal RR (pairs i ≠ j)"
                                                                 ", ε = 0.001")]
    assert "above the axis" not in ax.get_title()
    assert ax.get_ylim()[1] > 2 * res.loc[far, "value"].max()
    assert not [t for t in ax.texts if t.get_text().endswith("↑")]


def test_shared_peaks_name_the_radii_where_every_system_peaks_and_the_caption_says_so():
    store = _with_uniform(synthetic_store(n_ics=6))
    res = store.results
    bump = (res["radius"] == 0.014) & (res["diagnostic"] == "uniform_det@0.01")
    store.results = res.assign(value=np.where(bump, res["value"] + 5.0, res["value"]))
    rows, _ = recurrence.recurrence_rows(store.results, store.experiment)
    part = summary.diagnostic_summary(rows)
    assert recurrence.shared_peaks(part, "uniform_det@0.01") == [0.014]
    # one system without the peak: none shared
    one = bump & (store.results["system"] == "poisson")
    lower = store.results.assign(value=np.where(one, -1.0, store.results["value"]))
    rows_low, _ = recurrence.recurrence_rows(lower, store.experiment)
    assert recurrence.shared_peaks(summary.diagnostic_summary(rows_low),
                                   "uniform_det@0.01") == []
    caption = recurrence._peaks_note(rows, store.experiment)
    assert "ε = 0.01: r = 0.014" in caption and "by inference" in caption
    # the control, computed the same way on the run's own samples
    own = recurrence.shared_peaks(part, "det@0.01")
    assert "have shared local maxima at" in caption
    assert ("ε = 0.01: " + (", ".join(f"r = {r:g}" for r in own) or "none")) in caption


def test_family_figure_has_one_row_per_store_with_uniform_samples_where_present():
    a = _with_uniform(synthetic_store(n_ics=6))
    b = synthetic_store(n_ics=6, seed=1)
    b.experiment = SimpleNamespace(**{**vars(b.experiment), "name": "family_b"})
    a.experiment.name = "family_a"
    fig, caption = recurrence.family_figure([a, b])
    grid = np.array(fig.axes).reshape(2, 3)
    assert [ax.get_title().split(":")[0] for ax in grid[:, 0]] == ["family_a", "family_b"]
    assert "uniform-time samples" in grid[0, 0].get_title()
    assert grid[0, 0].containers and not grid[1, 0].containers  # b has no uniform rows
    assert any("not in the store" in t.get_text() for t in grid[1, 0].texts)
    assert all(ax.containers for ax in grid[:, 1:].ravel())
    assert "family_a" in caption and "family_b" in caption


def test_recurrence_table_gives_medians_and_flags_the_sticky_ic(ctx):
    (sec,) = ctx.sections["recurrence"]
    table = {name: df for name, df, _, _ in sec.tables}["recurrence_by_radius"]
    assert {"mean", "median", "n_sticky", "mean_without_sticky"} <= set(table.columns)
    sticky = table[(table["radius"] == 0.014) & (table["system"] == "two_particle")]
    assert (sticky["n_sticky"] == 1).all()
    assert (table.loc[table["radius"] != 0.014, "n_sticky"] == 0).all()


def test_sticky_ics_are_those_above_five_times_the_kinetic_rate():
    store = synthetic_store()
    flags = counts.sticky_ics(store.collisions, "mirror")
    assert flags["sticky"].sum() == 1
    assert flags.loc[flags["sticky"], ["radius", "ic"]].values.tolist() == [[0.014, 3]]


def test_acf_curves_figure_draws_each_radius_with_the_prediction(ctx):
    (sec,) = ctx.sections["autocorrelation"]
    names = [name for name, _, _ in sec.figures]
    assert names == ["fig07_autocorrelation_vs_radius", "fig07b_autocorrelation_curves"]
    fig = sec.figures[1][1]
    axes = [ax for ax in fig.axes if ax.get_visible()]
    titles = [ax.get_title() for ax in axes]
    # a column per radius; rows: the curves of the uniform-kick, then of the scatter-kick
    # systems (each with the two-disk curve), then their differences to two disks
    groups = ("uniform kicks", "scatter kicks")
    assert titles == [f"r = {r:g}, {g}" for g in groups for r in RADII] + [
        f"r = {r:g}: kicked − two-disk, {g}" for g in groups for r in RADII]
    # at most four curves a panel (seven systems on one panel could not be told apart)
    assert max(len(ax.get_lines()) for ax in axes) <= 4 + 4 + 1  # curves, predictions, 1/e
    scatter_row = axes[len(RADII):2 * len(RADII)]
    labels = {line.get_label() for ax in scatter_row for line in ax.get_lines()}
    assert system_label("poisson_scatter") in labels and system_label("poisson") not in labels
    assert "95 %" in sec.figures[1][2] and "95 %" in sec.figures[0][2]
    table = {name: df for name, df, _, _ in sec.tables}["autocorrelation_summary"]
    assert np.allclose(table["R1_mean"], table["predicted_lag1"])
    assert (table["decorrelation_lag_n_undefined"] == 16).all()



def test_acf_intervals_are_95_percent_t_intervals_and_crossings_are_found():
    curves = pd.DataFrame({
        "radius": 0.01, "system": ["two_particle"] * 3 + ["poisson"] * 3, "lag": [1, 2, 3] * 2,
        "mean": [0.9, 0.8, 0.7, 0.85, 0.8, 0.75], "sem": 0.01, "count": 10,
    })
    half = autocorrelation.half_width95(curves["sem"], curves["count"])
    assert half == pytest.approx(0.01 * 2.2621571627, rel=1e-9)  # t_{0.975, 9}
    diff = autocorrelation.acf_differences(curves)
    assert diff["difference"].tolist() == pytest.approx([-0.05, 0.0, 0.05])
    assert diff["ci95"].to_numpy() == pytest.approx(np.hypot(0.01, 0.01) * 2.2621571627)
    (row,) = autocorrelation.crossings(diff).itertuples()
    assert row.crosses and row.clear and row.sign_lag1 == -1 and row.first_lag_other_sign == 3


def test_lag1_figure_draws_95_percent_intervals(ctx):
    (sec,) = ctx.sections["autocorrelation"]
    ax, ax_ratio = sec.figures[0][1].axes
    part = summary.diagnostic_summary(ctx.results, diagnostic="autocorrelation")
    two = part[part["system"] == "two_particle"].sort_values("radius")
    bars = ax.containers[0].lines[2][0].get_segments()
    half = [(seg[1][1] - seg[0][1]) / 2 for seg in bars]
    assert half == pytest.approx(autocorrelation.half_width95(two["sem"], two["n_valid"]))
    assert all(c.lines[2] for c in ax_ratio.containers)  # the ratios have intervals too
    # the ratios' intervals: the findings tables' bootstrap over paired ICs, not the delta
    # method of independent samples
    ratios = autocorrelation.lag1_ratios(ctx).query("system == 'poisson'").sort_values("radius")
    (poisson,) = [c for c in ax_ratio.containers
                  if c.lines[0].get_color() == ax.containers[1].lines[0].get_color()]
    segments = poisson.lines[2][0].get_segments()
    assert [seg[0][1] for seg in segments] == pytest.approx(ratios["ci_low"].to_list())
    assert [seg[1][1] for seg in segments] == pytest.approx(ratios["ci_high"].to_list())
    assert "ICs resampled in pairs" in ax_ratio.get_title()
    assert "stay paired" in sec.figures[0][2]


def test_acf_paired_differences_keep_the_covariance_of_a_shared_ic():
    # a large IC effect shared by both systems: independent intervals are wide, paired narrow
    rng = np.random.default_rng(0)
    base = rng.uniform(0.3, 0.9, 40)
    rows = pd.concat([
        pd.DataFrame({"radius": 0.01, "ic": np.arange(40), "system": system,
                      "diagnostic": "acf@1", "value": base + shift + rng.normal(0, 1e-3, 40)})
        for system, shift in (("two_particle", 0.0), ("poisson", 0.01))
    ], ignore_index=True)
    paired = autocorrelation.acf_paired_differences(rows)
    independent = autocorrelation.acf_differences(autocorrelation.acf_curves(rows))
    assert paired["difference"].iloc[0] == pytest.approx(independent["difference"].iloc[0])
    assert paired["n_pairs"].iloc[0] == 40
    assert paired["ci95"].iloc[0] < independent["ci95"].iloc[0] / 20
    assert paired["ci95"].iloc[0] < 0.01  # the shift is resolved only by the pairing
    # one IC missing in one system: that pair is left out
    paired = autocorrelation.acf_paired_differences(rows.drop(index=0))
    assert paired["n_pairs"].iloc[0] == 39


def test_a_store_with_r1_only_has_no_curve_decorrelation_or_tau_int():
    # acf_max_lag = 1 (`reproduce --content paper`): one lag is no curve, and the
    # decorrelation lag and tau_int read off it would be meaningless
    store = synthetic_store(n_ics=6)
    res = store.results
    keep = ~res["diagnostic"].str.match(r"^acf@([2-9]|\d\d+)$")
    store.results = res[keep].reset_index(drop=True)
    assert set(autocorrelation.acf_curves(store.results)["lag"]) == {1}
    (sec,) = autocorrelation.sections(Context(store, n_boot=100))
    assert [name for name, _, _ in sec.figures] == ["fig07_autocorrelation_vs_radius"]
    assert any("stops at lag 1" in t for t in sec.paragraphs)
    assert not any(t.startswith("Decorrelation") for t in sec.paragraphs)
    tables = {name: df for name, df, _, _ in sec.tables}
    assert set(tables) == {"autocorrelation_summary"}
    table = tables["autocorrelation_summary"]
    assert not any(c.startswith(("decorrelation_lag", "tau_int")) for c in table.columns)
    assert np.allclose(table["R1_mean"], table["predicted_lag1"])

def test_stretching_per_perturbation_is_mean_lambda_over_the_pooled_rate(ctx):
    table = lyapunov.stretching_table(ctx.results)
    res = ctx.results
    part = res[(res["radius"] == 0.008) & (res["system"] == "two_particle")]
    lam = part[part["diagnostic"] == "lyapunov"]["value"].mean()
    n = part[part["diagnostic"] == "n_pp"]["value"].sum()
    t = part[part["diagnostic"] == "t_max"]["value"].sum()
    row = table[(table["radius"] == 0.008) & (table["system"] == "two_particle")].iloc[0]
    assert row["stretch_per_perturbation"] == pytest.approx(lam / (n / t))
    assert row["ln_inv_r"] == pytest.approx(np.log(1 / 0.008))


def test_lyapunov_figure_shows_lambda_stretching_and_the_ln_inverse_r_relation(ctx):
    (sec,) = ctx.sections["lyapunov"]
    fig = sec.figures[0][1]
    assert len(fig.axes) == 6
    lam_uniform, lam_scatter, excess, stretch_uniform, stretch_scatter, cell = fig.axes
    # the systems are split by kick kind (seven curves on one panel lay on each other)
    assert "uniform kicks" in lam_uniform.get_title()
    assert "scatter kicks" in lam_scatter.get_title()
    assert "scatter kicks" in stretch_scatter.get_title()
    assert lam_uniform.get_ylim() == lam_scatter.get_ylim()  # one y scale
    # every mean inside its axes: none clipped, no clipping note
    summary = ctx.found.summary
    means = summary[summary["diagnostic"] == "lyapunov"]["mean"]
    low, high = lam_uniform.get_ylim()
    assert low < means.min() and means.max() < high
    assert not lam_uniform.texts and not lam_scatter.texts
    assert "radius" in excess.get_xlabel()  # against r, as every other panel
    assert [ln for ln in excess.get_lines() if ln.get_linestyle() == ":"]  # the ln(1/r) guide
    assert "nats" in stretch_uniform.get_ylabel()
    # one legend, in its own cell: it covers no point
    assert [ax.get_legend() is not None for ax in fig.axes] == [False] * 5 + [True]
    assert not cell.axison and not fig.legends
    texts = [t.get_text() for t in cell.get_legend().get_texts()]
    assert system_label("two_particle") in texts and "median over ICs" in texts
    assert system_label("poisson_scatter") in texts


def test_findings_section_states_the_rules_and_the_scale(ctx):
    sec = ctx.findings
    kinds = [kind for kind, _ in sec.blocks]
    assert kinds[0] == "banner" and "ul" in kinds
    banner = sec.blocks[0][1]
    assert "16 ICs" in banner and "pipeline check" in banner and "docs/results" in banner
    assert any("Verdict rules" in p for p in sec.paragraphs)
    # below paper scale no answer ("No.") stands under the banner
    assert not any(p.startswith("Are the collision times Poisson?") for p in sec.paragraphs)


def test_sections_of_a_new_store_are_written_as_png_pdf_and_csv(ctx, tmp_path):
    from kicktimes.render.html import write_outputs

    secs = [ctx.findings] + [s for v in ctx.sections.values() for s in v]
    page = write_outputs(secs, tmp_path, 40)
    for name in (
        "fig05_lyapunov_vs_radius",
        "fig06_recurrence_rate_vs_radius",
        "fig07b_autocorrelation_curves",
    ):
        assert (tmp_path / f"{name}.png").is_file() and (tmp_path / f"{name}.pdf").is_file()
    assert (tmp_path / "findings.csv").is_file()
    assert '<p class="banner">' in page and '<ul class="findings">' in page


def _tables_as_csv(store):
    context = Context(store, n_boot=200)
    secs = []
    for module in (counts, summary, lyapunov, recurrence, autocorrelation):
        secs += module.sections(context)
    secs.append(findings.section(context))
    return {name: df.to_csv(index=False) for s in secs for name, df, _, _ in s.tables}


def test_the_categorical_results_view_writes_the_same_tables():
    # report_store turns system/diagnostic into categoricals (speed); every table the
    # sections write must be the same text as from the plain string columns
    from kicktimes.report.store import report_store

    store = synthetic_store(n_ics=8)
    view = report_store(store)
    assert isinstance(view.results["diagnostic"].dtype, pd.CategoricalDtype)
    assert store.results["diagnostic"].dtype != view.results["diagnostic"].dtype  # a copy
    plain, fast = _tables_as_csv(store), _tables_as_csv(view)
    assert plain.keys() == fast.keys() and len(plain) >= 8
    for name in plain:
        assert plain[name] == fast[name], name


def test_acf_curves_read_the_lag_from_every_acf_row_and_only_those():
    store = synthetic_store(n_ics=6)
    res = store.results
    ref = res[res["diagnostic"].str.match(r"^acf@(\d+)$")]
    ref = ref.assign(lag=ref["diagnostic"].str.slice(4).astype(int))
    ref = ref.groupby(["radius", "system", "lag"])["value"].agg(["mean", "median"]).reset_index()
    from kicktimes.report.store import report_store

    for results in (res, report_store(store).results):
        got = autocorrelation.acf_curves(results)
        assert sorted(got["lag"].unique()) == list(range(1, LAGS + 1))
        np.testing.assert_array_equal(got["mean"], ref["mean"])
        np.testing.assert_array_equal(got["median"], ref["median"])
        assert list(got["system"].astype(str)) == list(ref["system"].astype(str))


@pytest.mark.reproducibility
def test_figures_render_to_the_same_bytes_on_forked_workers():
    from kicktimes.render.html import render_figures

    def figures():
        context = Context(synthetic_store(n_ics=6), n_boot=100)
        return [f for s in autocorrelation.sections(context) for _, f, _ in s.figures]

    serial = render_figures(figures(), 40)
    forked = render_figures(figures(), 40, workers=2, pdf=True)
    assert len(serial) == len(forked) >= 2
    for (png1, pdf1), (png2, pdf2) in zip(serial, forked, strict=True):
        assert pdf1 is None and pdf2.startswith(b"%PDF")
        assert png1 == png2


def test_poisson_tests_started_ahead_on_a_pool_equal_the_tests_run_in_place():
    from kicktimes.report import poisson
    from kicktimes.report.context import Mapper

    store = synthetic_store(n_ics=6)
    in_place = Context(store, n_mc=39)
    expected = poisson.sections(in_place)[0].tables[0][1]
    pool = Mapper(2)
    try:
        ahead = Context(store, n_mc=39, pmap=pool.map, pstart=pool.start)
        poisson.start(ahead)
        assert "poisson" in ahead.pending
        got = poisson.sections(ahead)[0].tables[0][1]
    finally:
        pool.close()
    assert not ahead.pending
    pd.testing.assert_frame_equal(got, expected)
    pd.testing.assert_frame_equal(ahead.found.homogeneity, in_place.found.homogeneity)


def test_one_ic_per_radius_has_no_dispersion_index_and_no_warning():
    # the report's rate-homogeneity rows are kicktimes.stats.poisson_group's: a radius with
    # a single IC has no variance of its counts
    import warnings

    from kicktimes.report import heterogeneity, poisson

    context = Context(synthetic_store(n_ics=1), n_mc=39)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        poisson.sections(context)
    het = context.found.homogeneity
    assert (het["n_ics"] == 1).all() and het["dispersion_index"].isna().all()
    (sec,) = heterogeneity.sections(context)
    assert sec.figures and "rate_homogeneity" in [name for name, *_ in sec.tables]


def test_the_report_findings_are_stats_findings_with_an_effect_size(ctx):
    from kicktimes.report.findings import STATEMENT_COLUMNS
    from kicktimes.stats.findings import findings_table

    e = _effect(ctx, "FTLE", "poisson")
    assert isinstance(e, stats.Finding)
    assert e.statement.startswith("FTLE, Poisson vs two-particle: ratio of mean λ")
    assert e.sentence() == f"{e.statement} ({e.detail}.)"
    table = findings_table(ctx.found.effects, columns=STATEMENT_COLUMNS)
    assert list(table.columns) == list(STATEMENT_COLUMNS)
    assert len(table) == len(ctx.found.effects) and table["estimate"].notna().all()


def test_one_writer_writes_the_page_of_the_report_and_of_kicktimes_analyze(tmp_path):
    from kicktimes.render.html import CSS, toc_item, write_page

    files = {}
    toc = [toc_item("s", "S & T", [toc_item("u", "U")]), toc_item("v", "V")]
    path = write_page(tmp_path, "a <b> page", sources="x.csv", toc=toc, lead="<p>answers</p>",
                      body="<h3 id='s'>S</h3>", appendix="<p>end</p>", files=files)
    text = path.read_text(encoding="utf-8")
    assert path == tmp_path / "report.html" and set(files) == {"report.html"}
    assert text.startswith("<!DOCTYPE html>") and f"<style>{CSS}</style>" in text
    assert "<title>a &lt;b&gt; page</title>" in text and "<h1>a &lt;b&gt; page</h1>" in text
    # the answers first, then the contents, collapsed (3 sections)
    assert (' from x.csv.</p><p>answers</p><details class="contents"><summary>Contents '
            "(3 sections)</summary>") in text
    assert ('<ul><li><a href="#s">S &amp; T</a><ul><li><a href="#u">U</a></li></ul></li>'
            '<li><a href="#v">V</a></li></ul>') in text
    assert text.endswith("<h3 id='s'>S</h3><p>end</p></body></html>")
    assert not list(tmp_path.glob("*.tmp*"))  # written atomically


def test_recurrence_plot_section_names_the_system_and_eps_and_zooms_on_lines():
    from kicktimes.experiment import Experiment
    from kicktimes.report import trajectories

    exp = Experiment(name="tiny", radii=[0.014, 0.02], n_ics=1, n_steps=600, tau=0.3,
                     eps=[0.05])
    results = pd.DataFrame({"radius": [], "ic": [], "system": [], "diagnostic": [],
                            "value": []})
    store = SimpleNamespace(experiment=exp, results=results)
    (sec,) = [s for s in trajectories.sections(Context(store)) if s.key == "recurrence_plot"]
    name, fig, caption = sec.figures[0]
    title = fig.axes[0].get_title()
    assert "two-disk billiard" in title and "ε = 0.05" in title and "r = 0.02" in title
    assert "length ≥ 2" in caption
    (inset,) = fig.axes[0].child_axes
    assert any("pairs on lines" in t.get_text() for t in inset.texts)


def test_qq_band_null_equals_the_per_ic_loop_it_replaces():
    """The Q-Q band's null ensembles, one uniform draw per row and a kernel, are bitwise
    the loop of one ``rng.uniform(0, w, n)``, sort and rescaling per IC (runs of 0 and 1
    events among them: drawn, not pooled)."""
    from kicktimes.report.kick_times import _poisson_null_rescaled, rescaled_intervals

    def by_numpy(seqs, windows):  # the per-IC expression the kernel replaced
        return np.concatenate([np.diff(np.concatenate(([0.0], t))) * (t.size / float(w))
                               for t, w in zip(seqs, windows, strict=True) if t.size >= 2])

    counts = [0, 1, 5, 1, 0, 30, 2]
    windows = np.array([1.0, 2.0, 3.5, 4.0, 5.0, 60.0, 7.25])
    rng = np.random.default_rng(9)
    loop = []
    for _ in range(4):
        sim = [np.sort(rng.uniform(0.0, w, n)) for n, w in zip(counts, windows, strict=True)]
        np.testing.assert_array_equal(rescaled_intervals(sim, windows), by_numpy(sim, windows))
        loop.append(np.sort(by_numpy(sim, windows)))
    fast = _poisson_null_rescaled(counts, windows, 4, np.random.default_rng(9))
    assert fast.shape == (4, 5 + 30 + 2)
    np.testing.assert_array_equal(fast, np.vstack(loop))
