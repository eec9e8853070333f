"""Markov-modulated Poisson kicks: the schedule, its JSON and spec, the CLI and the sweep's
``mmpp`` system (issue 30, items 3 and 4)."""

from __future__ import annotations

import math
import pickle
import types

import numpy as np
import pytest
import scipy.stats as st
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as hs

from kicktimes import schedules
from kicktimes.cli import main
from kicktimes.schedules import MMPP, Poisson

# slow switching between a quiet and a busy state: pi = (0.8, 0.2), mean rate 1.2
CLUSTERED = MMPP([0.5, 4.0], [[-0.1, 0.1], [0.4, -0.4]])


def interval_cdf(schedule):
    r"""CDF of the stationary MMPP's intervals: :math:`F(x) = 1 - \phi e^{(Q - \Lambda)x} 1`
    with :math:`\phi = \pi\Lambda / \pi\lambda`, the state law just after a kick."""
    lam = schedule.rates
    m = schedule.generator - np.diag(lam)
    mu, v = np.linalg.eig(m)
    phi = schedule.stationary * lam / schedule.stationary_rate
    left, right = phi @ v, np.linalg.solve(v, np.ones(lam.size))

    def cdf(x):
        x = np.asarray(x, dtype=float)[..., None]
        return 1.0 - np.real((left * right * np.exp(mu * x)).sum(axis=-1))

    return cdf


def count_variance(schedule, t):
    """Var N(0, t] of a stationary two-state MMPP (switching rates a, b; s = a + b)."""
    (l0, l1), p = schedule.rates, schedule.stationary
    s = -np.trace(schedule.generator)
    return schedule.stationary_rate * t + 2 * p[0] * p[1] * (l0 - l1) ** 2 * (
        t / s - (1 - math.exp(-s * t)) / s**2)


# ------------------------------------------------------------------------- the process
def test_mmpp_samples_at_its_stationary_rate():
    assert CLUSTERED.stationary == pytest.approx([0.8, 0.2])
    assert CLUSTERED.stationary_rate == pytest.approx(1.2)
    times = CLUSTERED.sample(2e5, rng=0)
    # Var N(T) ~ 2 pi0 pi1 (l0 - l1)^2 T / s: a relative error of 0.8 %
    sd = math.sqrt(count_variance(CLUSTERED, 2e5))
    assert abs(times.size - 1.2 * 2e5) < 4 * sd
    assert abs(times.size / 2e5 / 1.2 - 1) < 0.05


def test_mmpp_intervals_follow_the_exact_interval_law():
    times = CLUSTERED.sample(4e4, rng=1)
    assert st.kstest(np.diff(times), interval_cdf(CLUSTERED)).pvalue > 1e-3
    # the same test rejects the exponential law of the same mean: the kicks cluster
    assert st.kstest(np.diff(times), st.expon(scale=1 / 1.2).cdf).pvalue < 1e-6


def test_mmpp_counts_are_overdispersed_as_the_theory_says():
    t, n = 20.0, 4000
    rng = np.random.default_rng(2)
    counts = np.array([CLUSTERED.sample(t, rng=rng).size for _ in range(n)])
    assert counts.mean() == pytest.approx(1.2 * t, abs=4 * math.sqrt(count_variance(
        CLUSTERED, t) / n))
    # the variance within 10 % (its standard error here is about 4 %); Poisson would be 24
    assert counts.var() / count_variance(CLUSTERED, t) == pytest.approx(1.0, abs=0.1)
    assert counts.var() > 5 * counts.mean()


def test_three_states_and_a_single_state():
    three = MMPP([0.0, 1.0, 10.0], [[-1.0, 0.5, 0.5], [0.2, -0.3, 0.1], [1.0, 1.0, -2.0]])
    pi = three.stationary
    assert pi @ three.generator == pytest.approx(np.zeros(3), abs=1e-12)
    times = three.sample(5e4, rng=3)
    assert times.size / 5e4 == pytest.approx(three.stationary_rate, rel=0.05)
    assert st.kstest(np.diff(times), interval_cdf(three)).pvalue > 1e-3
    one = MMPP([2.0], [[0.0]])
    assert one.stationary_rate == 2.0
    assert st.kstest(np.diff(one.sample(1e4, rng=4)), st.expon(scale=0.5).cdf).pvalue > 1e-3


def test_initial_law_sets_the_first_state():
    # a silent start that switches once, for ever, to rate 2: first kick at Exp(0.5) + Exp(2)
    late = MMPP([0.0, 2.0], [[-0.5, 0.5], [0.0, 0.0]], initial=[1.0, 0.0])
    rng = np.random.default_rng(5)
    first = np.array([late.sample(200.0, rng=rng)[0] for _ in range(4000)])
    assert first.mean() == pytest.approx(2.5, abs=4 * math.sqrt(4.25 / 4000))
    # the absorbing state's law is the unique stationary one
    assert late.stationary == pytest.approx([0.0, 1.0]) and late.stationary_rate == 2.0


def test_a_rate_zero_mmpp_never_kicks():
    assert MMPP([0.0, 0.0], [[-1.0, 1.0], [1.0, -1.0]]).sample(100.0, rng=0).size == 0


def test_sampling_is_reproducible_and_in_the_window():
    a = CLUSTERED.sample(50.0, rng=42)
    assert np.array_equal(a, CLUSTERED.sample(50.0, rng=np.random.default_rng(42)))
    assert a.dtype == np.float64 and a.flags.writeable
    assert np.all(a > 0) and np.all(a <= 50.0) and np.all(np.diff(a) >= 0)
    assert not np.array_equal(a, CLUSTERED.sample(50.0, rng=43))


@settings(max_examples=25, deadline=None)
@given(seed=hs.integers(0, 2**32), t1=hs.floats(1e-3, 3000.0), extra=hs.floats(0.0, 3000.0))
def test_shorter_horizon_is_a_prefix_of_a_longer_one(seed, t1, extra):
    three = MMPP([0.2, 1.0, 3.0], [[-1.0, 0.5, 0.5], [0.2, -0.3, 0.1], [0.0, 2.0, -2.0]])
    for schedule in (CLUSTERED, three):
        short = schedule.sample(t1, rng=seed)
        long = schedule.sample(t1 + extra, rng=seed)
        assert np.array_equal(short, long[long <= t1])


def test_max_kicks_guards_against_runaway_samples():
    with pytest.raises(ValueError, match="max_kicks"):
        CLUSTERED.sample(1e9, rng=0)
    with pytest.raises(ValueError, match="max_kicks"):
        CLUSTERED.sample(1e4, rng=0, max_kicks=100)


# ------------------------------------------------------------------------------ values
@pytest.mark.parametrize("schedule", [
    CLUSTERED,
    MMPP([0.5, 4.0], [[-0.1, 0.1], [0.4, -0.4]], initial=[0.25, 0.75]),
    MMPP([1 / 3, 0.1, 7.0], [[-0.3, 0.1, 0.2], [1e-300, -1e-300, 0.0], [2.0, 0.0, -2.0]]),
])
def test_json_and_pickle_round_trips_are_exact(schedule):
    text = schedule.to_json()
    again = schedules.from_json(text)
    assert again == schedule and hash(again) == hash(schedule)
    assert MMPP.from_json(text) == schedule and again.to_json() == text
    assert pickle.loads(pickle.dumps(schedule)) == schedule
    assert np.array_equal(pickle.loads(pickle.dumps(schedule)).sample(9.0, rng=1),
                          schedule.sample(9.0, rng=1))
    with pytest.raises(ValueError, match="expected a 'poisson'"):
        Poisson.from_json(text)


def test_repr_equality_and_immutability():
    assert repr(CLUSTERED) == (
        "MMPP(rates=[0.5, 4.0], generator=[[-0.1, 0.1], [0.4, -0.4]], initial='stationary')")
    assert CLUSTERED == MMPP(np.array([0.5, 4]), np.array([[-0.1, 0.1], [0.4, -0.4]]))
    assert CLUSTERED != MMPP([0.5, 4.0], [[-0.1, 0.1], [0.4, -0.4]], initial=[0.8, 0.2])
    assert CLUSTERED != Poisson(1.2)
    with pytest.raises(ValueError):
        CLUSTERED.rates[0] = 1.0
    with pytest.raises(AttributeError):
        CLUSTERED.rates = [1.0, 2.0]


BAD = [
    (lambda: MMPP([], np.zeros((0, 0))), ValueError, "rates"),
    (lambda: MMPP([1.0, -1.0], [[-1, 1], [1, -1]]), ValueError, "rates must be >= 0"),
    (lambda: MMPP([1.0, math.inf], [[-1, 1], [1, -1]]), ValueError, "rates must be finite"),
    (lambda: MMPP([[1.0, 2.0]], [[-1, 1], [1, -1]]), ValueError, "rates must be one-dim"),
    (lambda: MMPP(["a"], [[0.0]]), TypeError, "rates"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1]]), ValueError, r"generator must be a square matrix"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, math.nan]]), ValueError, "generator must be fin"),
    (lambda: MMPP([1.0, 2.0], [[1, -1], [1, -1]]), ValueError, r"generator\[0, 1\] must be >= 0"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, -2]]), ValueError, "row 1 sums to -1.0"),
    (lambda: MMPP([1.0, 2.0], "x"), TypeError, "generator"),
    (lambda: MMPP([1.0, 2.0], np.zeros((2, 2))), ValueError, "2 closed classes"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, -1]], initial="start"), ValueError, "initial"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, -1]], initial=[0.5]), ValueError, "2 state prob"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, -1]], initial=[0.5, 0.6]), ValueError, "sum to 1"),
    (lambda: MMPP([1.0, 2.0], [[-1, 1], [1, -1]], initial=[1.5, -0.5]), ValueError, "initial"),
    (lambda: CLUSTERED.sample(0.0), ValueError, "t_max"),
    (lambda: CLUSTERED.sample(1.0, rng=1.5), TypeError, "rng"),
    (lambda: MMPP.from_fit(object()), TypeError, "fit must have rates and generator"),
    (lambda: MMPP.from_fit(types.SimpleNamespace(rates=[1.0], generator=[[0.0]]),
                           stationary=False), ValueError, "fit.initial"),
    (lambda: schedules.from_spec("mmpp", {"rate1": 1.0}), ValueError, "rate0"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1.0, "mu": 2.0}), ValueError, "unknown"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1.0, "q00": 2.0}), ValueError, "q00"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1, "q01": 2.0}), ValueError, "beyond"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1, "rate1": 2, "q01": 1, "q10": 1, "p0": 1},
                                 stationary=False), ValueError, "p0, ..., p1"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1, "rate1": 2, "q01": 1, "q10": 1,
                                          "p0": 1, "p1": 0}, stationary=True),
     ValueError, "exclude"),
    (lambda: schedules.from_spec("mmpp", {"rate0": 1}, window=3.0), ValueError, "window"),
    (lambda: schedules.from_spec("mmpp", times=[1.0, 2.0]), ValueError, "fit_mmpp"),
    (lambda: schedules.from_spec("poisson", {"rate": 1}, window=3.0), ValueError, "window"),
]


@pytest.mark.parametrize("call, error, match", BAD, ids=[f"bad{i}" for i in range(len(BAD))])
def test_bad_input_raises_a_named_error(call, error, match):
    with pytest.raises(error, match=match):
        call()


# ------------------------------------------------------------------------ spec and CLI
def test_from_spec_builds_the_mmpp():
    spec = {"rate0": "0.5", "rate1": 4, "q01": 0.1, "q10": 0.4}
    assert schedules.from_spec("mmpp", spec) == CLUSTERED
    assert schedules.from_spec("mmpp", {**spec, "p0": 1, "p1": 0}) == MMPP(
        [0.5, 4.0], [[-0.1, 0.1], [0.4, -0.4]], initial=[1.0, 0.0])
    # a left-out switching rate is 0 (here: state 2 is entered from 1 and never left)
    three = schedules.from_spec("mmpp", {"rate0": 1, "rate1": 2, "rate2": 3, "q01": 1, "q10": 1,
                                         "q12": 0.5})
    assert three.generator.tolist() == [[-1, 1, 0], [1, -1.5, 0.5], [0, 0, 0]]


def test_cli_writes_mmpp_kicks_and_its_json(tmp_path):
    out = tmp_path / "kicks.parquet"
    args = ["schedule", "mmpp", "-p", "rate0=0.5", "-p", "rate1=4", "-p", "q01=0.1",
            "-p", "q10=0.4", "--t-max", "500", "--seed", "7", "--print-json", "-o", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    times, meta = schedules.read_kick_times(out, with_metadata=True)
    assert np.array_equal(times, CLUSTERED.sample(500.0, rng=7))
    assert schedules.from_dict(meta["schedule"]) == CLUSTERED
    assert CLUSTERED.to_json() in result.output


@pytest.mark.parametrize("args, message", [
    (["mmpp", "-p", "rate0=1", "-p", "q01=1"], "beyond the 1 rates"),
    (["mmpp", "-p", "rate0=1", "-p", "rate1=1", "-p", "q01=-1", "-p", "q10=1"],
     "generator[0, 1] must be >= 0"),
    (["mmpp", "--dist", "gamma", "-p", "rate0=1"], "dist is not used"),
])
def test_cli_reports_bad_mmpp_input(tmp_path, args, message):
    out = tmp_path / "x.csv"
    result = CliRunner().invoke(main, ["schedule", *args, "--t-max", "10", "-o", str(out)])
    assert result.exit_code == 2
    assert message in result.output
    assert not out.exists()


# ------------------------------------------------------------------------ from a fit
def test_a_schedule_from_a_fit_kicks_at_the_fits_stationary_rate():
    # the "must show": MMPP.from_fit(fit).sample(...) at fit.stationary_rate, 5 %
    from kicktimes import stats

    data = [CLUSTERED.sample(100.0, rng=rng) for rng in np.random.default_rng(8).spawn(60)]
    fit = stats.fit_mmpp(data, 100.0, rng=9)
    kicks = MMPP.from_fit(fit)
    assert kicks.stationary_rate == pytest.approx(fit.stationary_rate, rel=1e-12)
    assert np.array_equal(kicks.rates, fit.rates) and kicks.initial == "stationary"
    times = kicks.sample(1e5, rng=10)
    assert times.size / 1e5 == pytest.approx(fit.stationary_rate, rel=0.05)
    # the fitted process is the simulated one (rates within 15 %)
    assert fit.rates == pytest.approx(CLUSTERED.rates, rel=0.15)
    again = MMPP.from_fit(fit, stationary=False)
    assert np.array_equal(again.initial, fit.initial)


# ------------------------------------------------------------------- the sweep's system
def test_mmpp_kicks_fit_the_ics_collisions_or_fall_back_to_poisson():
    from kicktimes.experiment.tasks import MMPP_ROWS, mmpp_kicks
    from kicktimes.stats import MMPP_MIN_EVENTS

    clustered = CLUSTERED.sample(400.0, rng=11)
    schedule, rows = mmpp_kicks(clustered, 400.0, np.random.default_rng(12))
    rows = {name: (value, note) for name, value, note in rows}
    assert isinstance(schedule, MMPP) and set(rows) == {"kick_rate", *MMPP_ROWS}
    assert rows["kick_rate"][0] == pytest.approx(clustered.size / 400.0, rel=0.05)
    assert rows["mmpp_rate_low"][0] < rows["mmpp_rate_high"][0]
    assert rows["mmpp_delta_aic"][0] < -10  # the clustering is plain at 480 kicks
    few = np.sort(np.random.default_rng(13).uniform(0, 100.0, MMPP_MIN_EVENTS - 1))
    schedule, rows = mmpp_kicks(few, 100.0, np.random.default_rng(12))
    assert schedule == Poisson((MMPP_MIN_EVENTS - 1) / 100.0)
    for name, value, note in rows:
        assert note.startswith("Poisson kicks at the IC's rate: 49 collisions")
        assert math.isnan(value) == (name != "kick_rate")


def test_the_mmpp_system_is_run_per_ic_with_its_notes_and_independent_of_blocks():
    import dataclasses

    import pandas as pd

    from kicktimes.experiment import Experiment, run_task

    exp = Experiment(name="mmpp", radii=[0.02, 0.2], n_ics=2, n_steps=1500, tau=0.2,
                     systems=["two_particle", "poisson", "mmpp"],
                     diagnostics=["lyapunov", "autocorrelation"], block_size=2, seed=3)
    res = pd.concat([run_task(exp, task)[0] for task in exp.tasks()], ignore_index=True)
    mine = res[res["system"] == "mmpp"].set_index(["radius", "ic", "diagnostic"])
    assert {"lyapunov", "autocorrelation", "n_kicks", "kick_rate", "mmpp_delta_aic"} <= set(
        mine.index.get_level_values("diagnostic"))
    small, large = mine.loc[0.02], mine.loc[0.2]
    # few collisions at r = 0.02: Poisson kicks, said in the note; a fit at r = 0.2
    assert small.xs("mmpp_rate_low", level="diagnostic")["value"].isna().all()
    assert small.xs("kick_rate", level="diagnostic")["note"].str.contains("fewer than").all()
    assert large.xs("mmpp_rate_low", level="diagnostic")["value"].notna().all()
    # the kick rate is the IC's own collision rate (the fit's stationary rate: about n/T)
    two = res[res["system"] == "two_particle"].set_index(["radius", "ic", "diagnostic"])
    n_over_t = (two.xs("n_pp", level="diagnostic")["value"]
                / two.xs("t_max", level="diagnostic")["value"])
    kick_rate = mine.xs("kick_rate", level="diagnostic")["value"]
    assert np.allclose(kick_rate, n_over_t, rtol=0.1)
    # the same rows whatever the block size (each IC's fit and kicks have their own stream)
    one = dataclasses.replace(exp, block_size=1)
    again = pd.concat([run_task(one, task)[0] for task in one.tasks()], ignore_index=True)
    key = ["radius", "ic", "system", "diagnostic"]
    pd.testing.assert_frame_equal(res.sort_values(key, ignore_index=True),
                                  again.sort_values(key, ignore_index=True))


# ----------------------------------------------------------------------------- reports
def _clustered_store(n_ics=4, t=2000.0):
    """Collisions of a synthetic store: MMPP-2 times for ICs 0, 1, Poisson for the others."""
    from types import SimpleNamespace

    import pandas as pd

    busy = MMPP([0.02, 0.3], [[-0.01, 0.01], [0.05, -0.05]])
    coll = []
    for r in (0.01, 0.02):
        for ic in range(n_ics):
            rng = np.random.default_rng([ic, int(r * 1000)])
            times = (busy if ic < 2 else Poisson(busy.stationary_rate)).sample(t, rng=rng)
            coll.append((r, ic, t, times.size, times))
    collisions = pd.DataFrame(coll, columns=["radius", "ic", "t_window", "n_pp", "pp_times"])
    exp = SimpleNamespace(name="clustered", radii=[0.01, 0.02], n_ics=n_ics, seed=4)
    results = pd.DataFrame(columns=["radius", "ic", "system", "diagnostic", "value", "note"])
    return SimpleNamespace(experiment=exp, results=results, collisions=collisions)


def test_the_report_sets_the_mmpp_against_poisson_and_renewal_with_poisson_twins(tmp_path):
    from kicktimes.render.html import write_outputs
    from kicktimes.report import mmpp, renewal
    from kicktimes.report.context import Context

    ctx = Context(_clustered_store(), n_boot=200, max_ics_model_fits=4)
    secs = renewal.sections(ctx) + mmpp.sections(ctx)
    per_ic = ctx.found.mmpp
    assert len(per_ic) == 8 and per_ic["mmpp_aic"].notna().all()
    # the MMPP-2 wins on the clustered ICs and not on their Poisson twins
    clustered = per_ic["ic"] < 2
    assert per_ic.loc[clustered, "mmpp_best"].all()
    assert not per_ic["null_mmpp_best"].any()
    assert (per_ic.loc[clustered, "rate_high"] / per_ic.loc[clustered, "rate_low"] > 4).all()
    # the Poisson row of the comparison is the renewal section's exponential, same footing
    best = ctx.found.renewal_best.set_index(["radius", "ic"])
    poisson_ics = per_ic[~clustered].set_index(["radius", "ic"])
    exp_best = best.loc[poisson_ics.index, "best_model"] == "exponential"
    assert np.allclose(poisson_ics.loc[exp_best[exp_best].index, "poisson_aic"],
                       best.loc[exp_best[exp_best].index, "best_aic"])
    (effect,) = mmpp.effects(ctx)
    assert effect.estimate == pytest.approx(per_ic["mmpp_best"].mean())
    assert effect.question.startswith("Which model, with a Markov-modulated")
    assert "level: the share on Poisson twins" in effect.rule
    write_outputs(secs, tmp_path, 40)
    assert (tmp_path / "fig09b_mmpp_comparison.png").is_file()
    assert (tmp_path / "mmpp_per_ic.csv").is_file()


def test_the_answers_ask_whether_clustered_kicks_bring_the_disk_closer():
    import pandas as pd

    from kicktimes.report.answers import answers
    from kicktimes.report.controls import COLUMNS

    rows = []
    for system, est in (("poisson", 0.32), ("mmpp", 0.30)):
        for control in ("primary", "paired_median"):
            rows.append({"family": "f", "question": "FTLE", "diagnostic": "ftle",
                         "system": system, "control": control, "estimate": est,
                         "ci_low": est - 0.01, "ci_high": est + 0.01, "verdict": "lower",
                         "robust": True, "depends_on": "", "n_pairs": 10, "detail": ""})
    text = " ".join(answers(pd.DataFrame(rows, columns=list(COLUMNS))))
    assert "Does clustering in the kick times bring the kicked disk closer?" in text
    assert "f: 0.30 against 0.32" in text and "MMPP kicks: ✓ lower: 0.3" in text


def test_analyze_offers_the_mmpp_for_outside_data(tmp_path):
    import pandas as pd

    store = _clustered_store(n_ics=3)
    rows = [(f"s{r:g}-{ic}", t, ic < 2) for r, ic, _, _, times in
            store.collisions.itertuples(index=False) if r == 0.01 for t in times]
    events = pd.DataFrame(rows, columns=["sequence", "time", "clustered"])
    events["clustered"] = events["clustered"].astype(float)
    path = tmp_path / "events.csv"
    events.to_csv(path, index=False)
    out = tmp_path / "page"
    args = ["analyze", str(path), "--window", "0", "2000", "--mmpp", "--mmpp-boot", "39",
            "--n-mc", "19", "--out", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert "- Clustered (MMPP-2)? " in result.output
    assert "\n  Parametric-bootstrap LR test" in result.output
    table = pd.read_csv(out / "mmpp_per_sequence.csv")
    assert len(table) == 3 and table["lr_pvalue"].between(0.025, 1).all()
    assert table.loc[table["sequence"] != "s0.01-2", "mmpp_best"].all()
    # the two clustered sequences: no bootstrap Poisson sample reaches their LR statistic
    assert table.loc[table["sequence"] != "s0.01-2", "lr_pvalue"].eq(1 / 40).all()
    assert (out / "mmpp_comparison.png").is_file()
    findings = (out / "findings.md").read_text()
    assert "**Clustered (MMPP-2)?** clustered (MMPP-2). Parametric-bootstrap" in findings
    # off by default, and said in --help
    help_text = CliRunner().invoke(main, ["analyze", "--help"]).output
    assert "--mmpp" in help_text and "Markov-modulated" in help_text


def test_mmpp_figure_marks_a_quartile_beyond_its_axis_and_says_what_the_bars_are():
    import pandas as pd

    from kicktimes.report.mmpp import mmpp_comparison

    rng = np.random.default_rng(4)
    n = 24
    per_ic = pd.DataFrame({
        "radius": np.repeat([0.01, 0.02], n // 2), "rate": 1.0,
        "mmpp_best": rng.random(n) < 0.5, "mmpp_beats_poisson": True,
        "rate_low": rng.uniform(0.5, 0.9, n), "rate_high": rng.uniform(3, 9, n),
        "switch_low": 0.1, "switch_high": 1.0})
    per_ic.loc[per_ic.index[:8], "rate_high"] = 5e4  # a silent-state fit: far off the axis
    fig = mmpp_comparison(per_ic)
    rates = fig.axes[1]
    assert rates.get_ylim()[1] <= 1e3
    notes = [t.get_text() for t in rates.texts]
    assert "5e+04" in notes  # the clipped upper quartile, at the edge
    assert notes.count("12") == 2  # the number of sequences behind each median
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("Clopper-Pearson" in lab for lab in labels)
    assert any("quartiles" in lab for lab in labels)
    import matplotlib.pyplot as plt

    plt.close(fig)
