"""Specification of kicktimes.report.build_report on a tiny real sweep."""

from __future__ import annotations

import base64
import gc
import re

import numpy as np
import pandas as pd
import pytest
from threadpoolctl import threadpool_info

from kicktimes import __version__
from kicktimes.experiment import Experiment, load_store, run_experiment
from kicktimes.report import Render, Subsampling, build_report

EXPERIMENT = Experiment(
    name="tiny_report",
    radii=[0.008, 0.014, 0.02],
    n_ics=6,
    n_steps=2500,
    tau=0.3,
    sampling="paper",
    seed=7,
    lyapunov_variant="paper",
    block_size=3,
    description="report test",
)
FIGURES = {
    "fig00_ratios_vs_radius",
    "fig01_poincare_sections",
    "fig02_recurrence_plot",
    "fig03_kick_times_vs_collision_times",
    "fig04_counts_vs_radius",
    "fig05_lyapunov_vs_radius",
    "fig06_recurrence_rate_vs_radius",
    "fig07_autocorrelation_vs_radius",
    "fig07b_autocorrelation_curves",
    "fig08_poisson_rejection_rates",
    "fig09_renewal_model_comparison",
    "fig10_rate_heterogeneity",
}
TABLES = {
    "findings_statements",
    "findings_overview",
    "findings_by_radius",
    "poincare_runs",
    "kick_times_fit",
    "counts_by_radius",
    "count_regression",
    "count_overdispersion",
    "diagnostics_summary",
    "diagnostics_vs_two_particle",
    "lyapunov_by_radius",
    "lyapunov_stretching",
    "null_calibration",
    "recurrence_by_radius",
    "autocorrelation_summary",
    "autocorrelation_curves",
    "sticky_ics",
    "findings",
    "poisson_tests",
    "rate_homogeneity",
    "renewal_best_share",
    "renewal_pooled",
    "renewal_per_ic",
    "renewal_best_per_ic",
    "experiment",
    "report_timings",
    "sweep_timings",
}


OPTIONS = {"n_mc": 99, "subsampling": Subsampling(max_ics_model_fits=2),
           "render": Render(dpi=50)}


@pytest.fixture(scope="module")
def store_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("store")
    run_experiment(EXPERIMENT, path, workers=1, progress=False)
    return path


@pytest.fixture(scope="module")
def built(store_path, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    stages = []
    thresholds = {"before": gc.get_threshold(), "during": set(), "blas": set()}

    def progress(stage, done, total):
        stages.append((stage, done, total))
        thresholds["during"].add(gc.get_threshold())
        thresholds["blas"] |= {i["num_threads"] for i in threadpool_info()
                               if i["user_api"] == "blas"}

    path = build_report(
        store_path,
        out,
        progress=progress,
        **OPTIONS,
        workers=2,  # the multi-store build below uses 1: results must agree
    )
    thresholds["after"] = gc.get_threshold()
    return path, out, stages, thresholds


def test_report_html_is_self_contained_with_one_embedded_image_per_figure(built):
    path, out, *_ = built
    page = path.read_text(encoding="utf-8")
    images = re.findall(r'<img[^>]*src="([^"]+)"', page)
    assert len(images) == len(FIGURES)
    for src in images:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    assert "<link" not in page and "<script" not in page  # nothing to fetch


def test_every_figure_is_saved_as_png_and_no_pdf_by_default(built):
    _, out, *_ = built
    assert {p.stem for p in out.glob("*.png")} == FIGURES
    assert not list(out.glob("*.pdf"))
    assert 'PDF</a>' not in (out / "report.html").read_text(encoding="utf-8")


def test_every_table_is_saved_as_csv(built):
    _, out, *_ = built
    assert {p.stem for p in out.glob("*.csv")} == TABLES
    page = (out / "report.html").read_text(encoding="utf-8")
    assert page.count('<table class="dataframe">') >= 8


def test_report_records_experiment_seed_rule_version_and_store(built, store_path):
    path, out, *_ = built
    page = path.read_text(encoding="utf-8")
    for text in ("tiny_report", EXPERIMENT.hash(), "mirror", __version__, str(store_path)):
        assert text in page
    assert re.search(r"<b>seed</b></td><td>7</td>", page)
    assert Experiment.from_toml(out / "experiment.toml") == EXPERIMENT


def test_numbers_come_from_the_store(built, store_path):
    _, out, *_ = built
    store = load_store(store_path)
    counts = pd.read_csv(out / "counts_by_radius.csv").set_index("radius")
    expected = store.collisions.groupby("radius")["n_pp"].mean()
    assert np.allclose(counts["mean_count"], expected)
    summary = pd.read_csv(out / "diagnostics_summary.csv")
    res = store.results
    sel = (res["diagnostic"] == "autocorrelation") & (res["system"] == "poisson")
    mine = summary[(summary["diagnostic"] == "autocorrelation") & (summary["system"] == "poisson")]
    assert np.allclose(mine["mean"], res[sel].groupby("radius")["value"].mean(), equal_nan=True)
    assert list(mine["n_valid"]) == list(res[sel].groupby("radius")["value"].count())
    tests = pd.read_csv(out / "poisson_tests.csv")
    assert (tests["n_tested"] <= EXPERIMENT.n_ics).all()
    assert set(tests["radius"]) == set(EXPERIMENT.radii)


def test_recurrence_plot_is_the_stored_trajectory_of_ic_0(built):
    page = built[0].read_text(encoding="utf-8")
    assert "identical: the plot is the stored trajectory" in page


def test_lyapunov_section_names_the_paper_variant(built):
    page = built[0].read_text(encoding="utf-8")
    assert "paper variant: max(λˣ, λʸ)" in page


def test_subsampling_is_stated_in_the_report(built):
    page = built[0].read_text(encoding="utf-8")
    assert "Per-IC renewal-model comparison: the first 2 ICs" in page
    best = pd.read_csv(built[1] / "renewal_best_per_ic.csv")
    assert set(best["ic"]) == {0, 1}


def test_progress_callable_sees_every_stage_in_order(built):
    stages = built[2]
    assert [done for _, done, _ in stages] == list(range(len(stages)))
    assert stages[0][0] == "load store" and stages[-1][0] == "write files"


def test_the_build_runs_with_fewer_garbage_collections_and_restores_the_setting(built):
    from kicktimes.memory import _GC_THRESHOLDS

    thresholds = built[3]
    raised = tuple(max(a, b) for a, b in zip(_GC_THRESHOLDS, thresholds["before"], strict=True))
    assert thresholds["during"] == {raised}
    assert thresholds["after"] == thresholds["before"]


@pytest.mark.reproducibility
def test_the_build_runs_blas_on_one_thread(built):
    assert built[3]["blas"] == {1}


def _blas_threads_in_a_forked_process():
    import multiprocessing as mp

    with mp.get_context("fork").Pool(1) as pool:
        return pool.apply(_blas_threads)


def _blas_threads():
    return sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})


def test_one_blas_thread_reaches_the_forked_workers_and_is_lifted_after():
    import numpy  # noqa: F401  (its BLAS is loaded: the limit applies to loaded libraries)

    from kicktimes.report.pipeline import _one_blas_thread

    before = _blas_threads()
    with _one_blas_thread():
        assert _blas_threads() == [1]
        assert _blas_threads_in_a_forked_process() == [1]
    assert _blas_threads() == before


def test_no_figure_is_left_open(built):
    import matplotlib.pyplot as plt

    assert plt.get_fignums() == []


# a second family, with the default sampling and exponent (unlike EXPERIMENT)
SECOND = Experiment(name="tiny_report_b", radii=[0.01, 0.016], n_ics=4, n_steps=1000, tau=0.2,
                    seed=8, diagnostics=["autocorrelation"], block_size=4)


@pytest.mark.full
def test_several_stores_give_one_report_with_a_part_per_experiment(built, store_path, tmp_path):
    # in this process (the single-store build used two workers): same numbers
    second = tmp_path / "store_b"
    run_experiment(SECOND, second, workers=1, progress=False)
    out = tmp_path / "both"
    path = build_report([store_path, second], out, progress=False, **OPTIONS, workers=1)
    page = path.read_text(encoding="utf-8")
    assert "Experiment tiny_report</h2>" in page and "Experiment tiny_report_b</h2>" in page
    assert re.search(r"<b>seed</b></td><td>8</td>", page)
    # the families' FTLE and ACF are in each family's fig05/fig07 and in fig00: no copies
    assert not (out / "families_autocorrelation_vs_radius.png").exists()
    assert (out / "tiny_report_b_fig07_autocorrelation_vs_radius.png").is_file()
    assert not (out / "tiny_report_b_fig06_recurrence_rate_vs_radius.png").exists()
    # the paper's Fig. 7 layout: family A (the first store) on top and zoomed below
    assert (out / "families_recurrence_rate_vs_radius.png").is_file()
    # the Findings of both stores come before any experiment's details
    first_detail = page.index("Experiment tiny_report</h2>")
    assert page.index("Findings: tiny_report<") < first_detail
    assert page.index("Findings: tiny_report_b<") < first_detail
    single = built[1]
    for name in ("poisson_tests", "rate_homogeneity", "renewal_pooled", "renewal_per_ic"):
        a = pd.read_csv(single / f"{name}.csv")
        b = pd.read_csv(out / f"tiny_report_{name}.csv")
        pd.testing.assert_frame_equal(a, b)


def test_stores_of_the_same_experiment_name_are_refused(store_path, tmp_path):
    with pytest.raises(ValueError, match="distinct names"):
        build_report([store_path, store_path], tmp_path, progress=False, workers=1)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"alpha": 1.5}, ValueError, "alpha"),
        ({"n_mc": 5}, ValueError, "n_mc"),
        ({"workers": 0}, ValueError, "workers"),
        ({"progress": "yes"}, TypeError, "progress"),
    ],
)
def test_build_report_rejects_bad_arguments(store_path, tmp_path, kwargs, error, match):
    with pytest.raises(error, match=match):
        build_report(store_path, tmp_path, **kwargs)


def test_build_report_refuses_a_directory_that_is_not_a_store(tmp_path):
    with pytest.raises(ValueError, match="not a kicktimes store"):
        build_report(tmp_path, tmp_path / "out", progress=False)


# ------------------------------------------------------------------ findings first


def test_the_page_opens_with_the_findings_and_a_below_paper_scale_banner(built):
    page = built[0].read_text(encoding="utf-8")
    findings = page.index('id="findings"')
    assert findings < page.index('id="poincare"')
    assert '<p class="banner">A pipeline check, not an answer: tiny_report: 6 ICs' in page
    # the answers first, then the collapsed contents; the stores named relative to the page
    assert findings < page.index('<details class="contents">')
    assert str(built[1].parent) not in page.split('id="findings"')[0]
    assert "Verdict rules." in page and "the whole 95 % CI of the ratio lies in [0.9, 1.1]" in page


def test_every_finding_has_an_effect_a_confidence_interval_and_a_ruled_verdict(built):
    table = pd.read_csv(built[1] / "findings_statements.csv")
    questions = set(table["question"])
    assert {"FTLE", "Lag-1 ACF of boundary angles", "Off-diagonal RR (ε = 0.001)"} <= questions
    assert "Collision counts against kinetic theory" in questions
    assert set(table.loc[table["system"].notna(), "system"]) == {"poisson", "actual"}
    ratios = table[table["question"] != "Poisson collision times?"]
    ok = ratios["ci_low"].notna()
    assert (ratios.loc[ok, "ci_low"] <= ratios.loc[ok, "estimate"]).all()
    assert (ratios.loc[ok, "estimate"] <= ratios.loc[ok, "ci_high"]).all()
    for row in table.itertuples():
        assert row.verdict.split(" ")[0] in {"within", "higher", "lower", "inconclusive"} or any(
            w in row.verdict for w in ("Poisson", "model", "majority", "exponential")
        )
    acf = table[table["question"].str.startswith("Lag-1 ACF")]
    # never a confirmation: an agreement is marked built in, a difference is set beside the
    # rate-matching prediction
    assert (acf["verdict"].str.contains("built in")
            | acf["verdict"].str.contains("kick rate = collision rate predicts")).all()


def test_the_ftle_finding_is_the_mean_over_radii_of_the_ratio_of_means(built, store_path):
    res = load_store(store_path).results
    lam = res[res["diagnostic"] == "lyapunov"].pivot_table(
        index=["radius", "ic"], columns="system", values="value"
    )
    ratio = lam.groupby(level="radius").sum()
    expected = (ratio["poisson"] / ratio["two_particle"]).mean()
    table = pd.read_csv(built[1] / "findings_statements.csv")
    row = table[(table["question"] == "FTLE") & (table["system"] == "poisson")].iloc[0]
    assert row["estimate"] == pytest.approx(expected, rel=1e-12)


def test_the_stored_off_diagonal_rate_obeys_the_paper_rr_identity(built, store_path):
    res = load_store(store_path).results
    rr = res[(res["diagnostic"] == "recurrence_rate") & (res["system"] == "poisson")]
    n = EXPERIMENT.n_steps + 1
    expected = ((n * rr["value"] - 1) / (n - 1)).groupby(rr["radius"]).mean()
    table = pd.read_csv(built[1] / "recurrence_by_radius.csv")
    off = table[(table["quantity"] == "rr_offdiag@0.001") & (table["system"] == "poisson")]
    # the stored off-diagonal rate (Theiler window 1) obeys N RR - 1 = (N - 1) RR_off
    assert np.allclose(off.set_index("radius")["mean"], expected, rtol=1e-9)
    page = built[0].read_text(encoding="utf-8")
    assert "collision-truncated steps" in page  # which sampling the RR uses


def test_old_stores_get_the_off_diagonal_rate_derived_from_the_paper_rr(store_path):
    from kicktimes.report.recurrence import recurrence_rows

    res = load_store(store_path).results
    old = res[~res["diagnostic"].str.contains("@")]  # what a store before the RQA rows held
    rows, notes = recurrence_rows(old, EXPERIMENT)
    n = EXPERIMENT.n_steps + 1
    rr = old[old["diagnostic"] == "recurrence_rate"]["value"].to_numpy()
    derived = rows[rows["diagnostic"] == "rr_offdiag@0.001"]["value"].to_numpy()
    assert np.allclose(derived, (n * rr - 1) / (n - 1))
    assert "derived from the stored RR as (N·RR − 1)/(N − 1) with N = 2501" in notes[0]
    assert "no recurrence rows" in notes[1]  # the second eps cannot be derived


def test_tables_are_rounded_and_scroll_instead_of_stretching_the_page(built):
    page = built[0].read_text(encoding="utf-8")
    assert page.count('<div class="table-wrap"><table') >= 8
    body = page[page.index('id="findings"') :]  # the data tables, not the parameters
    cells = re.findall(r"<td>(-?\d+\.\d+)(?:e[-+]\d+)?</td>", body)
    digits = [len(c.lstrip("-").replace(".", "").lstrip("0")) for c in cells]
    assert cells and max(digits) <= 4


@pytest.mark.full
def test_write_results_gives_pngs_and_a_generated_findings_page(store_path, tmp_path):
    from kicktimes.studies.paper import write_results

    path = write_results(store_path, tmp_path, dpi=40, n_mc=19, max_ics_model_fits=1)
    text = path.read_text(encoding="utf-8")
    assert text.startswith("# What the reproduction shows (generated)")
    assert "**Below paper scale**" in text and "## The answers" in text
    # every statement and figure on the family's own page, the statements in its CSV
    family = (tmp_path / "tiny_report.md").read_text(encoding="utf-8")
    assert "**Below paper scale**" in family and "## Figures" in family
    statements = pd.read_csv(tmp_path / "tiny_report_statements.csv")
    assert statements["statement"].str.contains("FTLE, Poisson vs two-particle: ratio of mean λ",
                                                regex=False).any()
    pngs = {p.name for p in tmp_path.glob("*.png")}
    assert "tiny_report_fig05_lyapunov_vs_radius.png" in pngs
    for name in pngs:  # each on the README or on the family's page
        assert f"]({name})" in text + family
    assert (tmp_path / "tiny_report_findings.csv").is_file()
    # the null calibration: the runs' own Poisson control streams through the same tests
    null = pd.read_csv(tmp_path / "null_calibration.csv")
    assert set(null["study"]) == {"paper"} and set(null["data"]) == {"tiny_report"}
    assert "uniformity_ks" in set(null["test"]) and (null["n_runs"] > 0).all()
    assert ((null["ci_low"] <= null["value"]) & (null["value"] <= null["ci_high"])).all()
    assert "[null_calibration.csv](null_calibration.csv)" in text
    findings = pd.read_csv(tmp_path / "tiny_report_findings.csv")
    assert {"dispersion_index", "poisson@uniformity_ks"} <= set(findings["diagnostic"])
    # last, where the numbers come from: the CSVs written beside the page, by function
    from kicktimes.render.provenance import PROVENANCE_TITLE

    closing = text[text.rindex("\n## ") + 1:]
    assert closing.startswith(PROVENANCE_TITLE + "\n") and "`kicktimes." in closing
    named = set(re.findall(r"^\| \[([^]]+)\]\(", closing, re.M))
    # the statements CSV is named by the family's page (its own closing table)
    assert named == {p.name for p in tmp_path.glob("*.csv")} - {"tiny_report_statements.csv"}
    assert "[tiny_report_statements.csv](tiny_report_statements.csv)" in family


# ------------------------------------------------------------------ cache


def _snapshot(folder):
    """{name: (mtime_ns, size)} of every file in ``folder``, the cache manifest included."""
    return {p.name: (p.stat().st_mtime_ns, p.stat().st_size) for p in folder.iterdir()}


def test_a_rebuild_with_nothing_changed_writes_nothing_within_3_seconds(built, store_path):
    import time

    path, out, *_ = built
    before = _snapshot(out)
    assert ".cache.json" in before
    t0 = time.perf_counter()
    again = build_report(store_path, out, progress=False, **OPTIONS, workers=2)
    assert time.perf_counter() - t0 < 3.0
    assert again == path
    assert _snapshot(out) == before


@pytest.mark.full
def test_a_damaged_output_is_rebuilt_and_no_temporary_file_is_left(built, store_path, tmp_path):
    import shutil

    out = tmp_path / "copy"
    shutil.copytree(built[1], out)
    (out / "poisson_tests.csv").write_text("damaged")
    (out / "fig04_counts_vs_radius.png").unlink()
    build_report(store_path, out, progress=False, **OPTIONS, workers=1)
    pd.testing.assert_frame_equal(
        pd.read_csv(out / "poisson_tests.csv"), pd.read_csv(built[1] / "poisson_tests.csv")
    )
    assert (out / "fig04_counts_vs_radius.png").read_bytes() == (
        built[1] / "fig04_counts_vs_radius.png"
    ).read_bytes()  # the same figure, bit for bit
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.full
def test_pdf_copies_are_written_on_request_and_removed_when_no_longer_asked(
    built, store_path, tmp_path
):
    import shutil

    out = tmp_path / "copy"
    shutil.copytree(built[1], out)
    build_report(store_path, out, progress=False, **{**OPTIONS, "render": Render(dpi=50, pdf=True)},
                 workers=1)
    for name in FIGURES:
        assert (out / f"{name}.pdf").read_bytes()[:5] == b"%PDF-"
    assert f'<a href="{sorted(FIGURES)[0]}.pdf">PDF</a>' in (out / "report.html").read_text()
    build_report(store_path, out, progress=False, **OPTIONS, workers=1)
    assert not list(out.glob("*.pdf"))


def test_a_forced_rebuild_reuses_nothing_but_removes_what_it_no_longer_writes(tmp_path):
    # what build_report(force=True) does with its cache (ReportCache(fresh=True)), without
    # two more report builds (16 s each)
    from kicktimes.report._cache import ReportCache

    for name in ("fig.png", "fig.pdf"):
        (tmp_path / name).write_bytes(b"x")
    cache = ReportCache(tmp_path)
    cache.record("part", {"key": "k", "files": {"fig.png": "s1", "fig.pdf": "s2"}})
    cache.save()
    forced = ReportCache(tmp_path, fresh=True)
    assert forced.lookup("part", "k") is None  # nothing reused
    forced.record("part", {"key": "k", "files": {"fig.png": "s3"}})
    assert (tmp_path / "fig.png").exists() and not (tmp_path / "fig.pdf").exists()


@pytest.mark.full
def test_a_store_that_gains_a_task_rebuilds_only_its_own_part(store_path, tmp_path):
    import json

    second = tmp_path / "store_b"
    run_experiment(SECOND, second, workers=1, progress=False)
    # take the last task out of store B (entry and files), as if it had not run yet
    manifest = json.loads((second / "manifest.json").read_text())
    last = sorted(manifest["tasks"])[-1]
    for part in ("results", "collisions"):
        (second / part / f"{last}.parquet").unlink()
    del manifest["tasks"][last]
    (second / "manifest.json").write_text(json.dumps(manifest))
    out = tmp_path / "both"
    build_report([store_path, second], out, progress=False, **OPTIONS, workers=1)
    before = _snapshot(out)
    run_experiment(SECOND, second, workers=1, progress=False)  # resumes: one new task
    build_report([store_path, second], out, progress=False, **OPTIONS, workers=1)
    after = _snapshot(out)
    changed = {name for name in after if after[name] != before.get(name)}
    assert changed, "the new task must rebuild something"
    assert all(not n.startswith("tiny_report_") or n.startswith("tiny_report_b_") for n in changed)
    assert {"tiny_report_b_findings.csv", "report.html", ".cache.json"} <= changed
    assert "tiny_report_findings.csv" not in changed  # store A's part is reused
    timings = pd.read_csv(out / "report_timings.csv")
    reused = timings[timings["stage"] == "reused from the cache"]
    assert list(reused["experiment"]) == ["tiny_report"]


def test_one_draw_png_is_byte_identical_to_savefig():
    # the report draws each figure once (layout and rendering in one Agg draw) instead of
    # savefig's two draws; the bytes must be those savefig writes
    import io

    from matplotlib.figure import Figure

    from kicktimes.render.html import _png

    def figure():
        fig = Figure(figsize=(7.0, 3.5), layout="constrained")
        axes = fig.subplots(1, 2)
        x = np.linspace(0.0, 1.0, 50)
        for k, ax in enumerate(axes):
            ax.plot(x, np.sin(7 * x + k), marker="o", label="data")
            ax.set_xlabel("time (time units)")
            ax.set_title(f"panel {k}: $\\lambda = {k}$")
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center")
        fig.suptitle("a constrained layout with a legend outside")
        return fig

    buf = io.BytesIO()
    figure().savefig(buf, format="png", dpi=150)
    fig = figure()
    assert _png(fig, 150) == buf.getvalue()
    assert fig.dpi == 100  # the figure's own dpi is restored


def test_parts_of_about_equal_size_get_no_pools_of_their_own():
    from kicktimes.report.pipeline import _inner_workers

    def manifest(n_radii, n_ics, n_steps):
        return {"experiment": {"radii": [0.01] * n_radii, "n_ics": n_ics, "n_steps": n_steps}}

    quick = [manifest(4, 20, 2000), manifest(4, 20, 2000)]
    paper = [manifest(12, 200, 25000), manifest(10, 1000, 15000)]
    assert _inner_workers(2, quick) == 1  # one part per core: nested pools only add forks
    assert _inner_workers(2, paper) == 2  # unequal: the small part's core helps the large
    assert _inner_workers(4, quick) == 4  # more cores than parts
    assert _inner_workers(2, quick[:1]) == 2  # one part to rebuild


def test_the_report_reads_a_store_as_report_store_of_load_store(store_path, tmp_path):
    # load_report_store reads system/diagnostic as Parquet dictionaries and skips note:
    # the very frames of report_store(load_store(path)), categories and codes included,
    # for a whole store and for an unfinished one; a damaged part is still refused
    import json
    import shutil

    from kicktimes.experiment.store import _part_path
    from kicktimes.report.store import load_report_store, report_store

    def same(path):
        ref, got = report_store(load_store(path)), load_report_store(path)
        pd.testing.assert_frame_equal(got.results, ref.results, check_exact=True)
        pd.testing.assert_frame_equal(got.collisions, ref.collisions, check_exact=True)
        for column in ("system", "diagnostic"):
            cats = list(got.results[column].cat.categories)
            assert cats == sorted(cats) == list(ref.results[column].cat.categories)
        assert got.missing_tasks == ref.missing_tasks and got.manifest == ref.manifest
        return got

    full = same(store_path)
    assert not full.missing_tasks and "note" not in full.results.columns
    partial = tmp_path / "partial"
    shutil.copytree(store_path, partial)
    manifest = json.loads((partial / "manifest.json").read_text())
    dropped = sorted(manifest["tasks"])[0]
    del manifest["tasks"][dropped]
    (partial / "manifest.json").write_text(json.dumps(manifest))
    assert same(partial).missing_tasks == [dropped]
    part = _part_path(partial, "results", sorted(manifest["tasks"])[0])  # a task still read
    part.write_bytes(part.read_bytes()[:-10])
    with pytest.raises(ValueError, match="damaged store"):
        load_report_store(partial)


def test_the_findings_table_has_every_control_and_consistent_robust_flags(built):
    from kicktimes.report.controls import COLUMNS

    table = pd.read_csv(built[1] / "findings.csv")
    assert tuple(table.columns) == COLUMNS
    assert {"primary", "paired_median", "sticky_excluded"} <= set(table["control"])
    ratios = table[table["question"] != "Poisson collision times?"]
    for _, part in ratios.groupby(["family", "diagnostic", "system"]):
        assert part["robust"].nunique() == 1
        flips = (part["ci_low"] > 1).any() and (part["ci_high"] < 1).any()
        assert bool(part["robust"].iloc[0]) == (part["verdict"].nunique() == 1 and not flips)
    assert set(ratios["verdict"]) <= {"within 10 %", "higher", "lower", "inconclusive"}
    poisson = table[table["question"] == "Poisson collision times?"]
    shares = poisson[poisson["diagnostic"].str.startswith("reject@")]
    assert set(shares["verdict"]) <= {"nominal", "above nominal", "below nominal",
                                      "inconclusive"}
    # D, the first hazard bin and the gamma shape are read against their null streams
    against = poisson[poisson["diagnostic"].isin(
        ["dispersion_index", "hazard_first", "gamma_shape"])]
    assert set(against["diagnostic"]) == {"dispersion_index", "hazard_first", "gamma_shape"}
    assert set(against["verdict"]) <= {"at its null", "above its null", "below its null",
                                       "inconclusive"}
    assert against["detail"].str.contains("its null (the runs' Poisson control streams) ",
                                       regex=False).all()
