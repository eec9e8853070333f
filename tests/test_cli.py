"""The command line: ``kicktimes simulate`` (the other commands are tested with their modules)."""

import json
import subprocess
import sys

import pyarrow.parquet as pq
from click.testing import CliRunner

from kicktimes.cli import main


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


def test_simulate_rejects_a_bad_radius(tmp_path):
    result = CliRunner().invoke(main, ["simulate", "-r", "0.7", "--out", str(tmp_path / "x")])
    assert result.exit_code != 0
    assert "r_max must lie in" in result.output or "r must lie in" in result.output


def test_python_dash_m_runs_the_cli():
    out = subprocess.run([sys.executable, "-m", "kicktimes", "--help"], capture_output=True,
                         text=True, check=True)
    for command in ("simulate", "schedule", "run", "report", "reproduce"):
        assert command in out.stdout
