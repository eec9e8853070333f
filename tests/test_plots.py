"""Specification of kicktimes.plots: every function returns a labelled Figure, headless."""

from __future__ import annotations

import subprocess
import sys
import tracemalloc

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from kicktimes import initial_conditions, plots, simulate_two_particle, stats
from kicktimes.report.trajectories import line_pairs

# ------------------------------------------------------------------ synthetic data
# Tables with exactly the store's columns (docs: contracts / docs/experiments.md).

RADII = (0.008, 0.012, 0.016, 0.02)


def make_results(radii=RADII, n_ics=30, seed=0, nan_share=0.1):
    """Tidy results ``radius, ic, system, diagnostic, value, note`` like a store's."""
    rng = np.random.default_rng(seed)
    rows = []
    level = {"lyapunov": 0.05, "recurrence_rate": 2e-3, "autocorrelation": 0.6}
    for r in radii:
        for ic in range(n_ics):
            for k, system in enumerate(plots.SYSTEMS):
                for diagnostic, base in level.items():
                    value = base * (1 + 20 * r) * (1 + 0.05 * k) * rng.lognormal(0, 0.3)
                    note = ""
                    if diagnostic == "autocorrelation" and rng.uniform() < nan_share:
                        value, note = np.nan, "constant series"
                    rows.append((r, ic, system, diagnostic, value, note))
                rows.append((r, ic, system, "n_boundary", float(rng.integers(500, 900)), ""))
    df = pd.DataFrame(rows, columns=["radius", "ic", "system", "diagnostic", "value", "note"])
    return df.astype({"radius": "float64", "ic": "int64", "value": "float64"})


def make_collisions(radii=RADII, n_ics=30, t_window=2000.0, seed=0, rate_spread=0.5):
    """Collision table ``radius, ic, t_window, n_pp, pp_times``: Poisson times per IC with
    log-normally spread rates around the kinetic rate (heterogeneous ensemble)."""
    rng = np.random.default_rng(seed)
    rows = []
    for r in radii:
        for ic in range(n_ics):
            rate = stats.kinetic_rate(r) * rng.lognormal(0, rate_spread)
            n = rng.poisson(rate * t_window)
            times = np.sort(rng.uniform(0, t_window, n))
            rows.append((r, ic, t_window, n, times))
    return pd.DataFrame(rows, columns=["radius", "ic", "t_window", "n_pp", "pp_times"])


def main_axes(fig):
    return [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]


def assert_labelled(fig):
    assert isinstance(fig, Figure)
    axes = main_axes(fig)
    assert axes
    for ax in axes:
        assert ax.get_xlabel().strip() or ax.get_xaxis().get_visible() is False
        assert ax.get_ylabel().strip()


@pytest.fixture(scope="module")
def run():
    ic = initial_conditions(1, 0.02, rng=1)[0]
    return simulate_two_particle(ic, 0.02, n_steps=2000, tau=0.2)


# -------------------------------------------------------------------- Poincaré


def test_poincare_section_plots_one_disk_of_a_run(run):
    fig = plots.poincare_section(run, particle=1)
    assert_labelled(fig)
    (line,) = fig.axes[0].get_lines()
    n1 = int((run.boundary["particle"] == 1).sum())
    assert len(line.get_xdata()) == n1
    assert "r = 0.02" in fig.axes[0].get_title()


def test_poincare_section_accepts_a_boundary_dataframe():
    df = pd.DataFrame({"s": [0.1, 3.0, 6.0], "sin_theta": [0.5, -0.2, 0.9]})
    fig = plots.poincare_section(df)
    assert_labelled(fig)
    assert fig.axes[0].get_xlim() == pytest.approx((0, 2 * np.pi))


def test_poincare_panels_stacks_one_panel_per_radius_with_the_same_ic():
    ic = initial_conditions(1, 0.02, rng=3)[0]
    runs = [simulate_two_particle(ic, r, n_steps=500, tau=0.3) for r in (0.02, 0.014)]
    fig = plots.poincare_panels(runs)
    assert len(fig.axes) == 2
    assert "(a)" in fig.axes[0].get_title() and "0.014" in fig.axes[1].get_title()
    assert fig.axes[1].get_xlabel() and fig.axes[0].get_ylabel()


@pytest.mark.parametrize(
    ("data", "kwargs", "error"),
    [
        (pd.DataFrame({"s": [0.1]}), {}, ValueError),
        (pd.DataFrame({"s": [np.nan], "sin_theta": [0.1]}), {}, ValueError),
        (pd.DataFrame({"s": [7.0], "sin_theta": [0.1]}), {}, ValueError),
        (pd.DataFrame({"s": [1.0], "sin_theta": [0.1]}), {"particle": 2}, ValueError),
        (np.zeros((3, 2)), {}, TypeError),
    ],
)
def test_poincare_section_rejects_bad_input(data, kwargs, error):
    with pytest.raises(error):
        plots.poincare_section(data, **kwargs)


# ------------------------------------------------------------- recurrence plot


def test_recurrence_plot_from_points_reports_the_recurrence_rate(run):
    from kicktimes.diagnostics import recurrence_rate

    fig = plots.recurrence_plot(run.samples, eps=1e-2)
    assert_labelled(fig)
    rr = recurrence_rate(run.samples, eps=1e-2)
    assert f"RR = {rr:.3g}" in fig.axes[0].get_title()


def test_recurrence_plot_from_pairs_draws_every_pair():
    i = np.array([0, 0, 1, 1, 2], dtype=np.int64)
    j = np.array([0, 1, 0, 1, 2], dtype=np.int64)
    fig = plots.recurrence_plot((i, j), n_points=3, tau=0.5)
    (line,) = fig.axes[0].get_lines()
    assert np.array_equal(line.get_xdata(), i * 0.5)
    assert "time" in fig.axes[0].get_xlabel()


def test_recurrence_plot_bins_many_pairs_instead_of_drawing_them():
    rng = np.random.default_rng(0)
    i = rng.integers(0, 1000, 5000)
    fig = plots.recurrence_plot((i, i.copy()), n_points=1000, max_markers=100, bins=50)
    assert main_axes(fig)[0].get_images()  # a binned image, not 5000 markers
    assert len(fig.axes) == 2  # with its colorbar


def test_recurrence_plot_never_builds_an_n_by_n_array():
    # 10^5 points: an N x N boolean matrix alone would be 10 GB
    rng = np.random.default_rng(1)
    rad = np.sqrt(rng.uniform(size=100_000))
    ang = rng.uniform(0, 2 * np.pi, 100_000)
    points = np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
    tracemalloc.start()
    try:
        fig = plots.recurrence_plot(points, eps=1e-3)
        fig.savefig(__import__("io").BytesIO(), format="png", dpi=40)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 200e6


def test_line_pairs_are_the_pairs_on_diagonal_lines_off_the_main_diagonal():
    # a line (2, 7), (3, 8), (4, 9); an isolated pair (0, 5); the main diagonal
    i = np.array([0, 2, 3, 4, 0, 1, 2, 3, 4])
    j = np.array([5, 7, 8, 9, 0, 1, 2, 3, 4])
    on = line_pairs(i, j, 10)
    assert on.tolist() == [False, True, True, True, False, False, False, False, False]


def test_recurrence_plot_inset_shows_diagonal_lines_away_from_the_main_diagonal():
    n = 400
    diag = np.arange(n)
    line = np.arange(300, 306)  # a line of length 6 at j = i - 250, far off the diagonal
    i = np.concatenate([diag, line - 250, line, [10, 380]])
    j = np.concatenate([diag, line, line - 250, [200, 20]])
    fig = plots.recurrence_plot((i, j), n_points=n, zoom=40)
    (inset,) = fig.axes[0].child_axes
    x0, x1 = inset.get_xlim()
    y0, y1 = inset.get_ylim()
    assert x0 <= 50 and x1 >= 56 and y0 <= 300 and y1 >= 306  # the line, whole
    assert y0 > x1  # not the main diagonal
    red = [ln for ln in inset.get_lines() if ln.get_color() == "tab:red"]
    assert len(red) == 1 and len(red[0].get_xdata()) == 6
    assert any("6 of 6 pairs on lines" in t.get_text() for t in inset.texts)


@pytest.mark.parametrize(
    ("data", "kwargs", "error"),
    [
        ((np.array([0.5, 1.0]), np.array([0.5, 1.0])), {}, TypeError),
        ((np.array([0, 1]), np.array([0])), {}, ValueError),
        ((np.array([0, 5]), np.array([0, 5])), {"n_points": 3}, ValueError),
        (np.zeros((4, 2)), {"eps": -1.0}, ValueError),
        (np.zeros((4, 2)), {"tau": np.inf}, ValueError),
        (np.zeros((4, 2)), {"bins": 1}, ValueError),
    ],
)
def test_recurrence_plot_rejects_bad_input(data, kwargs, error):
    with pytest.raises(error):
        plots.recurrence_plot(data, **kwargs)


# --------------------------------------------------------------- kick times


def test_kth_time_fit_recovers_an_exact_line():
    x = np.array([1.0, 2.0, 4.0, 7.0])
    fit = plots.kth_time_fit(x, 3 * x + 2)
    assert fit.slope == pytest.approx(3) and fit.intercept == pytest.approx(2)
    assert fit.r_squared == pytest.approx(1) and fit.n == 4


def test_kth_time_fit_pairs_only_the_common_length():
    assert plots.kth_time_fit([1.0, 2.0, 3.0, 9.0, 10.0], [1.0, 2.0, 3.0]).n == 3


@pytest.mark.parametrize(
    ("pp", "kicks"),
    [([1.0, 2.0], [1.0, 2.0]), ([1.0, np.nan, 3.0], [1, 2, 3]), ([3.0, 2.0, 1.0], [1, 2, 3])],
)
def test_kth_time_fit_rejects_bad_times(pp, kicks):
    with pytest.raises(ValueError):
        plots.kth_time_fit(pp, kicks)


def test_kick_times_figure_shows_the_line_and_its_r_squared():
    rng = np.random.default_rng(2)
    pp = np.cumsum(rng.exponential(10, 80))
    kicks = np.cumsum(rng.exponential(10, 90))
    fig = plots.kick_times_vs_collision_times(pp, kicks, radius=0.008)
    assert_labelled(fig)
    fit = plots.kth_time_fit(pp, kicks)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(f"R² = {fit.r_squared:.4f}" in lab for lab in labels)
    assert "0.008" in fig.axes[0].get_title()


def test_kick_times_legend_prints_a_negative_intercept_with_a_minus_sign():
    pp = np.arange(1.0, 40.0) * 10
    fig = plots.kick_times_vs_collision_times(pp, 1.1 * pp - 7.0, radius=0.008)
    (label,) = [t.get_text() for t in fig.axes[0].get_legend().get_texts()
                if t.get_text().startswith("least squares")]
    assert "1.100 t − 7, R²" in label and "+ -" not in label
    import matplotlib.pyplot as plt

    plt.close(fig)


# ------------------------------------------------------------------- counts


def test_counts_by_radius_gives_mean_and_standard_error():
    df = pd.DataFrame(
        {"radius": [0.01] * 3 + [0.02] * 2, "n_pp": [1, 2, 3, 10, 20], "t_window": 100.0}
    )
    table = plots.counts_by_radius(df)
    assert table.loc[0.01, "mean_count"] == 2 and table.loc[0.02, "mean_count"] == 15
    assert table.loc[0.01, "sem"] == pytest.approx(1 / np.sqrt(3))


def test_counts_vs_radius_draws_points_line_regressions_and_kinetic_curve():
    coll = make_collisions()
    fig = plots.counts_vs_radius(coll)
    assert_labelled(fig)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    for key in ("least-squares", "Poisson regression", "negative binomial", "kinetic"):
        assert any(key in lab for lab in labels), key
    # the kinetic curve is Gamma(r) T at the window T
    kin = [ln for ln in fig.axes[0].get_lines() if "kinetic" in ln.get_label()][0]
    x, y = kin.get_data()
    assert np.allclose(y, stats.kinetic_rate(x) * 2000.0)


def test_counts_vs_radius_uses_a_given_regression():
    coll = make_collisions()
    frame = coll[["radius", "n_pp", "t_window"]].rename(columns={"n_pp": "count"})
    reg = stats.regress_counts(frame, rule="mirror")
    fig = plots.counts_vs_radius(coll, regression=reg)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(f"α = {reg.alpha:.3g}" in lab for lab in labels)
    with pytest.raises(TypeError):
        plots.counts_vs_radius(coll, regression="not a regression")
    with pytest.raises(ValueError):
        plots.counts_vs_radius(coll.assign(t_window=-1.0))


# ------------------------------------------------------- diagnostics vs radius


def test_diagnostic_summary_counts_nan_as_invalid_and_gives_both_error_bars():
    df = pd.DataFrame(
        {
            "radius": 0.01,
            "ic": [0, 1, 2, 3],
            "system": "poisson",
            "diagnostic": "autocorrelation",
            "value": [1.0, 2.0, 3.0, np.nan],
            "note": ["", "", "", "constant series"],
        }
    )
    row = plots.diagnostic_summary(df).iloc[0]
    assert (row["n"], row["n_valid"], row["mean"]) == (4, 3, 2.0)
    assert row["std"] == pytest.approx(1.0)
    assert row["sem"] == pytest.approx(1 / np.sqrt(3))
    assert row["paper_err"] == pytest.approx(0.1)


def test_diagnostic_summary_rejects_infinite_values_and_unknown_diagnostics():
    df = make_results(n_ics=3)
    with pytest.raises(ValueError, match="infinite"):
        plots.diagnostic_summary(df.assign(value=np.inf))
    with pytest.raises(ValueError, match="not in results"):
        plots.diagnostic_summary(df, diagnostic="entropy")


@pytest.mark.parametrize("diagnostic", ["lyapunov", "recurrence_rate", "autocorrelation"])
def test_diagnostic_vs_radius_draws_three_systems_with_both_bars(diagnostic):
    fig = plots.diagnostic_vs_radius(make_results(), diagnostic)
    assert_labelled(fig)
    ax = fig.axes[0]
    assert len(ax.containers) == 2 * len(plots.SYSTEMS)  # paper bar + standard error each
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"Two-particle", "Poisson", "Actual"} <= set(labels)
    assert any("std/10" in lab for lab in labels) and any("√n_valid" in lab for lab in labels)
    # first container of a system: the paper's bar (2 std/10 long), then the standard error
    # (2 std/sqrt(n_valid) long), both at the smallest radius first
    summary = plots.diagnostic_summary(make_results(), diagnostic=diagnostic)
    row = summary[summary["system"] == "two_particle"].sort_values("radius").iloc[0]
    paper, sem = ax.containers[0], ax.containers[1]
    seg_p = paper.lines[2][0].get_segments()[0]
    seg_s = sem.lines[2][0].get_segments()[0]
    assert np.ptp([p[1] for p in seg_p]) == pytest.approx(2 * row["std"] / 10)
    assert np.ptp([p[1] for p in seg_s]) == pytest.approx(2 * row["std"] / np.sqrt(row["n_valid"]))


def test_diagnostic_vs_radius_accepts_a_summary_and_checks_systems():
    summary = plots.diagnostic_summary(make_results())
    fig = plots.diagnostic_vs_radius(summary, "lyapunov", systems=["poisson"])
    assert len(fig.axes[0].containers) == 2
    with pytest.raises(ValueError, match="systems"):
        plots.diagnostic_vs_radius(summary, "lyapunov", systems=["three_particle"])
    with pytest.raises(TypeError):
        plots.diagnostic_vs_radius(summary, 3)


# -------------------------------------------------------------- statistics


def test_rejection_table_gives_clopper_pearson_intervals():
    df = pd.DataFrame(
        {"radius": [0.01, 0.02], "test": "runs", "n_tested": [100, 0], "n_reject": [5, 0]}
    )
    table = plots.rejection_table(df)
    assert table.loc[0, "rate"] == 0.05
    assert table.loc[0, "ci_low"] < 0.05 < table.loc[0, "ci_high"]
    assert np.isnan(table.loc[1, "rate"]) and np.isnan(table.loc[1, "ci_low"])
    with pytest.raises(ValueError, match="n_reject"):
        plots.rejection_table(df.assign(n_reject=[101, 0]))


def _rejection_rows():
    return pd.DataFrame(
        [
            {"radius": r, "test": t, "n_tested": 50, "n_reject": k}
            for r in RADII
            for k, t in enumerate(stats.TESTS)
        ]
    )


def test_poisson_rejection_rates_draws_one_panel_per_test_with_alpha():
    fig = plots.poisson_rejection_rates(_rejection_rows(), alpha=0.05)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == len(stats.TESTS)  # small multiples: no offsets between tests
    for ax, test in zip(axes, stats.TESTS, strict=True):
        from kicktimes.report.poisson import TEST_TITLES

        assert ax.get_title() == TEST_TITLES[test]  # what the test checks, not its identifier
        assert len(ax.containers) == 1
        assert any(np.allclose(ln.get_ydata(), 0.05) for ln in ax.get_lines())
        # every point sits at its radius, not shifted
        assert np.allclose(ax.containers[0].lines[0].get_xdata(), RADII)
    assert all(ax.get_ylabel() for ax in axes[::4])
    with pytest.raises(ValueError, match="alpha"):
        plots.poisson_rejection_rates(_rejection_rows(), alpha=1.5)


def test_poisson_rejection_rates_can_overlay_the_tests_in_a_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    assert plots.poisson_rejection_rates(_rejection_rows(), ax=ax) is fig
    assert len(ax.containers) == len(stats.TESTS) and ax.get_legend() is not None


def test_model_comparison_shares_add_up_to_one():
    per_ic = pd.DataFrame(
        {
            "radius": [0.01, 0.01, 0.01, 0.02, 0.02],
            "best_model": ["exponential", "gamma", "gamma", "weibull", "gamma"],
        }
    )
    pooled = pd.DataFrame(
        {
            "radius": [0.01, 0.01, 0.02, 0.02],
            "model": ["exponential", "gamma"] * 2,
            "delta_aic": [3.0, 0.0, 0.0, 12.0],
        }
    )
    fig = plots.model_comparison(per_ic, pooled)
    assert_labelled(fig)
    ax1 = fig.axes[0]
    tops = {}
    for bar in ax1.patches:  # one bar per model beside the others, grouped at the radius
        x = min((0.01, 0.02), key=lambda r: abs(r - (bar.get_x() + bar.get_width() / 2)))
        tops[x] = tops.get(x, 0) + bar.get_height()
    assert tops == {0.01: pytest.approx(1.0), 0.02: pytest.approx(1.0)}
    # every share has its Clopper-Pearson 95 % interval, and n is written per radius
    bars = [c for c in ax1.containers if hasattr(c, "errorbar")]
    assert len(bars) == 3 and all(c.errorbar is not None for c in bars)
    gamma = next(c for c in bars if c.get_label() == "gamma")
    segments = gamma.errorbar.lines[2][0].get_segments()
    low, high = plots.binomial_ci([2, 1], [3, 2])
    assert [seg[0][1] for seg in segments] == pytest.approx(low)
    assert [seg[1][1] for seg in segments] == pytest.approx(high)
    # n under each radius's tick (against the radius), not over the bars
    assert [t.get_text() for t in ax1.get_xticklabels()] == ["0.01\nn = 3", "0.02\nn = 2"]
    assert not [t for t in ax1.texts if t.get_text().startswith("n = ")]


def test_model_comparison_states_a_common_n_once_for_many_radii():
    radii = np.repeat([0.008, 0.01, 0.012, 0.014, 0.016, 0.018], 12)
    per_ic = pd.DataFrame({"radius": radii, "best_model": ["gamma", "exponential"] * 36})
    pooled = pd.DataFrame({"radius": [0.01], "model": ["gamma"], "delta_aic": [0.0]})
    ax1 = plots.model_comparison(per_ic, pooled).axes[0]
    assert "n = 12 ICs fitted at every radius" in ax1.get_title()
    assert not [t for t in ax1.texts if t.get_text().startswith("n = ")]
    assert all(c.errorbar is not None for c in ax1.containers if hasattr(c, "errorbar"))
    with pytest.raises(ValueError, match="non-negative"):
        plots.model_comparison(per_ic, pooled.assign(delta_aic=-1.0))


def test_model_comparison_keeps_legend_off_the_data_and_no_negative_delta_aic_band():
    per_ic = pd.DataFrame({"radius": [0.01, 0.02], "best_model": ["exponential", "gamma"]})
    pooled = pd.DataFrame(
        {"radius": [0.01, 0.01], "model": ["exponential", "gamma"], "delta_aic": [0.0, 150.0]}
    )
    fig = plots.model_comparison(per_ic, pooled)
    ax1, ax2 = fig.axes
    assert ax1.get_legend() is None and ax2.get_legend() is None
    assert len(fig.legends) == 1  # one legend, outside the panels
    # a log axis of delta AIC + 1, labelled in delta AIC: the best model (0) on a line
    # just above the bottom, and no label "0" below one of 1
    assert ax2.get_yscale() == "log" and 0 < ax2.get_ylim()[0] < 1 <= 151 <= ax2.get_ylim()[1]
    labels = [t.get_text() for t in ax2.get_yticklabels()]
    assert labels[:3] == ["0", "2", "10"]


def test_log_axes_have_plain_tick_labels():
    fig = plots.rate_heterogeneity(make_collisions(n_ics=20))
    fig.canvas.draw()
    for ax in fig.axes:
        labels = [t.get_text() for t in ax.get_yticklabels() + ax.get_yminorticklabels()]
        assert not any("times" in lab or "^" in lab for lab in labels), labels


def test_kick_times_labels_have_one_level_of_parentheses():
    fig = plots.kick_times_vs_collision_times(np.arange(1.0, 9), np.arange(1.0, 9))
    for label in (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()):
        assert label.count("(") == 1 and label.endswith("(time units)")


def test_model_comparison_says_so_when_no_ic_could_be_fitted():
    per_ic = pd.DataFrame({"radius": [], "best_model": []})
    pooled = pd.DataFrame(
        {"radius": [0.01, 0.01], "model": ["exponential", "gamma"], "delta_aic": [0.0, 1.5]}
    )
    fig = plots.model_comparison(per_ic, pooled)
    assert any("no sample" in t.get_text() for t in fig.axes[0].texts)
    with pytest.raises(ValueError, match="both be empty"):
        plots.model_comparison(per_ic, pooled.iloc[:0])


def test_rate_heterogeneity_draws_zero_rate_ics_at_the_floor_and_p_values():
    coll = make_collisions(n_ics=20)
    coll.at[0, "n_pp"] = 0
    coll.at[0, "pp_times"] = np.array([])
    hom = pd.DataFrame({"radius": list(RADII), "pvalue": [0.0, 0.01, 0.2, 0.5]})
    fig = plots.rate_heterogeneity(coll, homogeneity=hom)
    assert_labelled(fig)
    ax1, ax2 = fig.axes
    labels = [t.get_text() for t in ax1.get_legend().get_texts()]
    assert any("without disk-disk collisions" in lab for lab in labels)
    # p-values on a second x axis on top (never over a marker), one per radius, horizontal
    (top,) = ax2.child_axes
    assert [t.get_text() for t in top.get_xticklabels()] == ["< 10⁻³⁰⁰", "0.01", "0.2", "0.5"]
    assert all(t.get_rotation() == 0 for t in top.get_xticklabels())
    assert "asymptotic" in top.get_xlabel() and "below double precision" in top.get_xlabel()
    # with the Monte Carlo p-value beside (floored at 1/(n_mc + 1)) the labels stay the
    # asymptotic ones, which are not floored; with the Monte Carlo one alone, that one
    mc = hom.assign(pvalue_mc=[0.005, 0.02, 0.3, 0.6])
    (top,) = plots.rate_heterogeneity(coll, homogeneity=mc).axes[1].child_axes
    assert "asymptotic" in top.get_xlabel()
    assert top.get_xticklabels()[0].get_text() == "< 10⁻³⁰⁰"
    only_mc = mc.drop(columns="pvalue")
    (top,) = plots.rate_heterogeneity(coll, homogeneity=only_mc).axes[1].child_axes
    assert "Monte Carlo" in top.get_xlabel()
    assert top.get_xticklabels()[0].get_text() == "0.005"
    with pytest.raises(ValueError, match="pvalue"):
        plots.rate_heterogeneity(coll, homogeneity=hom.rename(columns={"pvalue": "p"}))


def test_rate_heterogeneity_writes_tiny_p_values_as_powers_of_ten():
    coll = make_collisions(n_ics=20)
    hom = pd.DataFrame({"radius": list(RADII), "pvalue": [3e-12, 2e-4, 0.04, np.nan]})
    (top,) = plots.rate_heterogeneity(coll, homogeneity=hom).axes[1].child_axes
    assert [t.get_text() for t in top.get_xticklabels()] == ["< 10⁻¹¹", "< 10⁻³", "0.04", ""]
    # the same label everywhere (every radius of a paper store): one sentence, no ticks
    (top,) = plots.rate_heterogeneity(coll, homogeneity=hom.assign(pvalue=0.0)).axes[1].child_axes
    assert not [t.get_text() for t in top.get_xticklabels() if t.get_text()]
    assert "p < 10⁻³⁰⁰ at every radius (below double precision)" in top.get_xlabel()


def test_rate_heterogeneity_draws_the_dispersion_without_the_sticky_runs():
    coll = make_collisions(n_ics=40, rate_spread=0.0)
    sticky = coll.index[(coll["radius"] == 0.012) & (coll["ic"] < 2)]
    coll.loc[sticky, "n_pp"] = int(20 * float(stats.kinetic_rate(0.012)) * 2000.0)
    fig = plots.rate_heterogeneity(coll)
    ax2 = fig.axes[1]
    (every,) = [ln for ln in ax2.get_lines() if ln.get_label().endswith("all ICs")]
    (without,) = [ln for ln in ax2.get_lines() if ln.get_gid() == "sticky_excluded"]
    assert "2 sticky runs (radius, IC) of 2 ICs" in without.get_label()
    at = list(RADII).index(0.012)
    # two sticky runs blow the dispersion up; without them a common Poisson rate is back
    assert every.get_ydata()[at] > 50 and without.get_ydata()[at] < 3
    np.testing.assert_allclose(np.delete(every.get_ydata(), at),
                               np.delete(without.get_ydata(), at))
    assert [t.get_text() for t in ax2.texts] == ["−2"]
    # flags given by hand, or none
    flags = np.zeros(len(coll), bool)
    flags[sticky[:1]] = True
    fig = plots.rate_heterogeneity(coll, sticky=flags)
    (without,) = [ln for ln in fig.axes[1].get_lines() if ln.get_gid() == "sticky_excluded"]
    assert "1 sticky run (radius, IC) of 1 IC" in without.get_label()
    # one IC sticky at two radii: two runs, one IC (the legend counts both)
    flags = ((coll["ic"] == 0) & coll["radius"].isin([0.012, 0.016])).to_numpy()
    fig = plots.rate_heterogeneity(coll, sticky=flags)
    (without,) = [ln for ln in fig.axes[1].get_lines() if ln.get_gid() == "sticky_excluded"]
    assert "2 sticky runs (radius, IC) of 1 IC" in without.get_label()
    fig = plots.rate_heterogeneity(coll, sticky=np.zeros(len(coll), bool))
    (without,) = [ln for ln in fig.axes[1].get_lines() if ln.get_gid() == "sticky_excluded"]
    assert "(none: the same curve)" in without.get_label()
    fig = plots.rate_heterogeneity(coll, sticky=None)
    assert not [ln for ln in fig.axes[1].get_lines() if ln.get_gid() == "sticky_excluded"]
    with pytest.raises(ValueError, match="one flag per row"):
        plots.rate_heterogeneity(coll, sticky=flags[:3])


def test_statistics_figures_draw_against_any_numeric_column_at_its_values():
    density = {r: 1000 * r for r in RADII}  # far outside the radius range (0, 0.5)
    rej = _rejection_rows().assign(density=lambda d: d["radius"].map(density))
    fig = plots.poisson_rejection_rates(rej.drop(columns="radius"), x="density",
                                        xlabel="density (1 / area)")
    ax = [a for a in fig.axes if a.get_visible()][-1]
    assert ax.get_xlabel() == "density (1 / area)"
    np.testing.assert_allclose(ax.containers[0].lines[0].get_xdata().astype(float),
                               sorted(density.values()))
    coll = make_collisions(n_ics=10).assign(density=lambda d: d["radius"].map(density))
    fig = plots.rate_heterogeneity(coll.drop(columns="radius"), x="density", rule=None)
    assert [a.get_xlabel() for a in fig.axes] == ["density", "density"]
    np.testing.assert_allclose(fig.axes[1].get_lines()[0].get_xdata(), sorted(density.values()))
    with pytest.raises(ValueError, match="rule needs x='radius'"):
        plots.rate_heterogeneity(coll, x="density")
    with pytest.raises(ValueError, match=r"pooled\['radius'\] must satisfy 0 < r < 0.5"):
        plots.model_comparison(pd.DataFrame({"radius": [], "best_model": []}),
                               pd.DataFrame({"radius": [2.0], "model": ["gamma"],
                                             "delta_aic": [0.0]}))


def test_statistics_figures_draw_a_column_of_labels_at_labelled_positions():
    per = pd.DataFrame({"site": ["north", "south", "north"], "best_model": ["gamma"] * 3})
    pooled = pd.DataFrame({"site": ["south", "north"], "model": "gamma", "delta_aic": 0.0})
    fig = plots.model_comparison(per, pooled, x="site", xlabel="site")
    ax1, ax2 = fig.axes
    assert [round(b.get_x() + b.get_width() / 2, 9) for b in ax1.patches] == [0.0, 1.0]
    assert list(ax2.get_lines()[0].get_xdata()) == [0.0, 1.0]
    for ax in (ax1, ax2):
        assert list(ax.xaxis.get_major_formatter().seq) == ["north", "south"]
        assert ax.get_xlabel() == "site"


def test_plotting_draws_into_a_given_axes():
    fig = Figure()
    ax = fig.add_subplot()
    out = plots.diagnostic_vs_radius(make_results(n_ics=5), "lyapunov", ax=ax)
    assert out is fig
    with pytest.raises(TypeError, match="ax"):
        plots.kick_times_vs_collision_times([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], ax="axes")


def test_the_library_never_imports_pyplot():
    code = (
        "import sys, numpy as np\n"
        "from kicktimes import plots\n"
        "plots.kick_times_vs_collision_times(np.arange(1.0, 9), np.arange(1.0, 9))\n"
        "import kicktimes.report\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
