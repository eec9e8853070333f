"""The gas page's one answer to "Poisson?": every statistic against its null
(kicktimes.studies.disks.readings, kicktimes.studies.disks.versus_null)."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from kicktimes.studies.disks.readings import answer_table, poisson_answer, summary_lines
from kicktimes.studies.disks.versus_null import (
    MARGINS,
    aic_margin,
    boltzmann_bin_hazard,
    gamma_shape_mle,
)

PAGE = Path(__file__).resolve().parents[1] / "docs" / "results" / "disks.md"


def _vn(n, **diffs):
    """A versus_null row whose every statistic is at its null but for ``diffs``:
    ``{statistic: (low, high)}`` of statistic - null."""
    row = {"geometry": "g", "rule": "elastic", "n_disks": n, "n_runs": 16,
           "d_n_needed": np.nan}
    for s, m in MARGINS.items():
        lo, hi = diffs.get(s, (-m / 2, m / 2))
        row.update({s: 1.0 + (lo + hi) / 2, f"{s}_low": 1.0 + lo, f"{s}_high": 1.0 + hi,
                    f"null_{s}": 1.0, f"null_{s}_low": 0.98, f"null_{s}_high": 1.02,
                    f"{s}_diff": (lo + hi) / 2, f"{s}_diff_low": lo, f"{s}_diff_high": hi})
        row[f"{s}_verdict"] = ("at its null" if -m <= lo and hi <= m else
                               "above its null" if lo > m else
                               "below its null" if hi < -m else "inconclusive")
    return row


def _bins(n, diffs=((-0.01, 0.01),) * 3):
    m = MARGINS["hazard_first"]
    rows = []
    for b, (lo, hi) in enumerate(diffs):
        rows.append({"geometry": "g", "rule": "elastic", "n_disks": n, "t_low": float(b),
                     "t_high": float(b + 1), "diff": (lo + hi) / 2, "diff_low": lo,
                     "diff_high": hi,
                     "verdict": ("at its null" if -m <= lo and hi <= m else
                                 "above its null" if lo > m else
                                 "below its null" if hi < -m else "inconclusive")})
    return pd.DataFrame(rows)


def test_the_answer_is_poisson_only_when_every_statistic_is_at_its_null():
    assert poisson_answer({"D": "at its null", "KS share": "at its null"})[0] == "Poisson"
    answer, by, others = poisson_answer({"D": "at its null", "KS share": "above its null",
                                         "gamma shape": "inconclusive"})
    assert (answer, by, others) == ("not Poisson", ["KS share"], ["D", "gamma shape"])
    answer, by, others = poisson_answer({"D": "inconclusive", "KS share": "at its null"})
    assert (answer, by, others) == ("not resolved", ["D"], ["KS share"])
    with pytest.raises(ValueError, match="verdicts"):
        poisson_answer({"D": "within 10 %"})
    with pytest.raises(ValueError, match="verdicts"):
        poisson_answer({})


def test_a_d_at_its_null_does_not_hide_a_departure_of_the_other_statistics():
    # the packing 0.2 elastic case of the referee: D on its null, the gamma shape, a late
    # hazard bin and the exponential's AIC away from theirs
    vn = pd.DataFrame([_vn(1000, gamma=(-0.045, -0.025)), _vn(30), _vn(100, d=(0.02, 0.3))])
    bins = pd.concat([_bins(1000, ((-0.01, 0.01), (-0.097, -0.045))), _bins(30),
                      _bins(100)])
    renewal = pd.DataFrame({"geometry": "g", "rule": "elastic", "n_disks": [1000, 30, 100],
                            "delta_aic_exponential": [72.0, 1.0, 1.5],
                            "n_intervals": 120000})
    replicate = pd.DataFrame({"geometry": "g", "rule": "elastic", "n_disks": [1000, 30, 100],
                              "replicate_d": 1.067, "replicate_diff": [0.04, 0.0, 0.01],
                              "replicate_diff_low": [0.0, -0.03, -0.02],
                              "replicate_diff_high": [0.08, 0.03, 0.04]})
    a = answer_table(vn, bins, renewal, replicate).set_index("n_disks")
    assert a.loc[1000, "answer"] == "not Poisson"
    assert a.loc[1000, "by"] == "gamma shape; hazard bins; ΔAIC"
    assert a.loc[1000, "D_verdict"] == "at its null"
    assert a.loc[1000, "replicate D_verdict"] == "inconclusive"
    assert "1 of 2 bins depart" in a.loc[1000, "hazard bins_text"]
    # every statistic at its null: Poisson
    assert a.loc[30, "answer"] == "Poisson" and a.loc[30, "others"] == ""
    # D's interval reaches past its margin, nothing departs: not resolved, by D alone
    assert a.loc[100, "answer"] == "not resolved" and a.loc[100, "by"] == "D"
    text = "\n".join(summary_lines(a.reset_index(), vn))
    # the first table is each family's largest N
    assert "| g, elastic, N = 1000 |" in text
    # the answer names the statistics that disagree with it
    assert ("**not Poisson** (by gamma shape, hazard bins, ΔAIC, 3 of 6; at its null: D, "
            "KS share)") in text


def test_a_verdict_the_replicate_changes_is_not_read_in_the_answer():
    # packing 0.2, elastic at N = 1000 on the page: the first hazard bin departs in the
    # primary (+0.129 [0.039, 0.213]) and not in the replicate (+0.072 [-0.006, 0.151])
    m = MARGINS["hazard_first"]
    vn = pd.DataFrame([_vn(1000, gamma=(-0.039, -0.021))])
    bins = _bins(1000, ((0.039, 0.213), (-0.01, 0.01)))
    seed_bins = _bins(1000, ((-0.006, 0.151), (-0.01, 0.01)))
    renewal = pd.DataFrame({"geometry": "g", "rule": "elastic", "n_disks": [1000],
                            "delta_aic_exponential": [72.0], "n_intervals": 120000})
    # the replicate keeps the gamma shape's departure and the ΔAIC
    seed_vn = pd.DataFrame([_vn(1000, gamma=(-0.05, -0.03))])
    a = answer_table(vn, bins, renewal, seed_vn=seed_vn, seed_bins=seed_bins,
                     seed_renewal=renewal.assign(delta_aic_exponential=60.0)).iloc[0]
    assert a["hazard bins_verdict"] == "above its null" and 0.039 > m
    assert a["replicate_changed"] == "hazard bins"
    assert a["answer"] == "not Poisson" and a["by"] == "gamma shape; ΔAIC"
    assert "the replicate keeps 0 of the 1" in a["hazard bins_text"]
    # a replicate that loses the gamma shape and the ΔAIC too: nothing departs that it keeps
    b = answer_table(vn, bins, renewal, seed_vn=pd.DataFrame([_vn(1000)]),
                     seed_bins=seed_bins,
                     seed_renewal=renewal.assign(delta_aic_exponential=1.0)).iloc[0]
    assert b["replicate_changed"] == "gamma shape; hazard bins; ΔAIC"
    assert b["answer"] == "not resolved"
    text = "\n".join(summary_lines(pd.DataFrame([b]), vn))
    assert "changed by the replicate: gamma shape, hazard bins, ΔAIC" in text
    # without a replicate the primary's verdicts stand
    c = answer_table(vn, bins, renewal).iloc[0]
    assert c["answer"] == "not Poisson" and c["replicate_changed"] == ""


def test_a_difference_beyond_a_margin_edge_that_excludes_0_says_its_side():
    from kicktimes.studies.disks.versus_null import EDGE_VERDICTS, edge_null_verdict

    m = MARGINS["d"]
    # r = 0.0045, mirror, N = 1000 on the page: D - null +0.083 [+0.018, +0.157]
    assert edge_null_verdict(0.018, 0.157, m) == EDGE_VERDICTS[0]
    assert edge_null_verdict(-0.157, -0.018, m) == EDGE_VERDICTS[1]
    assert edge_null_verdict(-0.014, 0.140, m) == "inconclusive"  # contains 0
    assert edge_null_verdict(0.108, 0.239, m) == "above its null"
    assert edge_null_verdict(-0.06, 0.065, m) == "at its null"
    # an edge verdict neither departs nor is at its null: the answer is not resolved
    assert poisson_answer({"D": EDGE_VERDICTS[0], "KS share": "at its null"})[0] == (
        "not resolved")


def test_the_aic_margin_is_the_gain_of_a_gamma_at_the_margin_shape():
    from scipy import stats

    k, n = 1.0 - MARGINS["gamma"], 400_000
    x = stats.gamma(k, scale=1 / k).rvs(n, random_state=np.random.default_rng(3))
    gain = 2 * (stats.gamma(*stats.gamma.fit(x, floc=0)).logpdf(x).sum()
                - stats.expon(scale=x.mean()).logpdf(x).sum()) - 2
    assert gain == pytest.approx(aic_margin(n), rel=0.35)
    assert aic_margin(2 * n) > 2 * aic_margin(n)


def test_the_gamma_shape_is_the_likelihood_root():
    from scipy import stats

    x = stats.gamma(0.95).rvs(50_000, random_state=np.random.default_rng(4))
    s = np.log(x.mean()) - np.log(x).mean()
    assert float(gamma_shape_mle(s)) == pytest.approx(stats.gamma.fit(x, floc=0)[0], rel=1e-6)


def test_the_boltzmann_hazard_per_bin_follows_its_curve():
    from kicktimes.stats import dilute_tagged_disk

    h = boltzmann_bin_hazard("elastic", (0.0, 0.01, 1.0, 1.1, 5.0, 5.01))
    curve = dilute_tagged_disk("elastic").hazard([0.005, 1.05, 5.005])
    np.testing.assert_allclose(h[[0, 2, 4]], curve, rtol=2e-3)
    assert h[0] > h[1] > h[2] > h[3] > h[4]


def test_every_d_verdict_on_the_published_page_names_its_null_value():
    text = PAGE.read_text(encoding="utf-8")
    body = text.split("## Where the numbers come from")[0]
    stated = 0
    for line in body.split("\n"):
        # a D stated with its value carries its null's value on the same line
        for _ in re.finditer(r"\bD (\d[\d.]*) \[", line):
            stated += 1
            assert re.search(r"null( D)? \(?\d", line), line
        # a table of D's verdicts reads D as a difference from its null
        if line.startswith("|") and re.search(r"\bD\b", line) and "---" not in line:
            if line.count("|") > 3 and not re.match(r"\| [\d]", line):
                assert "null D" in line or "null" in line, line
    assert stated >= 1
    # the D readings' table: every row a difference from the null with its verdict
    rows = body.split("## D against its null at every N")[1].split("\n\n")[1].split("\n")
    assert rows[0].startswith("| N |") and len(rows) >= 4
    for row in rows[2:]:
        assert re.search(r"[+−]\d\.\d{3} \[[+−]\d", row), row
    # and no D is read against 1 or a 10 % band
    assert "D within 10 %" not in body and "Poisson within 10 %" not in body


def test_the_published_page_is_short_and_opens_with_five_answers():
    text = PAGE.read_text(encoding="utf-8")
    assert len(text.split()) <= 2500
    lines = text.split("\n")
    first = next(m for m, line in enumerate(lines) if line.startswith("|"))
    answers = [line for line in lines[:first] if re.match(r"\d\. \*\*", line)]
    assert 1 <= len(answers) <= 5
    assert all("[" in a and "Caveat" in a for a in answers), answers
