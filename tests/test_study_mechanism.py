"""kicktimes reproduce --study mechanism: the page from the numbers of each rule, its
cache, at a tiny size (the mirror rule only)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from conftest import assert_provenance, built_study, refuse_simulations, table_cells

from kicktimes.stats import D_MARGIN, format_interval, null_verdict, ratio_reading, ratio_verdict
from kicktimes.studies.mechanism import analysis, page, run

TINY = run.MechanismScale(10, 1000.0, 1, n_boot=20)


def _placeholders(results, folder, **kwargs):
    """`write_figures` without drawing (the figures cost twice the tiny analysis; the
    slow test below draws them)."""
    for name in run.FIGURES:
        (folder / f"mechanism_{name}.png").write_bytes(f"{name} {sorted(results)}".encode())


built = built_study("mechanism", run, TINY, [(run, "RULES", {"mirror": "mechanism"}),
                                             (run, "write_figures", _placeholders)])


def test_the_page_names_the_command_and_reads_its_table(built):
    out, page = built
    assert page == out / "results-mechanism" / "mechanism.md"
    text = page.read_text(encoding="utf-8")
    generated = text.splitlines()[2]
    assert generated.startswith("Generated ")
    assert "(`kicktimes reproduce --study mechanism --scale quick`)" in generated
    assert "[table](mechanism/mechanism_numbers.csv)" in generated and str(out) not in text
    tab = pd.read_csv(page.parent / "mechanism" / "mechanism_numbers.csv")
    run_rows = tab[tab["method"] == "run"].set_index("quantity")["estimate"]
    assert run_rows.to_dict() == {"n_ics": 10, "t_max": 1000, "twins": 1, "seed": 29}
    section = text.split("## The mirror rule")[1]
    cells = table_cells(section, "Γ-rescaled hazard, t > 5")
    groups = [("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02)]
    for k, (method, r) in enumerate(groups):
        row = tab[(tab["method"] == method) & (tab["radius"] == r)
                  & (tab["quantity"] == "rescaled_hazard_late")].iloc[0]
        if pd.notna(row["estimate"]):
            assert cells[1 + k].startswith(format_interval(
                row["estimate"], row["ci_low"], row["ci_high"], edges=(0.9, 1.0, 1.1)))
            verdict = ratio_reading(row["ci_low"], row["ci_high"])
            assert cells[1 + k].split(" (")[0].endswith(verdict)
            assert ("not resolved at this size" in cells[1 + k]) == (verdict == "inconclusive")
    for name in run.FIGURES:
        assert (page.parent / "mechanism" / f"mechanism_{name}.png").read_bytes().startswith(
            name.encode())


def test_a_rerun_reuses_each_rule_s_numbers_and_figures(built, monkeypatch):
    out, page = built
    monkeypatch.setitem(run.SCALES, "quick", TINY)
    monkeypatch.setattr(run, "RULES", {"mirror": "mechanism"})
    refuse_simulations(monkeypatch, run, "simulate")
    again = run.reproduce(out, results_dir=out / "again", command="kicktimes reproduce "
                          "--study mechanism")
    assert "(`kicktimes reproduce --study mechanism`)" in again.read_text(encoding="utf-8")
    for name in ["mechanism_numbers.csv"] + [f"mechanism_{n}.png" for n in run.FIGURES]:
        assert ((out / "again" / "mechanism" / name).read_bytes()
                == (page.parent / "mechanism" / name).read_bytes()), name
    # other parameters are another computation
    monkeypatch.setitem(run.SCALES, "quick", run.MechanismScale(10, 1000.0, 1, seed=30,
                                                                n_boot=20))
    with pytest.raises(AssertionError, match="simulated again"):
        run.reproduce(out, results_dir=out / "other")


def test_the_whole_early_hazard_is_read_not_its_first_bin_alone(built):
    _, page = built
    text = page.read_text(encoding="utf-8")
    tab = pd.read_csv(page.parent / "mechanism" / "mechanism_numbers.csv")
    section = text.split("## The mirror rule")[1]
    low_cells = table_cells(section, "hazard minimum over t < 4 / rate vs its Poisson null")
    groups = [("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02)]
    for k, (method, r) in enumerate(groups):
        g = tab[(tab["method"] == method) & (tab["radius"] == r)]
        bins = g[g["quantity"].str.match(r"^hazard_nonsticky_bin_.*_over_rate$")]
        assert bins["note"].tolist()[0] == "bin [0, 0.5)" and len(bins) == 7
        first = g[g["quantity"] == "hazard_nonsticky_first_bin_over_rate"].iloc[0]
        assert bins["estimate"].iloc[0] == pytest.approx(first["estimate"])
        low = g[g["quantity"] == "hazard_nonsticky_min_over_rate"].iloc[0]
        at = bins["estimate"].to_numpy().argmin()
        assert low["estimate"] == pytest.approx(bins["estimate"].min())
        assert low["note"] == bins["note"].iloc[at]
        assert low_cells[1 + k].endswith(f"({low['note']} time units)")
        # read against the Poisson null of its own bin, not against 1
        a, b = low["note"].removeprefix("bin [").rstrip(")").split(", ")
        null = g[g["quantity"] == f"hazard_nonsticky_bin_{a}_{b}_poisson_null"].iloc[0]
        diff = g[g["quantity"] == "hazard_min_minus_null"].iloc[0]
        assert diff["estimate"] == pytest.approx(low["estimate"] - null["estimate"], abs=1e-5)
        verdict = null_verdict(diff["ci_low"], diff["ci_high"], margin=analysis.HAZARD_NULL_MARGIN)
        assert f"vs {null['estimate']:.3f}: {verdict}" in low_cells[1 + k]
        lower = [b.note.removeprefix("bin ") for b in bins.itertuples()
                 if ratio_verdict(b.ci_low, b.ci_high) == "lower"]
        count = g[g["quantity"] == "hazard_nonsticky_bins_lower"].iloc[0]
        assert count["estimate"] == len(lower)
        assert count["note"].endswith(", ".join(lower) or "none")
    assert "hazard's minimum over t < 4" in text.split("## The mirror rule")[0]


@pytest.mark.slow
def test_every_figure_the_page_links_is_drawn(tmp_path):
    from kicktimes.studies.mechanism.page import rule_section

    table = run.run_rule("elastic", TINY, tmp_path)
    assert set(table["rule"]) == {"elastic"}
    table = pd.concat([run.public_names(table),
                       run._cached_profile(tmp_path, "elastic", TINY, 1, print),
                       run._cached_null(tmp_path, "elastic", TINY, 1, print)],
                      ignore_index=True)
    table = pd.concat([table, pd.DataFrame(analysis.against_null(table))], ignore_index=True)
    drawn = {p.name for p in tmp_path.glob("mechanism_*.png")}
    assert drawn == {f"mechanism_{name}.png" for name in run.FIGURES}
    text = "\n".join(rule_section(table, "mechanism/elastic"))
    for name in ("hazard", "hazard_normalised", "battery"):
        assert f"(mechanism/elastic/mechanism_{name}.png)" in text


def test_the_page_ends_with_where_its_numbers_come_from(built):
    _, page = built
    rows = assert_provenance(page)
    # one table per rule of the run (here the mirror rule only), each from both functions
    assert {csv for csv, _, _ in rows} == {f"{p.parent.relative_to(page.parent)}/{p.name}"
                                           for p in page.parent.rglob("*.csv")}
    assert [f for _, _, f in rows] == [
        "kicktimes.studies.mechanism.analysis.analyse",
        "kicktimes.studies.mechanism.analysis.hazard_profile_rows",
        "kicktimes.studies.mechanism.analysis.poisson_null_rows",
        "kicktimes.studies.mechanism.analysis.against_null"]


def _first_table_at(text):
    """The index of the first line of the page's first Markdown table."""
    lines = text.splitlines()
    return lines, next(i for i, x in enumerate(lines) if x.startswith("|"))


def test_the_page_opens_with_at_most_five_one_line_answers_before_its_first_table(built):
    _, page_path = built
    lines, first = _first_table_at(page_path.read_text(encoding="utf-8"))
    answers = [x for x in lines[:first] if x.startswith("- ")]
    assert 1 <= len(answers) <= page.FIRST_SCREEN_MAX
    assert not [x for x in answers if "caveat" not in x]
    # one number with its interval each, unless no group has an excess to share out
    # (or the size that would resolve a share inside its own noise)
    assert not [x for x in answers if "[" not in x and "no group with an excess" not in x
                and "no interval ends there" not in x and "needs ≈" not in x]
    assert not any(x.startswith("Verdicts of") for x in lines[:first])


def test_the_first_screen_refuses_a_sixth_answer(monkeypatch, built):
    monkeypatch.setattr(page, "FIRST_SCREEN_MAX", 2)
    _, page_path = built
    tab = page.load(page_path.parent / "mechanism")
    with pytest.raises(ValueError, match="at most 2"):
        page.first_screen([tab])


def test_each_rate_dispersion_verdict_names_its_poisson_null(built):
    _, page_path = built
    text = page_path.read_text(encoding="utf-8")
    tab = page.load(page_path.parent / "mechanism")
    cells = table_cells(text.split("## The mirror rule")[1],
                        "rate dispersion across ICs vs its Poisson null")
    for k, (method, r) in enumerate(page.GROUPS):
        g = tab[(tab["method"] == method) & (tab["radius"] == r)].set_index("quantity")
        obs, null = g.loc["observed_rate_dispersion_across_ics_nonsticky"], g.loc[
            "rate_dispersion_poisson_null"]
        diff = g.loc["rate_dispersion_minus_null"]
        assert diff["estimate"] == pytest.approx(obs["estimate"] - null["estimate"], abs=1e-5)
        verdict = null_verdict(diff["ci_low"], diff["ci_high"], margin=D_MARGIN)
        assert f"vs {null['estimate']:.3f}: {verdict} (difference " in cells[1 + k]
        assert diff["note"].startswith(verdict)
    # the old name, read against 1, is gone from the page and from the CSV
    assert "dispersion index" not in text and "index of dispersion" not in text
    assert not tab["quantity"].str.contains("dispersion_index").any()
    assert not tab["note"].fillna("").str.contains("index of dispersion").any()


def test_a_poisson_ensemble_s_rate_dispersion_is_its_own_null():
    """Constructed data with a known answer: equal-rate runs are a Poisson ensemble, so the
    null's mean is about 1 and a Poisson group's dispersion lies at its null, while
    runs of two rates lie above it."""
    from types import SimpleNamespace

    rng = np.random.default_rng(4)
    counts = rng.poisson(40.0, 400)
    runs = [SimpleNamespace(n_pp=int(n), t_max=2000.0) for n in counts]
    null = analysis.poisson_null_rows(("paper", 0.01), runs, rng=rng, n_draws=2000)[0]
    assert null["estimate"] == pytest.approx(1.0, abs=0.01)
    assert null["ci_low"] < 1 < null["ci_high"]

    def table(n):
        d = n.var(ddof=1) / n.mean()
        picks = rng.integers(0, n.size, (2000, n.size))
        boot = np.array([x.var(ddof=1) / x.mean() for x in n[picks]])
        return pd.DataFrame({"rule": "mirror", "method": "paper", "radius": 0.01,
                             "quantity": ["observed_rate_dispersion_across_ics_nonsticky",
                                          "rate_dispersion_poisson_null"],
                             "estimate": [d, null["estimate"]],
                             "ci_low": [np.quantile(boot, 0.025), null["ci_low"]],
                             "ci_high": [np.quantile(boot, 0.975), null["ci_high"]],
                             "note": ""})

    mixed = np.r_[rng.poisson(20.0, 200), rng.poisson(60.0, 200)]
    at = analysis.against_null(table(counts))[0]
    above = analysis.against_null(table(mixed))[0]
    assert at["ci_low"] < 0 < at["ci_high"]          # no excess: not decomposed
    assert above["note"].startswith("above its null")
    assert above["estimate"] == pytest.approx(mixed.var(ddof=1) / mixed.mean()
                                              - null["estimate"])


def test_the_hazard_null_is_flat_for_equal_rates_and_falls_for_a_rate_mixture():
    """Known answers: Poisson streams at one rate have a flat hazard (1 in every bin);
    at two rates the pooled first bin is about E[rate^2] / E[rate]^2 of the pooled rate
    and the later bins lower."""
    from types import SimpleNamespace

    rng = np.random.default_rng(0)
    equal = [SimpleNamespace(n_pp=40, t_max=2000.0) for _ in range(10)]
    rows = {r["quantity"]: r for r in analysis.poisson_null_rows(("paper", 0.01), equal,
                                                                rng=rng, n_draws=10)}
    bins = [q for q in rows if q.endswith("_poisson_null") and q.startswith("hazard")]
    assert len(bins) == 7 and all(rows[q]["estimate"] == pytest.approx(1.0) for q in bins)
    mixed = [SimpleNamespace(n_pp=n, t_max=2000.0) for n in (20, 60) * 5]
    rows = {r["quantity"]: r for r in analysis.poisson_null_rows(("paper", 0.01), mixed,
                                                                rng=rng, n_draws=10)}
    lam = np.array([20, 60]) / 2000.0
    first = rows["hazard_nonsticky_bin_0_0.5_poisson_null"]["estimate"]
    assert first == pytest.approx((lam ** 2).mean() / lam.mean() ** 2, rel=1e-3)
    assert rows["hazard_nonsticky_bin_3_4_poisson_null"]["estimate"] < first


def test_the_rate_dispersion_null_refuses_bad_input():
    from types import SimpleNamespace

    runs = [SimpleNamespace(n_pp=0, t_max=100.0) for _ in range(3)]
    with pytest.raises(ValueError, match="runs"):
        analysis.poisson_null_rows(("paper", 0.01), runs, rng=np.random.default_rng(0))
    with pytest.raises(ValueError, match="n_draws"):
        analysis.poisson_null_rows(("paper", 0.01), runs, rng=np.random.default_rng(0),
                                      n_draws=1)


def test_an_inconclusive_ratio_names_the_size_that_would_resolve_it():
    from kicktimes.stats import equivalence_sample_size

    # half-width 0.15 at 200 ICs around 1: the CI must shrink into [0.9, 1.1]
    se = 0.3 / (2 * page.Z95)
    assert page.needed_ics(1.0, 0.85, 1.15, 200) == (
        f"not resolved at this size; needs ≈ {equivalence_sample_size(se, 200, margin=0.1)} ICs")
    # an estimate 0.05 inside the band has half the room: four times the ICs
    n1 = int(page.needed_ics(1.0, 0.9, 1.1, 100).split("≈ ")[1].split()[0])
    n2 = int(page.needed_ics(1.05, 0.95, 1.15, 100).split("≈ ")[1].split()[0])
    assert n2 == pytest.approx(4 * n1, rel=0.02)
    with pytest.raises(ValueError, match="n must be"):
        page.needed_ics(1.0, 0.9, 1.1, 0)


def test_a_hazard_whose_interval_excludes_its_null_is_a_departure_not_a_sample_size():
    # the elastic Γ-rescaled hazard in [1, 5): 1.10 [1.06, 1.15] lies wholly above 1
    row = pd.Series({"estimate": 1.10, "ci_low": 1.06, "ci_high": 1.15})
    assert page._ratio_cell(row, 200) == (
        "1.10 [1.06, 1.15], above 1, size unresolved")
    assert "needs ≈" in page._ratio_cell(
        pd.Series({"estimate": 1.0, "ci_low": 0.85, "ci_high": 1.15}), 200)


def test_an_explained_share_inside_its_own_noise_is_not_stated():
    assert page.share_cell({"estimate": 0.41, "ci_low": 0.336, "ci_high": 0.498}, 200) == (
        "0.410 [0.336, 0.498]")
    wide = page.share_cell({"estimate": 1.69, "ci_low": 0.875, "ci_high": 12.4}, 200)
    assert wide.startswith("not resolved at this size; needs ≈") and "1.69" not in wide
    assert int(wide.split("≈ ")[1].split()[0]) > 200
    assert page.share_cell({"estimate": 1.35, "ci_low": 0.802, "ci_high": 3.74},
                           200).startswith("not resolved")


def test_the_csv_names_the_first_hazard_bin_by_its_unit():
    tab = pd.DataFrame({"quantity": ["hazard_first_bin_over_rate", "rescaled_hazard_first_bin"],
                        "note": ["first bin [0, 0.5)", "first bin [0, 0.01) of Gamma t"]})
    assert run.public_names(tab)["note"].tolist() == [
        "hazard in [0, 0.5) time units after a collision",
        "hazard in [0, 0.01) of Γ-rescaled time"]


def test_the_battery_puts_both_rules_on_one_y_range():
    from kicktimes.studies.mechanism import figures

    assert figures.BATTERY_SHARE_YLIM == (0.0, 0.65)
    assert figures.BATTERY_DISPERSION_YLIM[0] < 1 < figures.BATTERY_DISPERSION_YLIM[1]
