"""One standard for "Poisson": a calibrated test and an effect outside a band stated in
advance (`stats.poisson_verdict`), and the shared null-calibration file."""

import itertools

import numpy as np
import pandas as pd
import pytest

from kicktimes.render.pages import NULL_CALIBRATION_COLUMNS, write_null_calibration
from kicktimes.stats import poisson_rule, poisson_verdict, ratio_verdict, rejection_verdict


@pytest.mark.parametrize("reject, dispersion, expected", [
    ((0.37, 0.41), (1.31, 1.47), "not Poisson"),
    ((0.37, 0.41), (0.60, 0.80), "not Poisson"),
    ((0.37, 0.41), (1.03, 1.13), "inconclusive"),      # D straddles the band's edge
    ((0.08, 0.11), (1.01, 1.06), "not Poisson, D within 10 %"),
    ((0.045, 0.06), (0.97, 1.04), "Poisson within 10 %"),
    ((0.045, 0.06), (1.2, 1.3), "inconclusive"),       # large D, the test does not reject
    ((0.01, 0.02), (0.97, 1.04), "inconclusive"),      # below the calibrated level
    ((np.nan, 0.06), (0.97, 1.04), "inconclusive"),
])
def test_the_verdict_needs_both_a_calibrated_rejection_and_an_effect(reject, dispersion,
                                                                     expected):
    low, high = dispersion
    assert poisson_verdict(*reject, null_level=0.05, dispersion_low=low,
                           dispersion_high=high) == expected


def test_the_verdict_is_symmetric_with_the_ratio_rule():
    # the dispersion index is read with the band of every ratio: 0.921 [0.915, 0.926]
    # is "within 10 %" as a ratio, so as D it is Poisson within 10 % at a nominal share
    assert ratio_verdict(0.915, 0.926) == "within 10 %"
    assert poisson_verdict(0.04, 0.06, null_level=0.05, dispersion_low=0.915,
                           dispersion_high=0.926) == "Poisson within 10 %"
    # and D = 1.08 [1.03, 1.13] is not "not Poisson"
    assert poisson_verdict(0.3, 0.4, null_level=0.05, dispersion_low=1.03,
                           dispersion_high=1.13) == "inconclusive"


def test_the_rejection_is_read_against_the_calibrated_level_not_alpha():
    # a test whose null streams reject 8 % (not nominal): 10 % of runs is at that level
    assert rejection_verdict(0.09, 0.11, alpha=0.05) == "above nominal"
    assert poisson_verdict(0.09, 0.11, null_level=0.08, dispersion_low=0.95,
                           dispersion_high=1.05) == "Poisson within 10 %"


def test_every_combination_gives_one_of_four_verdicts_and_the_rule_names_them():
    values = [0.0, 0.03, 0.05, 0.07, 0.1, 0.2, np.nan]
    d = [0.5, 0.89, 0.95, 1.05, 1.11, 1.5]
    seen = {poisson_verdict(lo, hi, null_level=0.05, dispersion_low=dlo, dispersion_high=dhi)
            for lo, hi in itertools.combinations(values, 2)
            for dlo, dhi in itertools.combinations(d, 2)}
    assert seen == {"not Poisson", "not Poisson, D within 10 %", "Poisson within 10 %",
                    "inconclusive"}
    rule = poisson_rule()
    assert "[0.9, 1.1]" in rule and "null calibration" in rule


def _rows(data, share):
    return pd.DataFrame({"data": [data], "test": ["uniformity_ks"], "design": ["Poisson"],
                         "alpha": [0.05], "n_runs": [100], "n_clusters": [100],
                         "share": [share], "ci_low": [share - 0.01],
                         "ci_high": [share + 0.01]})


def test_each_study_owns_its_rows_of_the_shared_calibration_file(tmp_path):
    write_null_calibration(tmp_path, "paper", _rows("family_a", 0.05))
    write_null_calibration(tmp_path, "disks", _rows("N=10", 0.2))
    path = write_null_calibration(tmp_path, "paper", _rows("family_b", 0.049))
    table = pd.read_csv(path)
    assert tuple(table.columns) == NULL_CALIBRATION_COLUMNS
    assert sorted(zip(table["study"], table["data"], strict=True)) == [("disks", "N=10"),
                                                          ("paper", "family_b")]
    assert dict(zip(table["data"], table["verdict"], strict=True)) == {"N=10": "above nominal",
                                                          "family_b": "nominal"}
    assert [p.name for p in tmp_path.iterdir()] == ["null_calibration.csv"]


def test_rows_without_a_column_are_refused_naming_it(tmp_path):
    with pytest.raises(ValueError, match="n_clusters"):
        write_null_calibration(tmp_path, "paper", _rows("a", 0.05).drop(columns="n_clusters"))


def test_other_statistics_are_read_against_1_and_an_unknown_one_is_refused(tmp_path):
    d = _rows("N=2", 0.0).drop(columns="share").assign(
        statistic="D", value=5.06, ci_low=4.47, ci_high=5.69)
    table = pd.read_csv(write_null_calibration(tmp_path, "disks", d))
    assert table.loc[0, "statistic"] == "D" and table.loc[0, "verdict"] == "higher"
    with pytest.raises(ValueError, match="statistic must be one of"):
        write_null_calibration(tmp_path, "disks", d.assign(statistic="mean"))
