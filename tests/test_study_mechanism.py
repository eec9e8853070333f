"""kicktimes reproduce --study mechanism: the page from the numbers of each rule, its
cache, at a tiny size (the mirror rule only)."""

from __future__ import annotations

import pandas as pd
import pytest
from conftest import assert_provenance, built_study, refuse_simulations, table_cells

from kicktimes.stats import format_interval, ratio_verdict
from kicktimes.studies.mechanism import run

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
    cells = table_cells(section, "rescaled t > 5")
    groups = [("paper", 0.01), ("paper", 0.02), ("uniform", 0.01), ("uniform", 0.02)]
    for k, (method, r) in enumerate(groups):
        row = tab[(tab["method"] == method) & (tab["radius"] == r)
                  & (tab["quantity"] == "rescaled_hazard_late")].iloc[0]
        if pd.notna(row["estimate"]):
            assert cells[1 + k].startswith(format_interval(
                row["estimate"], row["ci_low"], row["ci_high"], edges=(0.9, 1.0, 1.1)))
            assert cells[1 + k].endswith(ratio_verdict(row["ci_low"], row["ci_high"]))
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
    low_cells = table_cells(section, "minimum over t < 4 (bin)")
    count_cells = table_cells(section, "bins below the rate, t < 4")
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
        assert low_cells[1 + k].endswith(f"({low['note']})")
        assert ratio_verdict(low["ci_low"], low["ci_high"]) in low_cells[1 + k]
        lower = [b.note.removeprefix("bin ") for b in bins.itertuples()
                 if ratio_verdict(b.ci_low, b.ci_high) == "lower"]
        count = g[g["quantity"] == "hazard_nonsticky_bins_lower"].iloc[0]
        assert count["estimate"] == len(lower)
        assert count_cells[1 + k] == f"{len(lower)} of 7: " + (", ".join(lower) or "none")
    assert "hazard minimum over t < 4" in text.split("## The mirror rule")[0]


@pytest.mark.slow
def test_every_figure_the_page_links_is_drawn(tmp_path):
    from kicktimes.studies.mechanism.page import rule_section

    table = run.run_rule("elastic", TINY, tmp_path)
    assert set(table["rule"]) == {"elastic"}
    table = pd.concat([table, run._cached_profile(tmp_path, "elastic", TINY, 1, print)],
                      ignore_index=True)
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
        "kicktimes.studies.mechanism.analysis.hazard_profile_rows"]
