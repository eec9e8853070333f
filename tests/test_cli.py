"""The command line: ``kicktimes simulate`` (the other commands are tested with their modules)."""

import json
import subprocess
import sys

import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from kicktimes.cli import main
from kicktimes.cli._group import _plain
from kicktimes.experiment import Experiment


def test_simulate_writes_collisions_and_prints_the_kinetic_expectation(tmp_path):
    out = tmp_path / "sim"
    result = CliRunner().invoke(main, ["simulate", "-r", "0.01", "-r", "0.03", "--n-ics", "20",
                                       "--t-max", "200", "--seed", "4", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "kinetic" in result.output and "0.0300" in result.output
    table = pq.read_table(out / "collisions.parquet")
    assert table.num_rows == 40
    assert set(table.column_names) == {"radius", "ic", "t_window", "n_pp", "pp_times"}
    meta = json.loads(table.schema.metadata[b"kicktimes"])
    assert meta["seed"] == 4 and meta["rule"] == "mirror" and meta["version"]
    df = table.to_pandas()
    assert (df.n_pp == df.pp_times.map(len)).all()
    assert [p.name for p in out.iterdir()] == ["collisions.parquet"]


def test_simulate_in_a_table(tmp_path):
    out = tmp_path / "st"
    result = CliRunner().invoke(main, ["simulate", "--table", "stadium", "--a", "1", "-r", "0.02",
                                       "--n-ics", "10", "--t-max", "500", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "table=Stadium(a=1.0)" in result.output and "10 ICs (uniform)" in result.output
    meta = json.loads(pq.read_table(out / "collisions.parquet").schema.metadata[b"kicktimes"])
    assert meta["table"] == "stadium a=1.0" and meta["ic_method"] == "uniform"
    res = CliRunner().invoke(main, ["simulate", "--table", "ellipse", "--a", "1.25", "--b", "0.8",
                                    "--disks", "50", "--packing", "0.1", "--t-max", "2",
                                    "--out", str(tmp_path / "el")])
    assert res.exit_code == 0, res.output
    assert "table=Ellipse(a=1.25, b=0.8)" in res.output and "Enskog-Henderson" in res.output


@pytest.mark.parametrize(("args", "text"), [
    (["--table", "ellipse", "--a", "1.25"], "--table ellipse needs --b"),
    (["--table", "circle", "--a", "1"], "--a do not apply to --table circle"),
    (["--table", "stadium", "--a", "1", "--ic-method", "paper"], "--ic-method"),
    (["--table", "ellipse", "--a", "1", "--b", "2"], "--b must lie in"),
    (["--table", "stadium", "--a", "1", "--disks", "10", "--packing", "0.1", "--box", "2"],
     "--box and --table"),
])
def test_simulate_table_errors_name_the_option(tmp_path, args, text):
    result = CliRunner().invoke(main, ["simulate", *args, "-r", "0.02", "--out",
                                       str(tmp_path / "x")])
    assert result.exit_code != 0
    assert text in result.output and "Traceback" not in result.output


def test_simulate_rejects_a_bad_radius(tmp_path):
    result = CliRunner().invoke(main, ["simulate", "-r", "0.7", "--out", str(tmp_path / "x")])
    assert result.exit_code != 0
    assert "'--radius'" in result.output and "must lie in (0, 0.5), got 0.7" in result.output


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["-r", "nan"], "--radius"),
        (["-r", "-0.1"], "--radius"),
        (["--n-ics", "0"], "--n-ics"),
        (["--t-max", "-2"], "--t-max"),
        (["--t-max", "inf"], "--t-max"),
        (["--seed", "-1"], "--seed"),
    ],
)
def test_simulate_errors_name_the_option_never_the_library_argument(tmp_path, args, option):
    result = CliRunner().invoke(main, ["simulate", *args, "--out", str(tmp_path / "x")])
    assert result.exit_code == 2
    assert f"'{option}'" in result.output
    for internal in ("r_max", "t_max", " n must", "np.float64", "Traceback"):
        assert internal not in result.output


def test_schedule_errors_name_the_option_and_show_plain_numbers(tmp_path):
    out = str(tmp_path / "k.csv")
    result = CliRunner().invoke(main, ["schedule", "poisson", "-p", "rate=1", "--t-max", "-2",
                                       "-o", out])
    assert result.exit_code == 2 and "'--t-max'" in result.output
    result = CliRunner().invoke(main, ["schedule", "poisson", "-p", "rate=-2", "--t-max", "5",
                                       "-o", out])
    assert result.exit_code != 0 and "rate" in result.output
    assert "np.float64" not in result.output


def test_plain_unwraps_numpy_reprs_and_maps_leading_argument_names():
    assert _plain("x must lie in (0, 1), got np.float64(-2.0)") == "x must lie in (0, 1), got -2.0"
    assert _plain("t_max must be positive", {"t_max": "--t-max"}) == "--t-max must be positive"
    assert _plain("n must be >= 1", {"n": "--n-ics"}) == "--n-ics must be >= 1"
    # only a leading name is an argument name; words inside the text are left alone
    assert _plain("count n must be >= 1", {"n": "--n-ics"}) == "count n must be >= 1"


def test_file_system_errors_are_one_line_messages(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    result = CliRunner().invoke(main, ["simulate", "--n-ics", "2", "--t-max", "5",
                                       "--out", str(blocker / "sub")])
    assert result.exit_code == 1
    assert result.output.strip().splitlines() == [f"Error: Not a directory: {blocker / 'sub'}"]


def test_run_on_a_full_disk_prints_one_line(tmp_path, monkeypatch):
    import errno

    import pyarrow.parquet

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "store"))

    toml = tmp_path / "e.toml"
    Experiment(name="tiny", radii=[0.02], n_ics=2, n_steps=100, tau=0.3).write_toml(toml)
    monkeypatch.setattr(pyarrow.parquet, "write_table", full)
    result = CliRunner().invoke(main, ["run", str(toml), "--out", str(tmp_path / "store"),
                                       "--workers", "1", "--no-progress"])
    assert result.exit_code == 1
    assert result.output.strip().splitlines()[-1] == (
        f"Error: No space left on device: {tmp_path / 'store'}"
    )
    assert "Traceback" not in result.output


def test_run_on_a_locked_store_says_so_in_one_line(tmp_path):
    from kicktimes.experiment.store import StoreWriter

    exp = Experiment(name="tiny", radii=[0.02], n_ics=2, n_steps=100, tau=0.3)
    toml = tmp_path / "e.toml"
    exp.write_toml(toml)
    with StoreWriter(tmp_path / "store", exp):
        result = CliRunner().invoke(main, ["run", str(toml), "--out", str(tmp_path / "store"),
                                           "--workers", "1"])
    assert result.exit_code == 1
    assert "being written by another kicktimes run" in result.output
    assert "--wait" in result.output and "Traceback" not in result.output


def test_python_dash_m_runs_the_cli():
    out = subprocess.run([sys.executable, "-m", "kicktimes", "--help"], capture_output=True,
                         text=True, check=True)
    for command in ("simulate", "schedule", "run", "report", "reproduce"):
        assert command in out.stdout


def test_the_report_process_builds_the_report_the_driver_sends(tmp_path):
    # `reproduce` forks it before the sweeps: it imports the report's modules meanwhile
    from kicktimes.experiment import run_experiment
    from kicktimes.report.process import ReportProcess

    exp = Experiment(name="tiny_rp", radii=[0.02], n_ics=2, n_steps=200, tau=0.3,
                     diagnostics=["recurrence_rate"])
    run_experiment(exp, tmp_path / "store", workers=1, progress=False)
    process = ReportProcess()
    try:
        path = process.build([str(tmp_path / "store")], str(tmp_path / "report"), 1, False,
                             False)
    finally:
        process.close()
    assert path == tmp_path / "report" / "report.html" and path.is_file()
    assert process._proc.exitcode == 0


def test_the_report_process_hands_its_errors_to_the_driver(tmp_path):
    from kicktimes.report.process import ReportProcess

    process = ReportProcess()
    try:
        with pytest.raises(ValueError, match="is not a kicktimes store"):
            process.build([str(tmp_path)], str(tmp_path / "report"), 1, False, False)
    finally:
        process.close()
    idle = ReportProcess()
    idle.close()  # no job: it ends when the driver closes the pipe
    assert idle._proc.exitcode == 0


def test_an_unpicklable_error_of_the_report_process_still_reaches_the_driver(monkeypatch):
    from kicktimes.report import process as cli

    class LocalError(Exception):  # a local class: pickle cannot name it
        pass

    def fail(*job):
        raise LocalError("the figures could not be drawn")

    monkeypatch.setattr(cli, "build_stores_report", fail)  # the forked process inherits it
    process = cli.ReportProcess()
    try:
        with pytest.raises(RuntimeError, match="LocalError: the figures could not be drawn"):
            process.build(["store"], "out")
    finally:
        process.close()


def test_every_command_runs_with_fewer_garbage_collections():
    import gc

    import click

    from kicktimes.memory import _GC_THRESHOLDS

    before = gc.get_threshold()
    seen = []
    main.add_command(click.Command("probe-gc", callback=lambda: seen.append(gc.get_threshold())))
    try:
        result = CliRunner().invoke(main, ["probe-gc"])
    finally:
        main.commands.pop("probe-gc")
    assert result.exit_code == 0, result.output
    assert seen[0][0] >= _GC_THRESHOLDS[0]
    assert gc.get_threshold() == before


@pytest.mark.parametrize("workers, loads", [(1, False), (2, True), (None, None)])
def test_the_sweep_kernels_are_loaded_before_a_pool_forks(monkeypatch, workers, loads):
    import os

    from kicktimes import compilation as _compile
    from kicktimes.compilation import compile_first

    calls = []
    monkeypatch.setattr(_compile, "announce", lambda *a, **k: 0.0)
    monkeypatch.setattr(_compile, "warm_sweep", lambda: calls.append("warm_sweep"))
    compile_first(workers)
    if loads is None:  # the default pool: one worker per core
        loads = (os.cpu_count() or 1) > 1
    assert calls == (["warm_sweep"] if loads else [])


def test_run_an_experiment_in_a_table_from_toml(tmp_path):
    toml = tmp_path / "stadium.toml"
    toml.write_text('name = "st"\nradii = [0.02]\nn_ics = 2\nn_steps = 50\ntau = 2.0\n'
                    'ic_method = "uniform"\ntable = "stadium a=1"\nsampling = "uniform"\n'
                    'systems = ["two_particle", "poisson"]\ndiagnostics = ["lyapunov"]\n'
                    'lyapunov_method = "tangent"\n', encoding="utf-8")
    exp = Experiment.from_toml(toml)
    assert exp.table == "stadium a=1.0" and Experiment.from_toml_string(exp.to_toml()) == exp
    out = tmp_path / "store"
    result = CliRunner().invoke(main, ["run", str(toml), "--out", str(out), "--workers", "1"])
    assert result.exit_code == 0, result.output
    from kicktimes.experiment import load_store

    res = load_store(out).results
    lam = res[(res["diagnostic"] == "lyapunov") & (res["system"] == "poisson")]["value"]
    assert len(lam) == 2 and (lam > 0.2).all()   # the stadium's own exponent is ~0.43
    bad = tmp_path / "bad.toml"
    bad.write_text(toml.read_text(encoding="utf-8").replace('"stadium a=1"', '"sinai a=1"'),
                   encoding="utf-8")
    result = CliRunner().invoke(main, ["run", str(bad), "--out", str(tmp_path / "b")])
    assert result.exit_code != 0 and "table" in result.output
