r"""The disk-disk collision rate conditioned on the two angular momenta.

Between disk-disk collisions each centre runs on a free orbit of the circular billiard
``|x| <= rho = 1 - r``: its angular momentum :math:`L = x \times v` about the table's
centre is conserved, and the chords are tangent to the caustic :math:`|x| = |L|/|v|`.
The collision rate is therefore a function :math:`\Gamma(r; L_1, L_2)`, reset at every
collision (:func:`conditional_kinetic_rate`); its average over the partner's law is the
rate :math:`\bar\Gamma(r; L)` that one disk sees (:func:`mean_kinetic_rate`), and its
average over the invariant law of both is :func:`kinetic_rate` up to the disks'
excluded volume. The derivation, the substitutions of the quadrature and the measured
accuracy are in ``docs/kinetic.md``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ._checks import as_1d_float, check_choice, check_int
from ._kinetic_quadrature import conditional_rates, invariant_partner_rates

__all__ = ["conditional_kinetic_rate", "mean_kinetic_rate"]

_RULES = ("mirror", "elastic")
#: Gauss-Legendre nodes per piece of every quadrature. The relative quadrature error of
#: ``conditional_kinetic_rate`` at 24 nodes, measured against 160 on 300 random and
#: adversarial (r, L1, L2): median 1e-5, at most 2.2e-4 for r <= 0.1 and 1.3e-3 for r < 0.5;
#: it falls as n^-2 or faster (the kinks of the positive part of the approach speed).
DEFAULT_NODES = 24


@lru_cache(maxsize=8)
def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _at(arr, mask):
    """``[i, j] = value`` of the first entry of ``arr`` where ``mask`` holds."""
    idx = np.unravel_index(int(np.flatnonzero(mask)[0]), arr.shape)
    where = f"[{', '.join(str(int(i)) for i in idx)}]" if arr.ndim else ""
    return f"{where} = {float(arr[idx])!r}"


def _real_array(name, value):
    """A finite, non-empty float array of any shape (a number is a 0-d array)."""
    arr = None if isinstance(value, str | bytes) else np.asarray(value)
    if arr is None or arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must be a real number or an array of real numbers, got "
            f"{type(value).__name__}" + ("" if arr is None else f" of dtype {arr.dtype}")
        )
    arr = arr.astype(np.float64)
    if arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(f"{name} must be finite, got {name}{_at(arr, bad)}")
    return arr


def _radius(r):
    arr = _real_array("r", r)
    bad = (arr <= 0) | (arr >= 0.5)
    if bad.any():
        raise ValueError(f"r must satisfy 0 < r < 0.5 for two disks, got r{_at(arr, bad)}")
    return arr


def _speeds(rule, **given):
    """The speeds of the named disks: 1 under the mirror rule (none may be given), the
    given positive numbers under the elastic rule (each one required)."""
    out = {}
    for name, value in given.items():
        if rule == "mirror":
            if value is not None:
                raise ValueError(
                    f"{name} is fixed to 1 by the mirror rule (unit speeds); pass speeds "
                    f"only with rule='elastic', got {name} = {value!r}"
                )
            out[name] = np.float64(1.0)
            continue
        if value is None:
            raise ValueError(
                f"rule='elastic' needs {name}: speeds change at elastic collisions, so "
                "the rate is conditioned on them too"
            )
        arr = _real_array(name, value)
        if (arr <= 0).any():
            raise ValueError(f"{name} must be positive, got {name}{_at(arr, arr <= 0)}")
        out[name] = arr
    return out


def _momentum(name, value, r, speed, speed_name):
    """Angular momenta inside the open range ``|L| < speed (1 - r)`` (all broadcast)."""
    bad = np.abs(value) >= speed * (1.0 - r)
    if bad.any():
        i = np.unravel_index(int(np.flatnonzero(bad)[0]), value.shape)
        bound = ("1 - r" if speed_name is None else f"{speed_name} * (1 - r)")
        extra = "" if speed_name is None else f", {speed_name} = {float(speed[i])!r}"
        raise ValueError(
            f"{name} must satisfy |{name}| < {bound} (a centre moves in |x| <= 1 - r), got "
            f"{name}{_at(value, bad)} at r = {float(r[i])!r}{extra}"
        )


def _broadcast(**arrays):
    try:
        return np.broadcast_arrays(*arrays.values())
    except ValueError:
        shapes = ", ".join(f"{k} {np.shape(v)}" for k, v in arrays.items())
        raise ValueError(f"{', '.join(arrays)} must broadcast together, got shapes "
                         f"{shapes}") from None


def _flat(*arrays):
    # fresh contiguous copies: broadcast views are read-only (numba would warn)
    return [np.array(a, dtype=np.float64).ravel() for a in arrays]


def _shaped(values, shape):
    return float(values[0]) if shape == () else values.reshape(shape)


def conditional_kinetic_rate(r, L1, L2, *, rule="mirror", speed1=None, speed2=None,
                             n_nodes=DEFAULT_NODES):
    r"""Collision rate of two disks on free orbits with angular momenta ``L1`` and ``L2``.

    Two disks of radius ``r`` in the unit table, each centre on the free circular-billiard
    orbit of its signed angular momentum :math:`L_i = x_i \times v_i` (positive
    counter-clockwise), with independent uniform phases on the two invariant tori: the
    rate at which the centres reach the contact distance :math:`2r` while approaching.

    Parameters
    ----------
    r : float or array_like
        Disk radius, ``0 < r < 0.5``.
    L1, L2 : float or array_like
        Angular momenta about the table's centre, ``|L_i| < speed_i * (1 - r)``.
        ``r``, ``L1``, ``L2`` (and the speeds) broadcast together.
    rule : {"mirror", "elastic"}, optional
        ``"mirror"``: unit speeds (the speeds may not be given). ``"elastic"``: the speeds
        change at collisions, so the rate is conditioned on them: ``speed1`` and
        ``speed2`` are required.
    speed1, speed2 : float or array_like, optional
        The disks' speeds under the elastic rule (positive; ``speed1**2 + speed2**2 = 2``
        for kicktimes' initial conditions, but any positive values are allowed).
    n_nodes : int, optional
        Gauss-Legendre nodes per piece of each quadrature (4 to 1024).

    Returns
    -------
    float or ndarray
        :math:`\Gamma(r; L_1, L_2)` in collisions per unit time (table radius over unit
        speed), a float for scalar input, else of the broadcast shape.

    Raises
    ------
    ValueError
        A value outside its range (the message names the argument, the entry and the
        range), speeds under the mirror rule, missing speeds under the elastic rule, or
        shapes that do not broadcast.
    TypeError
        A non-numeric argument.

    Notes
    -----
    With :math:`\rho = 1 - r`, :math:`\sigma = 2r` and :math:`\kappa_i = L_i/c_i` (speed
    :math:`c_i`), the centre of disk *i* at a uniform phase has the density
    :math:`p_i(R) = 1 / (2\pi\sqrt{\rho^2-\kappa_i^2}\sqrt{R^2-\kappa_i^2})` on the
    annulus :math:`|\kappa_i| \le R \le \rho`, and its velocity at :math:`x` has the
    tangential component :math:`c_i\kappa_i/R` and the radial one
    :math:`\pm c_i\sqrt{1-\kappa_i^2/R^2}`, each sign with probability 1/2. The rate is
    the flux of approaching pairs through the contact circle,

    .. math::

        \Gamma = \int dA_1\, p_1(x_1) \oint \sigma\, d\phi\; p_2(x_1 + \sigma n)\;
                 E_\pm\big[((v_1 - v_2)\cdot n)^+\big],
        \qquad n = (\cos\phi, \sin\phi),

    (approaching: :math:`d|x_1 - x_2|/dt = -(v_1 - v_2)\cdot n < 0`), with :math:`x_1`
    put on the x-axis by rotational symmetry. The radial integral is split where the
    contact circle starts to cross the partner's caustic or the rim and mapped by
    :math:`R_1 = a + (b - a)\sin^2(\theta/2)` (which absorbs the caustic's inverse square
    root); the angular one, in :math:`u = \cos\phi`, runs over the arc where the partner is
    on its annulus and each half is mapped by :math:`u - u_0 = \delta\sinh^2 t`, which
    makes the partner's caustic singularity and the one of :math:`d\phi` smooth however
    close they are (``docs/kinetic.md``). The relative quadrature error at the default
    24 nodes was at most 2.2e-4 for ``r <= 0.1`` and 1.3e-3 for ``r < 0.5`` (median 1e-5);
    it falls as :math:`n^{-2}` or faster (the kinks of the positive part are not located).

    The phases are independent, so pairs of centres closer than :math:`2r` are not
    excluded: the excluded volume is ignored. Restricted to non-overlapping pairs the
    rate would be :math:`\Gamma / (1 - P_{ov})`, with :math:`P_{ov}(L_1, L_2)` the
    probability that independent phases overlap: a relative error of order :math:`r^2`
    (:math:`r^2 \log(1/r)` for :math:`|L_1| = |L_2|`). Averaged over the invariant law of
    both momenta it is exact: the average is ``kinetic_rate(r) * |Q| / (pi a^2)^2``
    (:func:`mean_kinetic_rate`). Correlations that a collision leaves between the two
    orbits (re-collisions) are not in this rate.

    References
    ----------
    .. [1] S. Chapman and T. G. Cowling, *The Mathematical Theory of Non-Uniform Gases*,
       3rd ed., Cambridge University Press (1970), ch. 5 (the collision frequency as a
       flux through the contact sphere).
    .. [2] S. Ranković and M. A. Porter, "Two-particle circular billiards versus randomly
       perturbed one-particle circular billiards", Chaos 23, 013123 (2013).

    Examples
    --------
    >>> from kicktimes import stats
    >>> rates = stats.conditional_kinetic_rate(0.01, 0.3, [0.3, -0.3, 0.0])
    >>> [round(float(g), 4) for g in rates]  # same sense, opposite sense, radial partner
    [0.0132, 0.0423, 0.0164]
    """
    check_choice("rule", rule, _RULES)
    n_nodes = check_int("n_nodes", n_nodes, low=4, high=1024)
    speeds = _speeds(rule, speed1=speed1, speed2=speed2)
    r = _radius(r)
    L1 = _real_array("L1", L1)
    L2 = _real_array("L2", L2)
    r, L1, L2, c1, c2 = _broadcast(r=r, L1=L1, L2=L2, **speeds)
    names = (None, None) if rule == "mirror" else ("speed1", "speed2")
    _momentum("L1", L1, r, c1, names[0])
    _momentum("L2", L2, r, c2, names[1])
    flat_r, k1, k2, f1, f2 = _flat(r, L1 / c1, L2 / c2, c1, c2)
    rates = conditional_rates(flat_r, k1, k2, f1, f2, *_gauss(n_nodes))
    return _shaped(rates, r.shape)


def mean_kinetic_rate(r, L, *, partner="invariant", partner_weights=None, partner_strata=None,
                      rule="mirror", speed=None, partner_speed=None, n_nodes=DEFAULT_NODES):
    r"""Collision rate of a disk with angular momentum ``L``, averaged over its partner.

    :math:`\bar\Gamma(r; L) = E_{L_2}[\Gamma(r; L, L_2)]`, with
    :math:`\Gamma` of :func:`conditional_kinetic_rate` and the partner's angular
    momentum drawn from its invariant law or from a given sample (for example the
    empirical post-collision law).

    Parameters
    ----------
    r : float or array_like
        Disk radius, ``0 < r < 0.5``.
    L : float or array_like
        The disk's angular momentum, ``|L| < speed * (1 - r)``; broadcasts with ``r``
        (and ``speed``).
    partner : "invariant" or array_like, optional
        ``"invariant"``: the partner is a draw from the invariant measure, centre uniform
        in ``|x| <= 1 - r`` and direction uniform, so that its angular momentum has the
        density :math:`f(L_2) = 2\sqrt{\rho^2 - L_2^2}/(\pi\rho^2)` on
        :math:`(-\rho, \rho)`. An array: a sample of the partner's angular momenta
        (1-D, each ``|L2| < partner_speed * (1 - r)``); the result is the (weighted) mean
        of :math:`\Gamma(r; L, L_2)` over it.
    partner_weights : array_like, optional
        Non-negative weights of the sample (e.g. the counts of a histogram whose bin
        centres are ``partner``); equal weights by default. Only with a sample.
    partner_strata : int, optional
        Only with a sample: if it has more values, average over this many strata of equal
        count instead (the sorted sample cut into consecutive groups, each represented by
        its weighted mean), which bounds the cost. An approximation: with 256 strata of a
        sample of 3000 the relative error was at most 1e-3 (at most 3e-3 with 128).
        ``None`` (default): the exact average over the whole sample.
    rule : {"mirror", "elastic"}, optional
        As in :func:`conditional_kinetic_rate`.
    speed : float or array_like, optional
        The disk's speed, required under the elastic rule (and ``< sqrt(2)`` with an
        invariant partner of the default speed).
    partner_speed : float or array_like, optional
        Elastic rule only. With ``partner="invariant"``: the partner's speed, broadcast
        with ``L``; by default :math:`\sqrt{2 - c^2}`, the invariant law of kicktimes'
        elastic runs (velocities uniform on :math:`|v_1|^2 + |v_2|^2 = 2`, so the partner's
        velocity is uniform on that circle). With a sample: one speed per sample value
        (required).
    n_nodes : int, optional
        Gauss-Legendre nodes per piece of each quadrature (4 to 1024).

    Returns
    -------
    float or ndarray
        :math:`\bar\Gamma` in collisions per unit time, a float for scalar input, else of
        the broadcast shape of ``r``, ``L`` and the speeds.

    Raises
    ------
    ValueError, TypeError
        As :func:`conditional_kinetic_rate`; also an empty or non-1-D sample, weights of
        the wrong length, negative or all zero, or ``partner_speed`` given where it has
        no meaning.

    Notes
    -----
    Mixing the partner's invariant tori with the density :math:`f` gives back the
    invariant measure (centre uniform in the disk of radius :math:`\rho`, direction
    uniform), so for ``partner="invariant"`` the partner's velocity average is done in
    closed form, :math:`E_\theta[(v - c_2\cos\theta)^+] = c_2\,h(v/c_2)` with
    :math:`h(x) = ((\pi - \arccos x)\,x + \sqrt{1 - x^2})/\pi` on :math:`|x| \le 1`
    (:math:`h = x^+` outside), and only a two-dimensional smooth quadrature remains: 200
    values of ``L`` take about 30 ms. For small ``r`` it tends to
    :math:`16r/(\pi^2\rho^2)` for every ``L`` away from the rim (the invariant partner
    does not care where the disk is); it drops for orbits that hug the rim. Its average
    over :math:`f(L)` is exactly the rate of independent uniform centres,
    ``kinetic_rate(r) * |Q| / (pi a^2)^2`` (``a = 1 - r``): the independent phases ignore
    the excluded volume, a relative difference :math:`|Q|/(\pi a^2)^2 - 1 \approx
    -4r^2/a^2` (-4.0e-4 at r = 0.01, -1.06e-2 at r = 0.05). A sample costs one
    :func:`conditional_kinetic_rate` (0.1 to 0.25 ms) per pair of ``L`` and sample value;
    bound it with ``partner_strata`` (or pass histogram bins with ``partner_weights``).

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import stats
    >>> L = np.array([0.0, 0.5, 0.9, 0.98])
    >>> np.round(stats.mean_kinetic_rate(0.01, L) / stats.kinetic_rate(0.01), 3)
    array([1.006, 1.003, 0.975, 0.636])
    >>> sample = np.array([-0.6, 0.0, 0.6])
    >>> round(float(stats.mean_kinetic_rate(0.01, 0.3, partner=sample)), 4)
    0.0145
    """
    check_choice("rule", rule, _RULES)
    n_nodes = check_int("n_nodes", n_nodes, low=4, high=1024)
    c1 = _speeds(rule, speed=speed)["speed"]
    r = _radius(r)
    L = _real_array("L", L)
    invariant = isinstance(partner, str)
    if invariant:
        check_choice("partner", partner, ("invariant",))
        for name, value in (("partner_weights", partner_weights),
                            ("partner_strata", partner_strata)):
            if value is not None:
                raise ValueError(f"{name} apply to a sample; they have no meaning with "
                                 "partner='invariant'")
    if rule == "mirror" and partner_speed is not None:
        raise ValueError("partner_speed is fixed to 1 by the mirror rule (unit speeds); pass "
                         f"it only with rule='elastic', got partner_speed = {partner_speed!r}")
    r, L, c1 = _broadcast(r=r, L=L, speed=c1)
    _momentum("L", L, r, c1, None if rule == "mirror" else "speed")
    if invariant:
        c2 = _invariant_partner_speed(rule, c1, partner_speed)
        r, L, c1, c2 = _broadcast(r=r, L=L, speed=c1, partner_speed=c2)
        flat_r, kap, f1, f2 = _flat(r, L / c1, c1, c2)
        rates = invariant_partner_rates(flat_r, kap, f1, f2, *_gauss(n_nodes))
        return _shaped(rates, r.shape)
    sample, weights, c2 = _partner_sample(partner, partner_weights, rule, partner_speed)
    rho_min = 1.0 - float(r.max())
    bad = np.abs(sample) >= c2 * rho_min
    if bad.any():
        bound = "1 - r" if rule == "mirror" else "partner_speed * (1 - r)"
        raise ValueError(f"partner must satisfy |L2| < {bound} at every r (largest r = "
                         f"{float(r.max())!r}), got partner{_at(sample, bad)}")
    kap2 = sample / c2
    if partner_strata is not None:
        n_strata = check_int("partner_strata", partner_strata, low=2)
        if sample.size > n_strata:
            kap2, c2, weights = _strata(kap2, c2, weights, n_strata)
    flat_r, kap, f1 = _flat(r, L / c1, c1)
    m, k = flat_r.size, kap2.size
    rates = conditional_rates(
        np.repeat(flat_r, k), np.repeat(kap, k), np.tile(kap2, m), np.repeat(f1, k),
        np.tile(c2, m), *_gauss(n_nodes),
    ).reshape(m, k)
    return _shaped(rates @ weights / weights.sum(), r.shape)


def _strata(kap2, c2, weights, n_strata):
    """The sample cut, in the order of ``kap2``, into ``n_strata`` groups of equal count,
    each replaced by its weighted means and total weight."""
    groups = np.array_split(np.argsort(kap2, kind="stable"), n_strata)
    groups = [g for g in groups if weights[g].sum() > 0]
    total = np.array([weights[g].sum() for g in groups])
    kap_mean = np.array([weights[g] @ kap2[g] for g in groups]) / total
    c2_mean = np.array([weights[g] @ c2[g] for g in groups]) / total
    return kap_mean, c2_mean, total


def _invariant_partner_speed(rule, c1, partner_speed):
    if rule == "mirror":
        return np.float64(1.0)
    if partner_speed is not None:
        return _speeds("elastic", partner_speed=partner_speed)["partner_speed"]
    bad = c1 >= np.sqrt(2.0)
    if bad.any():
        raise ValueError("speed must be < sqrt(2) for the default partner speed "
                         f"sqrt(2 - speed**2), got speed{_at(c1, bad)}; or pass partner_speed")
    return np.sqrt(2.0 - c1 * c1)


def _partner_sample(partner, partner_weights, rule, partner_speed):
    """The sample of partner momenta, its normalised weights and the speeds."""
    sample = as_1d_float("partner", partner, allow_empty=False)
    if partner_weights is None:
        weights = np.ones(sample.size)
    else:
        weights = as_1d_float("partner_weights", partner_weights, allow_empty=False)
        if weights.size != sample.size:
            raise ValueError(f"partner_weights must have one weight per partner value "
                             f"({sample.size}), got {weights.size}")
        if (weights < 0).any() or not weights.any():
            raise ValueError("partner_weights must be non-negative and not all zero, got "
                             f"min {float(weights.min())!r}, sum {float(weights.sum())!r}")
    if rule == "mirror":
        return sample, weights, np.ones(sample.size)
    if partner_speed is None:
        raise ValueError("rule='elastic' with a partner sample needs partner_speed, one "
                         "speed per sample value")
    c2 = as_1d_float("partner_speed", partner_speed, allow_empty=False)
    if c2.size != sample.size or (c2 <= 0).any():
        raise ValueError(f"partner_speed must hold {sample.size} positive speeds, one per "
                         f"partner value, got {c2.size} with minimum {float(c2.min())!r}")
    return sample, weights, c2
