"""Unequal disks in sweeps and stores: Experiment(partner_ratio=..., partner_mass=...)."""

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from kicktimes import initial_conditions
from kicktimes.experiment import Experiment, load_store, preset, run_experiment
from kicktimes.experiment.tasks import execute_task
from kicktimes.report.counts import sticky_ics
from kicktimes.report.store import store_header
from kicktimes.stats import kinetic_rate

BASE = dict(name="unequal", radii=[0.01, 0.02], n_ics=3, n_steps=1200, tau=0.2,
            block_size=3)
#: every preset's hash before partner_ratio and partner_mass existed (commit 3deab2e), with
#: the systems the presets had then (issue 38 added uniform_kinetic, and made
#: family_a_elastic the elastic rule from the paper's ICs, so that one is not pinned)
OLD_HASHES = {"family_a": "a7371aa8fff2f127", "family_b": "8d4618ac597dbaa9",
              "quick_a": "2abaf951939c2ad2", "quick_b": "f80f9e7803cd150b",
              "family_a_invariant": "408e3cac229aa00d"}
OLD_SYSTEMS = ("two_particle", "poisson", "actual", "poisson_scatter", "actual_scatter",
               "poisson_kinetic")


def test_default_experiments_keep_their_hash():
    for name, old in OLD_HASHES.items():
        exp = dataclasses.replace(preset(name), systems=OLD_SYSTEMS)
        assert exp.hash() == old
        assert dataclasses.replace(exp, partner_ratio=1, partner_mass=1.0).hash() == old
    paper = dataclasses.replace(preset("quick_a"), systems=["two_particle", "poisson", "actual"])
    assert dataclasses.replace(paper, partner_ratio=2.0).hash() != paper.hash()


def test_the_partner_is_a_toml_key_shown_in_the_summary():
    exp = Experiment(**BASE, partner_ratio=2, rule="elastic", partner_mass=3.0,
                     ic_method="uniform")
    assert exp.partner_ratio == 2.0 and isinstance(exp.partner_ratio, float)
    assert Experiment.from_toml_string(exp.to_toml()) == exp
    assert "partner_ratio = 2.0" in exp.to_toml()
    assert "disk 1 has radius 2 r, mass 3 m0" in exp.summary()
    assert "partner_ratio=2.0" in repr(exp)
    assert "disk 1" not in Experiment(**BASE).summary()
    assert "drawn at r_max = (0.02, 0.04)" in exp.summary()
    assert exp.radius_pair(0.01) == (0.01, 0.02) and exp.masses == (1.0, 3.0)
    assert exp.kinetic_rate(0.01) == kinetic_rate((0.01, 0.02), rule="elastic", masses=(1.0, 3.0))
    np.testing.assert_array_equal(
        Experiment(**BASE).kinetic_rate(np.array([0.01, 0.02])),
        kinetic_rate(np.array([0.01, 0.02])))


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(partner_ratio=0.0), ValueError, r"partner_ratio must lie in \(0.0, inf\)"),
    (dict(partner_ratio=math.inf), ValueError, "partner_ratio must be finite"),
    (dict(partner_ratio="2"), TypeError, "partner_ratio must be a real number"),
    (dict(partner_ratio=30.0), ValueError,
     r"partner_ratio: disk 1 at the largest radius has radius 30.0 \* 0.02 = 0.6.*"
     r"partner_ratio <= 25"),
    (dict(partner_ratio=20.0, ic_method="uniform"), ValueError,
     r"at most 0.333333 \(ic_method='uniform'\)"),
    (dict(partner_mass=2.0), ValueError, "partner_mass: masses apply to rule='elastic'"),
    (dict(partner_mass=2.0, rule="elastic"), ValueError, "ic_method='uniform'"),
    (dict(partner_mass=-1.0, rule="elastic", ic_method="uniform"), ValueError,
     r"partner_mass must lie in \(0.0, inf\)"),
    (dict(partner_ratio=2.0, systems=["two_particle", "poisson_kinetic"]), ValueError,
     "'poisson_kinetic' system tabulates the kinetic rate of equal disks"),
])
def test_bad_partners_are_refused_naming_the_key(kwargs, error, match):
    with pytest.raises(error, match=match):
        Experiment(**{**BASE, **kwargs})


@pytest.mark.parametrize("method", ["paper", "uniform"])
@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_the_ics_are_valid_for_the_pair_at_every_radius(method, ratio):
    exp = Experiment(**{**BASE, "n_ics": 200, "radii": [0.01, 0.05, 0.1]},
                     partner_ratio=ratio, ic_method=method)
    ics = initial_conditions(exp.n_ics, exp.ic_radius, rng=exp.seed, method=method)
    for r in exp.radii:
        r0, r1 = exp.radius_pair(r)
        assert (np.hypot(ics[:, 0, 0], ics[:, 0, 1]) <= 1 - r0).all()
        assert (np.hypot(ics[:, 1, 0], ics[:, 1, 1]) <= 1 - r1).all()
        gap = np.hypot(*(ics[:, 0, :2] - ics[:, 1, :2]).T)
        assert (gap >= r0 + r1).all()
    if method == "paper" and ratio < 1:  # the larger disk is disk 0: the equal-disk ICs
        np.testing.assert_array_equal(
            ics, initial_conditions(exp.n_ics, exp.r_max, rng=exp.seed))


@pytest.mark.parametrize("extra", [
    dict(partner_ratio=2.0),
    dict(partner_ratio=0.5, rule="elastic", partner_mass=3.0, ic_method="uniform"),
])
def test_one_pass_equals_separate_runs_with_a_partner(extra):
    exp = Experiment(**BASE, systems=["two_particle", "poisson", "actual", "poisson_scatter",
                                      "actual_scatter"], sampling="paper",
                     rr_sampling="run+uniform", **extra)
    tables = []
    for one_pass in (True, False):
        tables.append(pd.concat([execute_task(exp, t, one_pass=one_pass).results
                                 for t in exp.tasks()], ignore_index=True))
    pd.testing.assert_frame_equal(tables[0], tables[1], check_exact=True)
    # and not the equal-disk sweep: the partner changes the two-disk collisions
    equal = dataclasses.replace(exp, partner_ratio=1.0, partner_mass=1.0)
    same = pd.concat([execute_task(equal, t).results for t in equal.tasks()])
    n_pp = tables[0].query("diagnostic == 'n_pp'")["value"].to_numpy()
    assert not np.array_equal(n_pp, same.query("diagnostic == 'n_pp'")["value"].to_numpy())


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_a_sweeps_mean_count_is_the_pairs_kinetic_count(tmp_path, ratio):
    # invariant ICs of the pair at the single radius: the count's mean is Gamma(r0, r1) T
    exp = Experiment(name="count", radii=[0.02], n_ics=300, n_steps=1000, tau=0.5,
                     ic_method="uniform", systems=["two_particle"],
                     diagnostics=["autocorrelation"], block_size=150, partner_ratio=ratio)
    store = run_experiment(exp, tmp_path / "s", workers=1, progress=False)
    coll = load_store(tmp_path / "s").collisions
    assert "disk 1 has radius" in store.summary()
    header, _ = store_header(store, [])
    assert f"disk 1 has radius {ratio:g} r" in header and "0.02, " in header
    # the report's kinetic rate (sticky runs, counts) is the pair's
    sticky = sticky_ics(coll, exp.rule, kinetic=exp.kinetic_rate)
    np.testing.assert_allclose(sticky["kinetic_rate"], kinetic_rate((0.02, ratio * 0.02)),
                               rtol=1e-14)
    counts = coll["n_pp"].to_numpy(float)
    gamma = kinetic_rate((0.02, ratio * 0.02))
    expected = gamma * coll["t_window"].to_numpy(float)
    z = (counts - expected).mean() / (counts.std(ddof=1) / np.sqrt(counts.size))
    assert abs(z) < 3.5
    # the equal-disk rate is 25 % off: the test can tell the pair's rate from it
    assert abs(kinetic_rate(0.02) / gamma - 1) > 0.2
