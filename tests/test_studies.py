"""The studies' registry and the command line that builds their pages.

``kicktimes reproduce --study NAME`` runs the registered study's ``reproduce``; ``--study
all`` runs every one in the registry's order (the paper study first: the science study
reads its stores and findings) with every page in one folder; ``kicktimes run NAME`` and
``kicktimes presets`` serve the built-in experiments, the one definition of the presets.
"""

import importlib

import pytest
from click.testing import CliRunner

from kicktimes.cli import main
from kicktimes.experiment import PRESETS, Experiment, preset, preset_names
from kicktimes.studies import STUDIES, Study


@pytest.mark.parametrize("name", list(STUDIES))
@pytest.mark.parametrize(("option", "value"), [("scale", "huge"), ("scale", "Paper"),
                                               ("workers", 0), ("workers", 1.5),
                                               ("workers", True), ("workers", "2")])
def test_every_study_refuses_a_bad_scale_or_workers_by_name_writing_nothing(tmp_path, name,
                                                                           option, value):
    with pytest.raises(ValueError, match=option):
        STUDIES[name].reproduce(tmp_path, **{option: value})
    assert not any(tmp_path.iterdir())


def test_every_study_has_its_package_with_reproduce_and_a_page_of_its_own():
    pages = [s.page for s in STUDIES.values()]
    assert len(set(pages)) == len(pages)
    # every study, the paper's too (its sweeps, its report process and its page), is its
    # package's reproduce
    for study in STUDIES.values():
        module = importlib.import_module(study.module)
        assert callable(module.reproduce), study.name  # the command line calls only it
        assert all(need in STUDIES and list(STUDIES).index(need) < list(STUDIES).index(
            study.name) for need in study.needs)


def test_reproduce_dispatches_to_the_study_with_its_command(tmp_path, monkeypatch):
    calls = []

    def fake(self, out, **options):
        calls.append((self.name, out, options))
        return tmp_path / self.page

    monkeypatch.setattr(Study, "reproduce", fake)
    res = CliRunner().invoke(main, ["reproduce", "--study", "escape", "--scale", "paper",
                                    "--out", str(tmp_path), "--workers", "1",
                                    "--no-progress"])
    assert res.exit_code == 0, res.output
    (name, out, options), = calls
    assert (name, out) == ("escape", str(tmp_path))
    assert options["scale"] == "paper" and options["results_dir"] is None
    assert options["command"] == "kicktimes reproduce --study escape --scale paper"
    assert "page written to" in res.output


def test_all_runs_every_study_in_order_into_one_results_folder(tmp_path, monkeypatch):
    import kicktimes.cli.experiment as cli

    seen = []

    def fake(study, results, findings, scale, *args, command=None):
        seen.append((study, results, command))

    monkeypatch.setattr(cli, "_reproduce_one", fake)
    res = CliRunner().invoke(main, ["reproduce", "--study", "all", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert [s for s, _, _ in seen] == list(STUDIES)
    assert {r for _, r, _ in seen} == {str(tmp_path / "results")}
    # each page names its own study's command (`Study.command`), which rebuilds it alone
    assert {c for *_, c in seen} == {None}


def test_findings_is_refused_where_no_study_reads_it(tmp_path):
    res = CliRunner().invoke(main, ["reproduce", "--study", "escape", "--findings",
                                    str(tmp_path), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "--findings applies to" in res.output


def test_presets_lists_every_preset_and_prints_the_toml_of_a_two_disk_one():
    two, disks = preset_names()
    assert two == list(PRESETS)
    listing = CliRunner().invoke(main, ["presets"])
    assert listing.exit_code == 0
    for name in two + disks:
        assert f"  {name} " in listing.output
    toml = CliRunner().invoke(main, ["presets", "quick_b"])
    assert Experiment.from_toml_string(toml.output) == preset("quick_b")
    wrong = CliRunner().invoke(main, ["presets", "family_c"])
    assert wrong.exit_code == 2 and "'family_c' is not a preset" in wrong.output
    gas = CliRunner().invoke(main, ["presets", disks[0]])
    assert gas.exit_code == 2 and "kicktimes run " + disks[0] in gas.output


@pytest.mark.parametrize("how", ["name", "toml"])
def test_run_takes_a_preset_name_or_a_toml_file(tmp_path, monkeypatch, how):
    import kicktimes.cli.experiment as cli

    ran = []
    monkeypatch.setattr(cli, "_pending", lambda exp, out: False)
    monkeypatch.setattr(cli, "_run_one", lambda exp, out, *a, **k: ran.append(exp) or
                        type("S", (), {"summary": lambda self: "done"})())
    arg = "quick_a"
    if how == "toml":
        arg = str(tmp_path / "mine.toml")
        preset("quick_a").write_toml(arg)
    res = CliRunner().invoke(main, ["run", arg, "--out", str(tmp_path / "s")])
    assert res.exit_code == 0, res.output
    assert ran == [preset("quick_a")]
    bad = CliRunner().invoke(main, ["run", "quick_c", "--out", str(tmp_path / "s")])
    assert bad.exit_code == 2 and "neither a TOML file nor a preset" in bad.output


def test_reproduce_says_a_stores_warning_in_one_line_and_keeps_no_warning(tmp_path,
                                                                          monkeypatch):
    import warnings

    from kicktimes.experiment import StoreWarning

    def fake(self, out, **options):
        warnings.warn("the store was written by another version", StoreWarning, stacklevel=2)
        for k in range(1000):  # a study may warn many times: none is kept for later
            warnings.warn(f"value {k}", RuntimeWarning, stacklevel=2)
        return tmp_path / self.page

    monkeypatch.setattr(Study, "reproduce", fake)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        res = CliRunner().invoke(main, ["reproduce", "--study", "escape", "--out",
                                        str(tmp_path), "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "warning: the store was written by another version" in res.output
    assert "page written to" in res.output


def test_an_option_of_another_study_is_refused_naming_it(tmp_path):
    res = CliRunner().invoke(main, ["reproduce", "--study", "escape", "--scheduler",
                                    "tcp://h:1", "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert ("--scheduler applies to --study paper, disks, small_r, tables, not to --study escape"
            in res.output)


def test_the_paper_page_s_closing_table_is_what_it_wrote_and_never_in_the_readme(tmp_path):
    import pandas as pd

    from kicktimes.render.pages import write_results_page
    from kicktimes.render.provenance import PROVENANCE_TITLE
    from kicktimes.report.controls import COLUMNS, POISSON_QUESTION
    from kicktimes.studies.paper.page import BEGIN, END, copy_first_screen, results_sources

    family = pd.DataFrame([dict.fromkeys(COLUMNS, "x") | {"question": POISSON_QUESTION}])
    curves = pd.DataFrame(columns=["family", "control", "radius", "ratio", "ci_low", "ci_high"])
    for name in ("fam", "fam-elastic"):
        family.to_csv(tmp_path / f"{name}_findings.csv", index=False)
        curves.to_csv(tmp_path / f"{name}_findings_by_radius.csv", index=False)
    rows = results_sources(["fam", "fam-elastic"], {"fam": family}, ["fam", "fam-elastic"],
                           gaps=False, nulls=False)
    pd.DataFrame({"diagnostic": ["FTLE λ"]}).to_csv(tmp_path / "overview.csv", index=False)
    # the overview, then the family's table twice (its comparisons, its Poisson rows); the
    # control's own table is folded into the family's, not listed
    assert [(r.csv, r.computed_by.__name__) for r in rows[:3]] == [
        ("overview.csv", "overview_table"), ("fam_findings.csv", "compute_controls"),
        ("fam_findings.csv", "poisson_rows")]
    assert {r.csv for r in rows} == {p.name for p in tmp_path.glob("*.csv")} - {
        "fam-elastic_findings.csv", "fam-elastic_findings_by_radius.csv"}
    page = write_results_page(tmp_path / "README.md", [
        "# t", "", "Generated now from `fam`.", "", "## The answers", "", "One.", ""], rows)
    readme = tmp_path / "top.md"
    readme.write_text(f"intro\n{BEGIN}\nold\n{END}\n", encoding="utf-8")
    copy_first_screen(page, readme)
    assert "One." in readme.read_text() and PROVENANCE_TITLE not in readme.read_text()
