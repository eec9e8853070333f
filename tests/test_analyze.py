"""``kicktimes analyze`` / ``stats.analyze``: collision times from any source.

Specifications: the input contract (windows from columns, a second table or an option;
covariates), one-line errors naming column and row, empty sequences counted and listed,
the statistics on known processes, the CLI outputs, and an outside simulator end to end.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from kicktimes import stats
from kicktimes.cli import main
from kicktimes.stats._table import event_table
from kicktimes.stats.findings import findings


def _poisson_rows(rates, t_end=100.0, seed=0, start=0.0):
    rng = np.random.default_rng(seed)
    rows = []
    for k, rate in enumerate(rates):
        n = rng.poisson(rate * (t_end - start))
        for t in np.sort(rng.uniform(start, t_end, n)):
            rows.append((f"s{k}", t, rate))
    return pd.DataFrame(rows, columns=["sequence", "time", "density"])


# ------------------------------------------------------------------ input contract


def test_windows_from_option_columns_and_table_agree():
    df = _poisson_rows([1.0, 2.0])
    a = event_table(df, window=(0.0, 100.0)).sequences
    b = event_table(df.assign(t_start=0.0, t_end=100.0)).sequences
    win = pd.DataFrame({"sequence": ["s0", "s1"], "t_start": 0.0, "t_end": 100.0})
    c = event_table(df, windows=win).sequences
    for other in (b, c):
        assert other["n_events"].tolist() == a["n_events"].tolist()
        assert other["t_window"].tolist() == [100.0, 100.0]


def test_times_are_shifted_to_the_window_start():
    df = pd.DataFrame({"sequence": ["a", "a"], "time": [11.0, 12.5]})
    seq = event_table(df, window=(10.0, 20.0)).sequences
    np.testing.assert_allclose(seq["times"].iloc[0], [1.0, 2.5])
    assert seq["t_window"].iloc[0] == 10.0


def test_sequences_only_in_the_windows_table_are_empty_and_kept():
    df = pd.DataFrame({"sequence": ["a", "a"], "time": [1.0, 2.0]})
    win = pd.DataFrame({"sequence": ["a", "b"], "t_start": 0.0, "t_end": 5.0, "x": [1.0, 2.0]})
    tab = event_table(df, windows=win)
    assert tab.sequences["n_events"].tolist() == [2, 0]
    assert tab.empty_sequences == ["b"]
    assert tab.covariates == ("x",)


def test_event_level_columns_are_not_covariates_but_constant_ones_are():
    df = pd.DataFrame(
        {
            "sequence": ["a", "a", "b"],
            "time": [1.0, 2.0, 1.0],
            "partner": [3, 4, 5],
            "radius": [0.1, 0.1, 0.2],
            "label": ["x", "x", "y"],
        }
    )
    assert event_table(df, window=(0, 5)).covariates == ("radius",)


@pytest.mark.parametrize(
    "events, kwargs, message",
    [
        (
            pd.DataFrame({"sequence": ["a", "a"], "time": [2.0, 1.0]}),
            {"window": (0, 5)},
            "row 1: unsorted times in sequence 'a'",
        ),
        (
            pd.DataFrame({"sequence": ["a", "a"], "time": [1.0, 1.0]}),
            {"window": (0, 5)},
            "row 1: duplicate times in sequence 'a'",
        ),
        (
            pd.DataFrame({"sequence": ["a", "a"], "time": [1.0, 7.0]}),
            {"window": (0, 5)},
            "row 1: column 'time' = 7.0 lies outside the window",
        ),
        (
            pd.DataFrame({"sequence": ["a"], "time": ["x1"]}),
            {"window": (0, 5)},
            "row 0: column 'time' must be numeric, got 'x1'",
        ),
        (pd.DataFrame({"sequence": ["a"], "time": [1.0]}), {}, "no window for its sequences"),
        (
            pd.DataFrame({"sequence": ["a", "b"], "time": [1.0, 1.0]}),
            {"windows": pd.DataFrame({"sequence": ["a"], "t_start": [0.0], "t_end": [5.0]})},
            "no window for sequence 'b'",
        ),
        (
            pd.DataFrame({"sequence": ["a"], "time": [1.0], "t_start": [3.0], "t_end": [2.0]}),
            {},
            "row 0: window of sequence 'a' must satisfy t_start < t_end",
        ),
        (
            pd.DataFrame(
                {
                    "sequence": ["a", "a"],
                    "time": [1.0, 2.0],
                    "t_start": [0.0, 0.5],
                    "t_end": [5.0, 5.0],
                }
            ),
            {},
            "row 1: column 't_start' must be constant within sequence 'a'",
        ),
        (pd.DataFrame({"seq": ["a"], "time": [1.0]}), {"window": (0, 5)}, "no column 'sequence'"),
        (
            pd.DataFrame({"sequence": ["a", None], "time": [1.0, 2.0]}),
            {"window": (0, 5)},
            "row 1: column 'sequence' has a missing sequence id",
        ),
        (
            pd.DataFrame({"sequence": ["a", "a"], "time": [1.0, None]}),
            {"window": (0, 5)},
            "row 1: missing time in sequence 'a'",
        ),
    ],
)
def test_bad_input_gets_one_line_naming_the_column_and_row(events, kwargs, message):
    with pytest.raises(ValueError) as err:
        event_table(events, **kwargs)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_csv_errors_name_the_file_and_its_line(tmp_path):
    path = tmp_path / "events.csv"
    path.write_text("sequence,time\na,1.0\na,oops\n")
    with pytest.raises(
        ValueError,
        match=r"events.csv, row 1 \(line 3\): column 'time' must be "
        r"numeric, got 'oops'",
    ):
        event_table(path, window=(0, 5))


# ------------------------------------------------------------------- the statistics


def test_poisson_sequences_are_consistent_with_poisson_and_rate_scales_linearly():
    df = _poisson_rows([1.0, 1.0, 2.0, 2.0, 4.0, 4.0] * 2, seed=3)
    res = stats.analyze(
        df, window=(0, 100), group="density", rng=2, max_fits_per_group=1, reference="density"
    )
    slope = res.regressions.query("model == 'poisson' and term == 'slope'").iloc[0]
    assert slope["g"] == "log" and slope["ci_low"] < 1.0 < slope["ci_high"]
    assert (res.reference["ci_low"] < 1).all() and (res.reference["ci_high"] > 1).all()
    verdicts = {f.question: f.verdict for f in findings(res)}
    assert verdicts["Poisson?"] == "; ".join(
        f"density = {d}: consistent with Poisson" for d in (1, 2, 4)
    )
    assert verdicts["One rate for all sequences?"] == "; ".join(
        f"density = {d}: consistent with one rate" for d in (1, 2, 4)
    )


def test_regular_sequences_are_not_poisson():
    rows = []
    rng = np.random.default_rng(1)
    for k in range(6):
        t = np.cumsum(rng.gamma(20.0, 1 / 20.0, size=90))  # nearly periodic
        rows += [(f"s{k}", x) for x in t[t < 80]]
    res = stats.analyze(
        pd.DataFrame(rows, columns=["sequence", "time"]),
        window=(0, 80),
        rng=0,
        max_fits_per_group=2,
    )
    assert res.poisson["combined_pvalue"].min() < 1e-3
    best = res.renewal_pooled.sort_values("aic").iloc[0]["model"]
    assert best in ("gamma", "weibull", "lognormal")


def test_empty_sequences_count_in_rates_and_are_listed_as_skipped():
    df = _poisson_rows([1.0, 1.0])
    win = pd.DataFrame({"sequence": ["s0", "s1", "silent"], "t_start": 0.0, "t_end": 100.0})
    res = stats.analyze(df, windows=win, rng=0, max_fits_per_group=0)
    het = res.heterogeneity.iloc[0]
    assert het["n_sequences"] == 3 and het["n_empty"] == 1
    assert het["pooled_rate"] == pytest.approx(len(df) / 300.0)
    assert "silent" in set(res.skipped["sequence"])
    assert res.sequences.set_index("sequence").loc["silent", "n_events"] == 0


def test_covariate_regression_recovers_a_linear_log_rate_on_any_scale():
    rng = np.random.default_rng(5)
    rows, win = [], []
    for k, temp in enumerate(np.repeat([-20.0, 0.0, 20.0, 40.0], 8)):
        rate = math.exp(0.5 + 0.03 * temp)
        rows += [(f"s{k}", t) for t in np.sort(rng.uniform(0, 50, rng.poisson(rate * 50)))]
        win.append((f"s{k}", 0.0, 50.0, temp))
    res = stats.analyze(
        pd.DataFrame(rows, columns=["sequence", "time"]),
        windows=pd.DataFrame(win, columns=["sequence", "t_start", "t_end", "temperature"]),
        rng=0,
        max_fits_per_group=0,
    )
    reg = res.regressions.set_index(["model", "term"])
    assert reg.loc[("poisson", "slope"), "g"] == "linear"  # negative values: no log
    assert reg.loc[("poisson", "slope"), "ci_low"] < 0.03 < reg.loc[("poisson", "slope"), "ci_high"]
    assert reg.loc[("poisson", "intercept"), "estimate"] == pytest.approx(0.5, abs=0.1)


def test_group_must_be_a_column_and_reference_a_covariate():
    df = _poisson_rows([1.0])
    with pytest.raises(ValueError,
                       match=r"group must name a per-sequence column, one of \['density'\]"):
        stats.analyze(df, window=(0, 100), group="nope")
    with pytest.raises(ValueError, match="reference must be one of the covariates"):
        stats.analyze(df, window=(0, 100), reference="nope")


# ---------------------------------------------------------------------------- CLI


def test_cli_writes_findings_html_figures_and_tables(tmp_path):
    df = _poisson_rows([1.0, 1.0, 2.0, 2.0], seed=1)
    df[["sequence", "time"]].to_csv(tmp_path / "events.csv", index=False)
    win = df.groupby("sequence", as_index=False)["density"].first().assign(t_start=0, t_end=100)
    win.to_csv(tmp_path / "windows.csv", index=False)
    out = tmp_path / "report"
    result = CliRunner().invoke(
        main,
        [
            "analyze",
            str(tmp_path / "events.csv"),
            "--windows",
            str(tmp_path / "windows.csv"),
            "--group",
            "density",
            "--out",
            str(out),
            "--max-fits-per-group",
            "1",
            "--dpi",
            "40",
        ],
    )
    assert result.exit_code == 0, result.output
    assert "Poisson?" in result.output
    page = (out / "report.html").read_text()
    assert page.index("Findings") < page.index("Poisson tests of the event times")
    for name in (
        "findings.md",
        "sequences.csv",
        "poisson_tests.csv",
        "rate_homogeneity.csv",
        "renewal_pooled.csv",
        "count_regressions.csv",
        "poisson_rejection_rates.png",
    ):
        assert (out / name).is_file(), name


def test_cli_bad_input_is_one_error_line(tmp_path):
    (tmp_path / "e.csv").write_text("sequence,time\na,2.0\na,1.0\n")
    result = CliRunner().invoke(
        main,
        ["analyze", str(tmp_path / "e.csv"), "--window", "0", "5", "--out", str(tmp_path / "o")],
    )
    assert result.exit_code == 2  # bad input is bad usage, as in every command
    assert result.output.strip().splitlines()[-1] == (
        "Error: e.csv, row 1 (line 3): unsorted times in sequence 'a': 1.0 is earlier than the "
        "time of row 0 (2.0); times must increase strictly within a sequence"
    )
    assert not (tmp_path / "o").exists()


def _poisson_and_clustered(n_per_kind=12, window=200.0, seed=0):
    """Events of ``n_per_kind`` Poisson sequences and as many clustered ones (Neyman-Scott:
    clusters of about 6 events within 0.5 time units), with a text column ``kind``."""
    rng = np.random.default_rng(seed)
    rows, wins = [], []
    for k in range(2 * n_per_kind):
        kind = "poisson" if k < n_per_kind else "clustered"
        if kind == "poisson":
            t = np.sort(rng.uniform(0, window, rng.poisson(100)))
        else:
            centres = rng.uniform(0, window, rng.poisson(15))
            t = np.concatenate([c + rng.exponential(0.5, rng.poisson(6)) for c in centres])
            t = np.sort(t[t < window])
        rows += [(f"s{k}", x) for x in t]
        wins.append((f"s{k}", 0.0, window, kind))
    return (pd.DataFrame(rows, columns=["sequence", "time"]),
            pd.DataFrame(wins, columns=["sequence", "t_start", "t_end", "kind"]))


def test_a_text_group_gets_one_verdict_per_group_in_order_of_appearance(tmp_path):
    events, windows = _poisson_and_clustered()
    events.to_csv(tmp_path / "events.csv", index=False)
    windows.to_csv(tmp_path / "sequences.csv", index=False)
    result = CliRunner().invoke(main, [
        "analyze", str(tmp_path / "events.csv"), "--windows", str(tmp_path / "sequences.csv"),
        "--group", "kind", "--max-fits-per-group", "2", "--n-mc", "99",
        "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    poisson = next(line for line in lines if line.startswith("- Poisson?"))
    assert poisson == ("- Poisson? kind = poisson: consistent with Poisson; "
                       "kind = clustered: not Poisson.")
    statement = lines[lines.index(poisson) + 1]
    assert "kind = poisson: consistent with Poisson: none of 7 tests rejects" in statement
    assert "...." not in statement and "; ..." not in statement
    import re

    page = (tmp_path / "out" / "report.html").read_text()
    page = re.sub(r"<img[^>]*>", "", page)  # the embedded PNGs' base64 is not text
    # no billiard words on the page of outside data
    for word in ("disk", " IC", "ICs", "radius", "radii"):
        assert word not in page, word
    seqs = pd.read_csv(tmp_path / "out" / "sequences.csv")
    assert list(pd.unique(seqs["group"])) == ["poisson", "clustered"]


def test_text_groups_are_categories_drawn_without_joining_lines():
    from kicktimes.report.poisson import poisson_rejection_rates

    events, windows = _poisson_and_clustered(n_per_kind=4)
    res = stats.analyze(events, windows=windows, group="kind", rng=0, max_fits_per_group=0,
                        n_mc=99)
    assert res.events.labels == ("kind",) and "kind" not in res.events.covariates
    fig = poisson_rejection_rates(res.poisson, x="group", xlabel="kind")
    ax = [a for a in fig.axes if a.get_visible()][-1]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["poisson", "clustered"]
    line = ax.containers[0].lines[0]
    assert line.get_linestyle() == "None"
    legend = " ".join(t.get_text() for t in fig.legends[0].get_texts())
    assert "event times" in legend and "IC" not in legend and "disk" not in legend


def test_a_numeric_group_with_few_values_is_ticked_at_its_values():
    from kicktimes.render.figures import XAxis

    t = pd.DataFrame({"clustered": [0, 1, 0]})
    (_, axis) = XAxis("clustered", "clustered").positions(t=t)
    assert axis.values == (0.0, 1.0) and axis.line == "-"


@pytest.mark.parametrize(
    "name, content, message",
    [
        ("empty.csv", "", "empty.csv: the file is empty"),
        ("header.csv", "sequence,time\n", "header.csv: no rows (only a header)"),
        ("prose.parquet", "This is prose, not Parquet.\n",
         "prose.parquet: not a readable Parquet file"),
        ("latin.csv", b"sequence,time\n\x80\xff,1\n", "latin.csv: not a text (UTF-8 CSV) file"),
    ],
)
def test_bad_files_get_one_line_naming_the_file_and_nothing_is_written(
        tmp_path, name, content, message):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    result = CliRunner().invoke(
        main, ["analyze", str(path), "--window", "0", "5", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    errors = [line for line in result.output.splitlines() if line.startswith("Error")]
    assert len(errors) == 1 and errors[0].startswith(f"Error: {message}"), result.output
    assert not (tmp_path / "o").exists()


def test_a_header_only_event_file_with_windows_names_the_file(tmp_path):
    (tmp_path / "events.csv").write_text("sequence,time\n")
    (tmp_path / "w.csv").write_text("sequence,t_start,t_end\na,0,10\nb,0,10\n")
    result = CliRunner().invoke(main, [
        "analyze", str(tmp_path / "events.csv"), "--windows", str(tmp_path / "w.csv"),
        "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert result.output.splitlines()[-1] == (
        "Error: events.csv: no event in any of the 2 sequences: nothing to analyse")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "args, message",
    [
        ([], "give columns 't_start' and 't_end', a --windows table, or --window T_START T_END"),
        (["--window", "0", "5", "--time-col", "t"],
         "no column 't' (the event table); the columns are ['sequence', 'time'] (name the "
         "column with --time-col)"),
        (["--window", "0", "5", "--group", "nope"],
         "--group must name a per-sequence column, one of [], got 'nope'"),
    ],
)
def test_cli_messages_name_the_options(tmp_path, args, message):
    (tmp_path / "e.csv").write_text("sequence,time\na,1.0\n")
    result = CliRunner().invoke(
        main, ["analyze", str(tmp_path / "e.csv"), *args, "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert message in result.output.splitlines()[-1], result.output


# ------------------------------------------------------------ an outside simulator


@pytest.mark.slow
def test_outside_hard_disk_simulator_matches_kinetic_theory(tmp_path):
    """Disks in a box simulated by the ``billiards`` package (not kicktimes): the per-disk
    collision rate agrees with the 2D Enskog rate and scales with the density."""
    pytest.importorskip("billiards")
    import importlib.util
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "analysis" / "outside_billiards.py"
    spec = importlib.util.spec_from_file_location("outside_billiards", script)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    events, seqs = mod.generate(collisions_per_disk=150.0, n_runs=2, seed=7)
    res = stats.analyze(events, windows=seqs, covariates=["density", "kinetic_rate"],
                        group="density", reference="kinetic_rate", rng=0, max_fits_per_group=2)
    ref = res.reference
    assert ((ref["ratio"] > 0.93) & (ref["ratio"] < 1.07)).all(), ref
    reg = res.regressions.set_index(["covariate", "model", "term"])
    b = reg.loc[("kinetic_rate", "poisson", "slope")]
    assert b["ci_low"] < 1.0 < b["ci_high"] or abs(b["estimate"] - 1) < 0.03
    d = reg.loc[("density", "poisson", "slope"), "estimate"]
    assert 0.95 < d < 1.2  # rate ∝ n at low density, g(σ) adds a little


# ------------------------------------------------------------ edge cases and the page


def test_a_group_of_one_sequence_has_no_dispersion_index_and_no_warning():
    df = _poisson_rows([1.0, 2.0, 2.0])  # density 1.0: a single sequence
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = stats.analyze(df, window=(0, 100), group="density", rng=0, max_fits_per_group=0)
    het = res.heterogeneity.set_index("group")
    assert het.loc[1.0, "n_sequences"] == 1 and np.isnan(het.loc[1.0, "dispersion_index"])
    assert np.isfinite(het.loc[2.0, "dispersion_index"])


def test_sequences_without_any_event_are_nothing_to_analyse():
    df = pd.DataFrame({"sequence": ["a", "b"], "time": [None, None]})
    with pytest.raises(ValueError, match="no event in any of the 2 sequences"):
        stats.analyze(df, window=(0, 10), rng=0)


def test_the_poisson_finding_of_a_group_without_testable_sequences_says_so():
    df = pd.DataFrame({"sequence": ["a", "b"] + ["c"] * 6,
                       "time": [None, None, 1.0, 2.5, 3.0, 4.5, 7.0, 9.0],
                       "kind": ["x", "x"] + ["y"] * 6})
    res = stats.analyze(df, window=(0, 10), group="kind", rng=0)
    verdict = {f.question: f.verdict for f in findings(res)}["Poisson?"]
    assert verdict.startswith("kind = x: untested")


def test_a_tie_between_pooled_renewal_models_goes_to_the_first_group():
    import dataclasses

    res = stats.analyze(_poisson_rows([1.0, 2.0]), window=(0, 100), group="density", rng=0,
                        max_fits_per_group=0)
    pooled = pd.DataFrame({"group": [1.0, 1.0, 2.0, 2.0],
                           "model": ["weibull", "gamma", "gamma", "weibull"],
                           "aic": [1.0, 5.0, 1.0, 5.0], "delta_aic": [0.0, 4.0, 0.0, 4.0],
                           "n": 50})
    (renewal,) = [f for f in findings(dataclasses.replace(res, renewal_pooled=pooled))
                  if f.question == "Which renewal model?"]
    assert renewal.verdict == "density = 1: weibull (clear); density = 2: gamma (clear)"


def test_the_page_draws_the_figures_against_the_group_values_and_names(tmp_path):
    from kicktimes.report.analyze_page import write_analysis
    from kicktimes.report.poisson import poisson_rejection_rates

    df = _poisson_rows([1.0, 1.0, 2.0, 2.0, 4.0, 4.0], seed=2)
    df["density"] *= 100.0  # far outside the disk radii
    res = stats.analyze(df, window=(0, 100), group="density", rng=0, max_fits_per_group=1)
    fig = poisson_rejection_rates(res.poisson, alpha=res.alpha, x="group", xlabel="density")
    ax = [a for a in fig.axes if a.get_visible()][-1]
    assert ax.get_xlabel() == "density"
    np.testing.assert_array_equal(ax.containers[0].lines[0].get_xdata(), [100.0, 200.0, 400.0])
    page = write_analysis(res, tmp_path / "grouped", dpi=30).read_text()
    assert page.count("<img") == 3 and '<details class="contents">' in page
    # the answers come first, the collapsed contents after them
    assert page.index('id="findings"') < page.index('<details class="contents">')
    # without a group every sequence is in the one group "all", drawn as a labelled tick
    ungrouped = stats.analyze(df, window=(0, 100), rng=0, max_fits_per_group=1)
    fig = poisson_rejection_rates(ungrouped.poisson, x="group", xlabel="group")
    ax = [a for a in fig.axes if a.get_visible()][-1]
    fig.canvas.draw()
    assert [t.get_text() for t in ax.get_xticklabels()] == ["all"]
    assert write_analysis(ungrouped, tmp_path / "all", dpi=30).is_file()
