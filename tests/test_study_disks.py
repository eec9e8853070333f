"""The disks study's own computations: the checks of the gas's FTLE and its sweep against
density run through `kicktimes.studies.disks` at a tiny size, write their tables beside the
page, are cached in the work folder with their parameters (a rerun simulates nothing, a
published runs table seeds the cache), and ``reproduce_disks`` writes them before the page,
which closes with the table of where its numbers come from.
"""

from __future__ import annotations

import filecmp
import re
import shutil
import warnings
from pathlib import Path

import pandas as pd
import pytest
from conftest import refuse_simulations

import kicktimes.studies.disks.density as density_module
import kicktimes.studies.disks.ftle_check as check_module
import kicktimes.studies.disks.run as run_module
from kicktimes.experiment import DisksExperiment, run_experiment
from kicktimes.render.provenance import PROVENANCE_TITLE
from kicktimes.studies.disks import reproduce_disks
from kicktimes.studies.disks.density import (
    LyapunovDensity,
    seed_lyapunov_density,
    write_lyapunov_density,
)
from kicktimes.studies.disks.ftle_check import FtleCheck, seed_ftle_check, write_ftle_check
from kicktimes.studies.disks.kicked import FTLE_CHECK_COLUMNS, density_lines, ftle_check_lines

#: N = 2 and 10 under both rules, and the two-disk check: 6 rows of 2 states, a second
TINY_CHECK = FtleCheck(ics=2, scale=0.002, max_disks=10)
TINY_DENSITY = LyapunovDensity(n_disks=(20,), packings=(0.005, 0.01, 0.02), states=2,
                               mean_free_times=12.0, skip=2)
CHECK_CSVS = ("disks_ftle_check.csv", "disks_ftle_check_runs.csv")
DENSITY_CSVS = ("disks_lyapunov_density.csv", "disks_lyapunov_density_fit.csv",
                "disks_lyapunov_density_runs.csv")


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    out = tmp_path_factory.mktemp("disks-study")
    write_ftle_check(out, out / "results", TINY_CHECK)
    write_lyapunov_density(out, out / "results", TINY_DENSITY)
    return out


def _no_simulation(monkeypatch):
    refuse_simulations(monkeypatch, check_module, "pair")
    refuse_simulations(monkeypatch, density_module, "one_state")


def _same(a, b, names):
    return {name: filecmp.cmp(a / name, b / name, shallow=False) for name in names}


def test_the_ftle_checks_give_the_ratio_of_the_means_over_their_states(work):
    table = pd.read_csv(work / "results" / "disks_ftle_check.csv")
    runs = pd.read_csv(work / "results" / "disks_ftle_check_runs.csv")
    assert list(table.columns) == list(FTLE_CHECK_COLUMNS)
    assert len(table) == 6 and set(table["n_ics"]) == {2} and len(runs) == 12
    assert list(table["check"]) == ["tangent/twin"] * 4 + ["engine/two-disk"] * 2
    for _, row in table.iterrows():
        g = runs[(runs["check"] == row["check"]) & (runs["n_disks"] == row["n_disks"])
                 & (runs["rule"] == row["rule"])]
        assert row["estimate"] == pytest.approx(g["numerator"].mean() / g["denominator"].mean())
        assert row["margin"] == check_module.MARGINS[row["check"]]
    # the page's section is the table's rows
    text = "\n".join(ftle_check_lines(work / "results" / "disks_ftle_check.csv"))
    assert text.count(f"| tangent/twin ({check_module.PACKING:g}) | 10 |") == 2


def test_the_density_sweep_writes_its_means_and_its_fit(work):
    results = work / "results"
    runs = pd.read_csv(results / "disks_lyapunov_density_runs.csv")
    table = pd.read_csv(results / "disks_lyapunov_density.csv")
    fits = pd.read_csv(results / "disks_lyapunov_density_fit.csv")
    assert len(runs) == 6 and (runs["lam_per_coll"] > 0).all()
    assert list(table["n_states"]) == [2, 2, 2]
    assert table["lam_per_coll"].tolist() == pytest.approx(
        runs.groupby("packing")["lam_per_coll"].mean().tolist())
    assert len(fits) == 1 and isinstance(fits["reading"].iloc[0], str)
    text = "\n".join(density_lines(results / DENSITY_CSVS[0], results / DENSITY_CSVS[1]))
    assert "| 20 | 0.005 |" in text and "N = 20, fitted at φ ≤ 0.02" in text


def test_the_page_ends_with_where_its_numbers_come_from(work, tmp_path):
    from kicktimes.studies.disks.page import write_disks_page

    # the page beside the FTLE tables reproduce_disks writes first, from a tiny mirror gas
    results = tmp_path / "results"
    results.mkdir()
    for name in CHECK_CSVS + DENSITY_CSVS:
        shutil.copy(work / "results" / name, results / name)
    gas = DisksExperiment(name="tiny-gas", n_disks=[2, 5], packing=0.1, n_tagged=6,
                          min_runs=3, collisions=5, block_sequences=2, seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        store = run_experiment(gas, tmp_path / "store", progress=False, workers=1)
        page = write_disks_page([store.path], results, n_boot=99, n_mc=19, dpi=30)
    text = page.read_text(encoding="utf-8")
    headings = [line for line in text.split("\n") if line.startswith("## ")]
    assert headings[-1] == PROVENANCE_TITLE
    table = text.split(f"\n{PROVENANCE_TITLE}\n", 1)[1]
    named = re.findall(r"^\| \[([^\]]+)\]\(\1\) \| [^|]+ \| `kicktimes\.[\w.]+` \|$",
                       table, flags=re.MULTILINE)
    assert len(named) == table.count("\n| [")
    assert all((results / name).is_file() for name in named)
    # every table written beside the page is named; a table not written is not
    assert {"disks.csv", "disks_null.csv", "null_calibration.csv",
            *CHECK_CSVS, *DENSITY_CSVS} <= set(named)
    assert "disks_kicked.csv" not in named and "disks_cost.csv" not in named
    # a mirror gas has no speed-rescaled columns: the page names none
    assert "rescaled_" not in table


def test_a_rerun_with_the_same_parameters_simulates_nothing(work, tmp_path, monkeypatch):
    _no_simulation(monkeypatch)
    write_ftle_check(work, tmp_path, TINY_CHECK)
    write_lyapunov_density(work, tmp_path, TINY_DENSITY)
    assert all(_same(work / "results", tmp_path, CHECK_CSVS + DENSITY_CSVS).values())
    # fewer rows of the same parameters are the cached ones too
    fewer = write_ftle_check(work, tmp_path, FtleCheck(ics=2, scale=0.002, max_disks=2))
    assert list(fewer["n_disks"]) == [2, 2, 2, 2]


def test_other_parameters_recompute_only_their_tables(work, tmp_path, monkeypatch):
    out = tmp_path / "out"
    shutil.copytree(work, out)
    calls = []

    def fake(task):
        calls.append(task)
        return task[:5] + (1.0, 1.0)

    monkeypatch.setattr(check_module, "pair", fake)
    longer = FtleCheck(ics=2, scale=0.004, max_disks=10)
    table = write_ftle_check(out, tmp_path / "results", longer)
    assert len(calls) == 12 and (table["estimate"] == 1.0).all()
    assert set(table["t_max"]) == {16.0, 1.6, 80.0}


def test_a_published_runs_table_seeds_the_cache(work, tmp_path, monkeypatch):
    _no_simulation(monkeypatch)
    results = work / "results"
    seed_ftle_check(tmp_path, results / "disks_ftle_check_runs.csv", TINY_CHECK)
    seed_lyapunov_density(tmp_path, results / "disks_lyapunov_density_runs.csv", TINY_DENSITY)
    write_ftle_check(tmp_path, tmp_path / "results", TINY_CHECK)
    write_lyapunov_density(tmp_path, tmp_path / "results", TINY_DENSITY)
    assert all(_same(results, tmp_path / "results", CHECK_CSVS + DENSITY_CSVS).values())


def test_seeding_refuses_runs_of_other_parameters(work, tmp_path):
    results = work / "results"
    runs = pd.read_csv(results / "disks_ftle_check_runs.csv")
    with pytest.raises(ValueError, match="seeds 0 .. 2"):
        seed_ftle_check(tmp_path, runs, FtleCheck(ics=3, scale=0.002, max_disks=10))
    with pytest.raises(ValueError, match="t_max"):
        seed_ftle_check(tmp_path, runs, FtleCheck(ics=2, scale=0.001, max_disks=10))
    with pytest.raises(ValueError, match="missing columns"):
        seed_ftle_check(tmp_path, runs.drop(columns="numerator"), TINY_CHECK)
    with pytest.raises(ValueError, match="states 0 .. 2"):
        seed_lyapunov_density(tmp_path, pd.read_csv(results / DENSITY_CSVS[2]),
                              LyapunovDensity(n_disks=(20,), packings=(0.005, 0.01, 0.02),
                                              states=3, mean_free_times=12.0, skip=2))


@pytest.mark.parametrize("make, name", [
    (lambda: FtleCheck(ics=1), "ics"),
    (lambda: FtleCheck(scale=0.0), "scale"),
    (lambda: FtleCheck(max_disks=1), "max_disks"),
    (lambda: LyapunovDensity(states=1), "states"),
    (lambda: LyapunovDensity(n_disks=(1,)), "n_disks"),
    (lambda: LyapunovDensity(packings=(0.01, 0.5)), "packings"),
    (lambda: LyapunovDensity(mean_free_times=12.0, skip=11), "skip"),
    (lambda: LyapunovDensity(fit_max_packing=0.004), "fit_max_packing"),
])
def test_bad_parameters_are_refused_naming_them(make, name):
    with pytest.raises(ValueError, match=name):
        make()


@pytest.mark.parametrize("options, name", [
    ({"workers": 0}, "workers"), ({"ftle_check": "paper"}, "ftle_check"),
    ({"density": {"states": 4}}, "density")])
def test_reproduce_refuses_bad_arguments_before_running_anything(tmp_path, options, name):
    with pytest.raises(ValueError, match=name):
        reproduce_disks(tmp_path, **options)
    assert not list(tmp_path.iterdir())


@pytest.mark.full
def test_reproduce_writes_the_ftle_tables_before_the_page(tmp_path, monkeypatch):
    import kicktimes.experiment as experiment

    tiny = DisksExperiment(name="tiny-gas", n_disks=[2, 5], packing=0.1, n_tagged=6,
                           min_runs=3, collisions=5, block_sequences=2, seed=3)
    monkeypatch.setattr(experiment, "disks_preset", lambda name: tiny)
    pages = []

    def page_writer(paths, target, *, command, cost):
        # the page (tests/test_disks_controls.py) renders the tables found beside it
        pages.append({name: (Path(target) / name).exists()
                      for name in CHECK_CSVS + DENSITY_CSVS})
        assert command == "kicktimes reproduce --study disks --scale paper"
        assert list(cost["experiment"]) == ["tiny-gas"]
        assert [Path(p).name for p in paths] == ["store-tiny-gas"]
        return Path(target) / "disks.md"

    monkeypatch.setattr(run_module, "write_disks_page", page_writer)
    lines = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        page = reproduce_disks(tmp_path, names=["tiny-gas"], progress=lines.append,
                               ftle_check=TINY_CHECK, density=TINY_DENSITY)
    assert page == tmp_path / "results-disks" / "disks.md"
    assert all(pages[0].values())
    assert any("computing 6" in line for line in lines)
    # the second time every store and every table is reused
    lines.clear()
    _no_simulation(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reproduce_disks(tmp_path, names=["tiny-gas"], results_dir=tmp_path / "again",
                        progress=lines.append, ftle_check=TINY_CHECK, density=TINY_DENSITY)
    assert not any("computing" in line for line in lines) and all(pages[1].values())
    assert "the FTLE checks: 6 of 6 tables reused from the cache" in lines
    assert "the FTLE against density: 3 of 3 tables reused from the cache" in lines
    # without them, nothing is written beside the page
    reproduce_disks(tmp_path, names=["tiny-gas"], results_dir=tmp_path / "none",
                    progress=False, ftle_check=None, density=None)
    assert not any(pages[2].values())


def test_the_quick_scale_runs_every_preset_smaller_under_its_own_name(tmp_path, monkeypatch):
    import kicktimes.studies.disks.run as run
    from kicktimes.experiment import DISKS_CONTROLS, DISKS_PRESETS, DISKS_REFERENCES
    from kicktimes.studies.disks import QUICK_N, quick_experiment, reproduce

    for exp in [*DISKS_PRESETS.values(), *DISKS_CONTROLS.values(), *DISKS_REFERENCES.values()]:
        small = quick_experiment(exp)
        assert small.name == exp.name and small.hash() != exp.hash()
        if isinstance(exp, DisksExperiment):
            assert set(small.n_disks) <= set(QUICK_N) and small.n_tagged <= 1000
            assert len(small.tasks()) < len(exp.tasks())
        else:
            assert small.n_ics <= 1000 and small.radii == exp.radii
    calls = []
    monkeypatch.setattr(run, "reproduce_disks", lambda out, **kw: calls.append((out, kw)))
    reproduce(tmp_path, scale="quick")
    reproduce(tmp_path, scale="paper", results_dir=tmp_path / "r")
    (quick_out, quick), (paper_out, paper) = calls
    assert quick_out == str(tmp_path / "disks-quick") and quick["experiment"] is quick_experiment
    assert quick["results_dir"] == str(tmp_path / "results-disks")
    assert quick["command"] == "kicktimes reproduce --study disks --scale quick"
    assert paper_out == tmp_path and "experiment" not in paper
    with pytest.raises(ValueError, match="scale must be one of"):
        reproduce(tmp_path, scale="huge")
