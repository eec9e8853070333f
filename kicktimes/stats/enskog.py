"""The Enskog collision frequency of hard disks, with Henderson's contact value.

The rate at which one disk of a hard-disk fluid collides (docs/disks.md, "The Enskog
check"), for the N-disk billiard's bulk and its whole table.
"""

from __future__ import annotations

import math

import numpy as np

from kicktimes.validation import check_choice, check_int, check_real

__all__ = ["contact_value", "enskog_frequency", "henderson_z", "speed_rate_factor"]

#: the densest packing of disks, pi / sqrt(12)
PACKING_MAX = math.pi / math.sqrt(12.0)


def contact_value(packing):
    r"""Henderson's pair correlation at contact of hard disks at area fraction ``packing``.

    :math:`g(\sigma) = (1 - 7\varphi/16) / (1 - \varphi)^2` (Henderson, Mol. Phys. 30, 971
    (1975)), accurate to about 1 % in the fluid (``packing`` up to about 0.65).

    >>> round(float(contact_value(0.3)), 4)
    1.773
    """
    phi = np.asarray(packing, dtype=float)
    return (1.0 - 7.0 * phi / 16.0) / (1.0 - phi) ** 2


def henderson_z(packing):
    r"""Henderson's compressibility factor of hard disks, :math:`Z = PA/(NkT)`.

    Parameters
    ----------
    packing : array_like
        Area fraction :math:`\varphi = n \pi r^2`, in ``[0, pi / sqrt(12))``.

    Returns
    -------
    ndarray or float
        :math:`Z = (1 + \varphi^2/8) / (1 - \varphi)^2` (Henderson, Mol. Phys. 30, 971
        (1975)).

    Notes
    -----
    The two-dimensional virial equation of state of hard disks is
    :math:`Z = 1 + 2\varphi\, g(\sigma)`, :math:`g(\sigma)` the pair correlation at
    contact; with Henderson's contact value (`contact_value`),
    :math:`1 + 2\varphi (1 - 7\varphi/16)/(1 - \varphi)^2 = (1 + \varphi^2/8)/(1 -
    \varphi)^2`: this function and `contact_value` are one approximation. Its virial
    coefficients in powers of :math:`\varphi`, :math:`2, 3.125, 4.25, 5.375`, against the
    exact :math:`2, 3.1280, 4.2579, 5.3369` (Clisby & McCoy, J. Stat. Phys. 122, 15
    (2006)), differ by 0.1, 0.2 and 0.7 %: at :math:`\varphi = 0.3` the two series differ
    by less than 0.1 % of :math:`Z`.

    Examples
    --------
    >>> round(float(henderson_z(0.3)), 4)
    2.0638
    >>> bool(abs(henderson_z(0.3) - (1 + 2 * 0.3 * contact_value(0.3))) < 1e-12)
    True
    """
    phi = np.asarray(packing, dtype=float)
    if np.any(~(phi >= 0.0) | (phi >= PACKING_MAX)):
        bad = float(phi[~(phi >= 0.0) | (phi >= PACKING_MAX)].ravel()[0])
        raise ValueError(f"packing must lie in [0, pi/sqrt(12) = {PACKING_MAX:.6g}), got "
                         f"{bad!r}")
    z = (1.0 + phi * phi / 8.0) / (1.0 - phi) ** 2
    return float(z) if z.ndim == 0 else z


def enskog_frequency(r, n_disks, *, rule="mirror", area=math.pi, kT=0.5, contact=None):
    r"""Collisions per unit time of one disk among ``n_disks`` disks of radius ``r`` in ``area``.

    Parameters
    ----------
    r : float
        Disk radius (``> 0``).
    n_disks : int
        Number of disks in ``area`` (``>= 1``).
    rule : {"mirror", "elastic"}
        The velocity law: unit speeds with uniform directions (``"mirror"``), or a
        Maxwellian at temperature ``kT`` (unit masses; ``"elastic"``).
    area : float
        The area the disks share (default the unit table's, ``pi``).
    kT : float
        Temperature of the Maxwellian (``"elastic"``): ``kT = E / N`` in two dimensions,
        0.5 for the energy shell ``sum |v|^2 = N`` of `kicktimes.initial_state`.
    contact : float, optional
        The pair correlation at contact :math:`g(\sigma)`; default Henderson's
        (`contact_value`, about 1 % high at packing 0.55, 2.5 % at 0.65). From a measured
        :math:`Z`: `kicktimes.stats.contact_from_z` (the contact theorem), so that the
        frequency and the pressure check each other exactly (docs/disks.md).

    Returns
    -------
    float
        :math:`\nu = n \cdot 2\sigma \cdot g(\sigma) \cdot \langle |v_i - v_j| \rangle`
        with :math:`n` = ``n_disks / area``, :math:`\sigma = 2r`, :math:`g` = ``contact``
        or Henderson's contact value (`contact_value`) at :math:`\varphi = n \pi r^2`.

    Notes
    -----
    A disk moving at relative velocity :math:`w` through partners of density
    :math:`n g(\sigma)` at contact sweeps the area :math:`2\sigma |w|` per unit time (the
    exclusion disk of radius :math:`\sigma` has width :math:`2\sigma`). The mean relative
    speed is :math:`4/\pi` for two unit speeds with independent uniform directions
    (:math:`|w| = 2|\sin(\Delta/2)|`, :math:`\Delta` uniform) and
    :math:`\sqrt{\pi kT/m}` for two Maxwellian velocities (:math:`w` Gaussian of variance
    :math:`2kT/m` per component, its length Rayleigh). Each collision counts for both
    disks, so the table logs :math:`N\nu/2` collisions per unit time.

    Examples
    --------
    >>> round(enskog_frequency(0.01, 1000), 3)
    19.138
    """
    r = check_real("r", r, low=0.0)
    n_disks = check_int("n_disks", n_disks, low=1)
    check_choice("rule", rule, ("mirror", "elastic"))
    area = check_real("area", area, low=0.0)
    kT = check_real("kT", kT, low=0.0)
    n = n_disks / area
    phi = n * math.pi * r * r
    if phi >= PACKING_MAX:
        raise ValueError(f"r: {n_disks} disks of radius {r!r} in area {area!r} have packing "
                         f"{phi:.6g}, more than the densest packing pi/sqrt(12) = "
                         f"{PACKING_MAX:.6g}")
    g = contact_value(phi) if contact is None else check_real("contact", contact, low=0.0)
    w = 4.0 / math.pi if rule == "mirror" else math.sqrt(math.pi * kT)
    return float(n * 4.0 * r * g * w)


def speed_rate_factor(speed, *, kT=0.5):
    r"""How much faster a disk of speed ``speed`` collides than the average disk of a
    Maxwellian gas at temperature ``kT``: :math:`\nu(v) / \bar\nu`.

    Parameters
    ----------
    speed : array_like
        Speeds ``>= 0`` (NaN passes through).
    kT : float
        Temperature (unit masses), ``> 0``; 0.5 on the energy shell ``sum |v|^2 = N``.

    Returns
    -------
    ndarray
        :math:`\langle |v - w| \rangle_w / \langle |w_1 - w_2| \rangle`, with :math:`w`
        Maxwellian: in Enskog's frequency (`enskog_frequency`) a disk of speed :math:`v`
        sweeps partners at the mean relative speed :math:`\langle |v - w| \rangle`, so
        :math:`\nu(v) = n\,2\sigma\,g(\sigma) \langle |v - w| \rangle` and the density
        and contact value cancel in the ratio.

    Notes
    -----
    :math:`|v - w|` is Rice-distributed with scale :math:`\sqrt{kT}`; its mean is
    :math:`\sqrt{\pi kT / 2}\, L_{1/2}(-v^2 / 2kT)`, and with :math:`y = v^2 / 4kT`,
    :math:`L_{1/2}(-2y) = e^{y}[(1 + 2y) I_0(y) + 2y I_1(y)]`. Over :math:`\langle |w_1 -
    w_2| \rangle = \sqrt{\pi kT}`:

    .. math:: \nu(v) / \bar\nu = [(1 + 2y)\, e^{-y} I_0(y) + 2y\, e^{-y} I_1(y)] / \sqrt 2,

    :math:`1/\sqrt 2` at rest, :math:`\to v / \sqrt{\pi kT}` for fast disks, 1 on
    average over the Maxwellian. This is the tagged particle's speed-dependent rate of
    Visco, van Wijland & Trizac, Phys. Rev. E 77, 041117 (2008), in two dimensions.

    Examples
    --------
    >>> import numpy as np
    >>> speed_rate_factor([0.0, 1.0]).round(4).tolist()
    [0.7071, 1.0228]
    >>> v = np.random.default_rng(0).normal(0.0, 0.5 ** 0.5, (200000, 2))
    >>> round(float(speed_rate_factor(np.hypot(v[:, 0], v[:, 1])).mean()), 2)
    1.0
    """
    from scipy.special import i0e, i1e

    kT = check_real("kT", kT, low=0.0)
    v = np.asarray(speed, dtype=float)
    if np.any(v < 0):
        raise ValueError(f"speed must be >= 0, got {float(v[v < 0].ravel()[0])!r}")
    y = v * v / (4.0 * kT)
    return ((1.0 + 2.0 * y) * i0e(y) + 2.0 * y * i1e(y)) / math.sqrt(2.0)
