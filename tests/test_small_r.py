"""The small-r study: its log-free FTLE experiments and its page (kicktimes.studies.small_r)."""

import re

import numpy as np
import pytest

from kicktimes.experiment import Experiment, run_experiment
from kicktimes.studies.small_r import SCALES, reproduce, small_r_experiment
from kicktimes.studies.small_r.sweep import SYSTEMS

BASE = dict(name="logfree", radii=[0.02], n_ics=2, n_steps=200, tau=0.5, ic_method="uniform",
            systems=SYSTEMS, diagnostics=("lyapunov",), lyapunov_method="tangent",
            block_size=2)


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
def test_log_free_runs_give_the_one_pass_values_bitwise(tmp_path, rule):
    logged = run_experiment(Experiment(**BASE, rule=rule), tmp_path / "a", workers=1,
                            progress=False).results
    free = run_experiment(Experiment(**BASE, rule=rule, log_events=False), tmp_path / "b",
                          workers=1, progress=False).results
    keys = ["ic", "system", "diagnostic"]
    both = logged.merge(free, on=keys, suffixes=("_log", "_free"))
    shared = both[both["diagnostic"].isin(["lyapunov", "t_max", "n_pp", "n_kicks",
                                           "kick_rate"])]
    assert len(shared) == 2 * (3 + 4 * 3) + 2 * 2   # + kick_rate of the two Poisson systems
    np.testing.assert_array_equal(shared["value_log"].to_numpy(),
                                  shared["value_free"].to_numpy())
    assert "n_boundary" not in set(free["diagnostic"])


def test_log_events_default_keeps_the_hash():
    exp = Experiment(**BASE)
    assert exp.hash() == Experiment.from_dict(
        {k: v for k, v in exp.to_dict().items() if k != "log_events"}).hash()
    assert Experiment(**BASE, log_events=False).hash() != exp.hash()


@pytest.mark.parametrize(("change", "text"), [
    ({"diagnostics": ("lyapunov", "recurrence_rate")}, "diagnostics"),
    ({"lyapunov_method": "twin"}, "lyapunov_method"),
    ({"sampling": "paper"}, "sampling"),
    ({"systems": ("two_particle", "actual")}, "systems"),
    ({"log_events": "no"}, "log_events"),
])
def test_log_free_experiments_refuse_what_needs_the_logs(change, text):
    with pytest.raises((ValueError, TypeError), match=text):
        Experiment(**{**BASE, **change, "log_events": change.get("log_events", False)})


def test_the_sweeps_horizon_is_collisions_over_the_kinetic_rate():
    exp = small_r_experiment(1e-4, "elastic", n_ics=100, n_collisions=10_000)
    assert exp.horizon * exp.kinetic_rate(1e-4) == pytest.approx(10_000)
    assert exp.ic_method == "uniform" and exp.radii == (1e-4,) and not exp.log_events
    assert SCALES["paper"].radii == (1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2)


@pytest.mark.full
def test_quick_page(tmp_path):
    page = reproduce(tmp_path, scale="quick")
    text = page.read_text(encoding="utf-8")
    assert text.startswith("# The paper's premise at its limit")
    assert "Generated " in text
    head = text.split("\n\n", 3)[2]          # the block after the Generated line
    answers = [ln for ln in head.splitlines() if ln.startswith("- ")]
    assert 1 <= len(answers) <= 5
    assert len(re.findall(r"\S+", text)) <= 2500
    again = reproduce(tmp_path, scale="quick")     # resumes: the stores and theory reused
    assert again == page
