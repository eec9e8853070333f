"""The two-disk kinetic rate in any table: the centre region's covariogram by quadrature
(`Table.covariogram`, `Table.configuration_volume`) and `stats.kinetic_rate(..., table=)`."""

import math

import numpy as np
import pytest

from kicktimes import stats
from kicktimes.billiard.kernels import covariogram as cov
from kicktimes.stats.counts import configuration_volume, lens_area
from kicktimes.tables import Circle, Ellipse, Stadium

FLUX = {"mirror": 4.0 / math.pi**2, "elastic": 4.0 / (3.0 * math.pi)}


class GenericCircle:
    """The unit circle through the generic path of `kinetic_rate` (its covariogram by
    quadrature, not the closed form)."""

    def __init__(self):
        self._c = Circle()

    def check_radius(self, r):
        return self._c.check_radius(r)

    def area(self, r):
        return self._c.area(r)

    def covariogram(self, d, r):
        return self._c.covariogram(d, r)

    def configuration_volume(self, r):
        return self._c.configuration_volume(r)


TABLES = [(Stadium(1.0), 0.02), (Stadium(0.3), 0.3), (Ellipse(1.5, 1.0), 0.02),
          (Ellipse(2.0, 1.0), 0.3)]


def test_circle_quadrature_is_the_closed_form():
    for r in (0.005, 0.05, 0.2, 0.45):
        d = np.array([0.0, 1e-6, 2 * r, 0.5, 1.9 * (1 - r)])
        np.testing.assert_allclose(Circle().covariogram(d, r), lens_area(d, 1 - r),
                                   rtol=1e-12, atol=1e-14)
        assert Circle().configuration_volume(r) == pytest.approx(configuration_volume(r),
                                                                 rel=1e-12)
        for rule in ("mirror", "elastic"):
            closed = stats.kinetic_rate(r, rule=rule)
            generic = stats.kinetic_rate(r, rule=rule, table=GenericCircle())
            assert generic == pytest.approx(closed, rel=1e-9)


def test_circle_table_is_bitwise_the_default():
    r = np.array([0.01, 0.02, 0.1])
    assert np.array_equal(stats.kinetic_rate(r, table=Circle()), stats.kinetic_rate(r))
    assert stats.kinetic_rate(0.03, table=None) == stats.kinetic_rate(0.03)
    assert (stats.kinetic_rate(0.03, rule="elastic", masses=(1.0, 3.0), table=Circle())
            == stats.kinetic_rate(0.03, rule="elastic", masses=(1.0, 3.0)))
    assert stats.kinetic_rate((0.02, 0.05), table=Circle()) == stats.kinetic_rate((0.02, 0.05))


@pytest.mark.parametrize(("table", "r"), TABLES)
def test_covariogram_at_zero_is_the_area_and_vanishes_beyond_the_diameter(table, r):
    assert table.covariogram(0.0, r) == pytest.approx(table.area(r), rel=1e-12)
    diameter = 2.0 * ((table.a + 1.0 - r) if isinstance(table, Stadium) else table.a - r)
    assert table.covariogram(diameter * 1.0001, r) == 0.0
    g = table.covariogram(np.linspace(0.0, diameter, 40), r)
    assert (np.diff(g) < 0).all()  # decreasing: D_r convex


@pytest.mark.parametrize(("table", "r"), TABLES)
def test_covariogram_quadrature_converges(table, r):
    kind, p0, p1, p2 = table.kernel(r)
    d = np.array([1e-4, 2 * r, 0.5, 1.3])
    n, levels = (36, (10, 10)) if isinstance(table, Stadium) else (44, (2, 6))
    fine = cov.covariogram(kind, p0, p1, p2, d, *np.polynomial.legendre.leggauss(n), *levels)
    np.testing.assert_allclose(table.covariogram(d, r), fine, rtol=5e-11)


def _mc_covariogram(table, r, d, n, rng):
    """Monte Carlo of ``g(d)``: ``|B| P(x in D, x - d e in D)``, ``x`` uniform in the
    bounding box ``B``, ``e`` a uniform direction; and its standard error."""
    half_x = table.a + 1.0 if isinstance(table, Stadium) else table.a
    half_y = 1.0 if isinstance(table, Stadium) else table.b
    x = np.column_stack([rng.uniform(-half_x, half_x, n), rng.uniform(-half_y, half_y, n)])
    phi = rng.uniform(0.0, 2 * math.pi, n)
    y = x - d * np.column_stack([np.cos(phi), np.sin(phi)])
    hit = table.contains(x, r) & table.contains(y, r)
    box = 4.0 * half_x * half_y
    p = hit.mean()
    return box * p, box * math.sqrt(p * (1 - p) / n)


@pytest.mark.parametrize(("table", "r", "d", "n"), [
    (Stadium(1.0), 0.02, 0.3, 400_000), (Stadium(1.0), 0.02, 2.5, 400_000),
    (Stadium(0.3), 0.3, 0.8, 400_000), (Ellipse(1.5, 1.0), 0.05, 0.6, 60_000),
    (Ellipse(2.0, 1.0), 0.3, 1.0, 60_000)])
def test_covariogram_against_monte_carlo(table, r, d, n):
    est, se = _mc_covariogram(table, r, d, n, np.random.default_rng(7))
    # 4 standard errors: a false alarm once in ~16000 runs (the seed is fixed)
    assert abs(table.covariogram(d, r) - est) < 4 * se


@pytest.mark.parametrize("table", [Stadium(1.0), Ellipse(1.5, 1.0), GenericCircle()])
def test_small_r_limit(table):
    # Gamma = (2 pi sigma E / |D_r|) (1 - L_r sigma / (pi |D_r|) + O(sigma^2))
    for r in (1e-4, 1e-3):
        sigma = 2 * r
        area = table.area(r)
        perim = (table._c if isinstance(table, GenericCircle) else table).perimeter(r)
        leading = 2 * math.pi * sigma * FLUX["mirror"] / area
        ratio = stats.kinetic_rate(r, table=table) / leading
        slope = (ratio - 1.0) / sigma
        assert slope == pytest.approx(-perim / (math.pi * area), rel=20 * sigma)


def test_rules_masses_and_arrays_in_a_table():
    st = Stadium(1.0)
    mirror = stats.kinetic_rate(0.02, table=st)
    elastic = stats.kinetic_rate(0.02, rule="elastic", table=st)
    assert elastic / mirror == pytest.approx(FLUX["elastic"] / FLUX["mirror"], rel=1e-14)
    heavy = stats.kinetic_rate(0.02, rule="elastic", masses=(1.0, 3.0), table=st)
    circle_factor = (stats.kinetic_rate(0.02, rule="elastic", masses=(1.0, 3.0))
                     / stats.kinetic_rate(0.02, rule="elastic"))
    assert heavy / elastic == pytest.approx(circle_factor, rel=1e-14)
    arr = stats.kinetic_rate([0.01, 0.02], table=st)
    assert arr.shape == (2,) and arr[1] == mirror
    # the stadium's rate sits below the circle's: its region is larger
    assert mirror < stats.kinetic_rate(0.02)


def test_bad_tables_and_radii():
    with pytest.raises(TypeError, match="table"):
        stats.kinetic_rate(0.02, table="stadium")
    with pytest.raises(TypeError, match="table"):
        stats.kinetic_rate(0.02, table=object())
    with pytest.raises(ValueError, match="r"):
        stats.kinetic_rate((0.01, 0.02), table=Stadium(1.0))
    with pytest.raises(ValueError, match=r"r must lie in \(0.0, 0.5\)"):
        stats.kinetic_rate(0.6, table=Ellipse(2.0, 1.0))  # the table's check_radius
    with pytest.raises(ValueError, match="do not fit"):
        stats.kinetic_rate(0.7, table=Ellipse(1.2, 1.0))  # 2 r > the diameter 2 (a - r)
    with pytest.raises(ValueError, match="d must"):
        Stadium(1.0).covariogram(-0.1, 0.02)


# --- the rate against simulated two-disk collision counts ----------------------------------------

def _count_over_rate(table, r, rule, n_ics, collisions_per_ic, seed):
    """Simulated two-disk collisions per unit time over `kinetic_rate`, with its standard
    error over the invariant-measure ICs (each IC's run lasts ``collisions_per_ic / rate``)."""
    from kicktimes import initial_conditions, simulate_two_particle

    rate = stats.kinetic_rate(r, rule=rule, table=table)
    t_max = collisions_per_ic / rate
    ics = initial_conditions(n_ics, r, rng=seed, method="uniform", table=table)
    counts = np.array([simulate_two_particle(ic, r, t_max=t_max, rule=rule, table=table).n_pp
                       for ic in ics], float)
    return counts.mean() / collisions_per_ic, counts.std(ddof=1) / math.sqrt(n_ics) / counts.mean()


@pytest.mark.parametrize("rule", ["mirror", "elastic"])
@pytest.mark.parametrize("table", [Stadium(1.0), Ellipse(1.25, 0.8)], ids=repr)
def test_the_rate_is_the_simulated_collision_rate(table, rule):
    """About 2000 collisions at r = 0.02 (the full test: 2 % at r = 0.01, 0.02, 0.03)."""
    ratio, se = _count_over_rate(table, 0.02, rule, 10, 200, seed=11)
    assert se < 0.05
    assert abs(ratio - 1.0) < 4.0 * se


@pytest.mark.full
@pytest.mark.parametrize("r", [0.01, 0.02, 0.03])
@pytest.mark.parametrize("table", [Stadium(1.0), Ellipse(1.25, 0.8)], ids=repr)
def test_the_rate_is_the_simulated_collision_rate_within_two_percent(table, r):
    """128,000 collisions from 200 invariant-measure ICs: the standard error is 0.35-0.55 %
    (the ICs' rates spread most in the ellipse at r = 0.03), so 2 % is four of them."""
    ratio, se = _count_over_rate(table, r, "mirror", 200, 640, seed=12)
    assert se < 0.006
    assert ratio == pytest.approx(1.0, abs=0.02)
