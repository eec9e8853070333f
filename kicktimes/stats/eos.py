r"""Reference equations of state of the hard-disk fluid: the virial series and Kolafa-Rottner.

The compressibility factor :math:`Z = PA/(NkT)` of hard disks of diameter :math:`\sigma` at
area fraction :math:`\varphi = \pi\rho\sigma^2/4`, against which the N-disk engine's
collisional virial is checked (docs/disks.md, "The equation of state"):

* `virial_z`: the virial series :math:`Z = 1 + \sum_{k \ge 2} b_k (2\varphi)^{k-1}`
  (:math:`B_2 \rho = 2\varphi`), with the reduced coefficients :math:`b_k = B_k /
  B_2^{k-1}` known to :math:`k = 10` (`VIRIAL_COEFFICIENTS`): :math:`b_3, b_4` exact,
  :math:`b_5 \ldots b_{10}` by Clisby & McCoy, J. Stat. Phys. 122, 15 (2006), Table 1. All
  :math:`b_k > 0`, so a truncated series lies below :math:`Z`: at :math:`\varphi = 0.3`
  by about 0.005 %, at 0.4 by about 0.07 %, at 0.5 by 0.6 % (the tail of the
  Kolafa-Rottner fit's own expansion);
* `kolafa_rottner_z`: the simulation-based equation of state of Kolafa & Rottner, Mol.
  Phys. 104, 3435 (2006), eq. (7), their fit to :math:`\rho\sigma^2 \le 0.90`
  (:math:`\varphi \le 0.7069`): :math:`Z = \sum_i A_i x^i`, :math:`x = \varphi/(1 -
  \varphi)`. It reproduces their molecular-dynamics pressures, whose relative errors are
  :math:`2 \times 10^{-6}` at :math:`\rho\sigma^2 = 0.4` to about :math:`10^{-4}` at
  0.89-0.90, and its expansion gives Clisby & McCoy's :math:`b_6 \ldots b_{10}` to about
  their errors. Engel et al., PRE 87, 042134 (2013) (:math:`1024^2` disks) lie 0.03 % below
  it at :math:`\varphi = 0.698`, the edge of the fluid;
* `kicktimes.stats.henderson_z`: Henderson's approximation (Mol. Phys. 30, 971 (1975)),
  0.025 % above Kolafa-Rottner at :math:`\varphi = 0.3`, 0.14 % at 0.4, 1.2 % at 0.6 and
  5 % at 0.68.

The coefficients were read from transcriptions of the papers (Clisby & McCoy's table as
reproduced by SklogWiki; Kolafa & Rottner's as typed in two public scripts from the
paper's pages). Two checks tie them to the exact :math:`b_3, b_4` and to each other:
:math:`A_2 = 4 b_3 - 2` and :math:`A_3 = 8 b_4 - 2 - 2 A_2` hold to the digits given, and
the fit's expansion reproduces :math:`b_5 \ldots b_{10}` (tests/test_eos.py).

Examples
--------
>>> from kicktimes.stats import kolafa_rottner_z, virial_z
>>> round(float(virial_z(0.3)), 5), round(float(kolafa_rottner_z(0.3)), 5)
(2.06316, 2.06326)
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["KOLAFA_ROTTNER", "KOLAFA_ROTTNER_MAX", "VIRIAL_COEFFICIENTS",
           "VIRIAL_COEFFICIENT_ERRORS", "contact_from_z", "kolafa_rottner_z", "virial_z"]

#: reduced virial coefficients b_k = B_k / B_2^(k-1) of hard disks, k = 2..10: b_3 = 4/3 -
#: sqrt(3)/pi and b_4 = 2 - 9 sqrt(3)/(2 pi) + 10/pi^2 exact, b_5..b_10 Clisby & McCoy,
#: J. Stat. Phys. 122, 15 (2006), Table 1
VIRIAL_COEFFICIENTS = (
    1.0,
    4.0 / 3.0 - math.sqrt(3.0) / math.pi,
    2.0 - 9.0 * math.sqrt(3.0) / (2.0 * math.pi) + 10.0 / math.pi ** 2,
    0.33355604,
    0.1988425,
    0.1148728,
    0.0649930,
    0.0362193,
    0.0199537,
)
#: their stated one-standard-error uncertainties (the exact ones: 0)
VIRIAL_COEFFICIENT_ERRORS = (0.0, 0.0, 0.0, 1e-8, 4.2e-6, 4.3e-6, 3.4e-6, 3.5e-6, 8.0e-6)

#: Kolafa & Rottner, Mol. Phys. 104, 3435 (2006), eq. (7), the fit to rho sigma^2 <= 0.90:
#: the nonzero A_i of Z = sum_i A_i x^i, x = phi / (1 - phi), as {i: A_i}
KOLAFA_ROTTNER = {
    0: 1.0, 1: 2.0, 2: 1.12801775, 3: 0.00181895291, 4: -0.0526134737, 5: 0.0504960168,
    6: -0.0325537792, 7: 0.0134578632, 8: 0.00140888182, 9: -0.00834273601,
    10: 0.00694127367, 11: -0.00262254723, 12: 0.000355746352, 22: -5.24672938e-9,
    57: 5.88054639e-23,
}
#: the largest area fraction of that fit's data, pi 0.90 / 4
KOLAFA_ROTTNER_MAX = math.pi * 0.90 / 4.0


def _packing(packing, high: float, why: str) -> np.ndarray:
    phi = np.asarray(packing, dtype=float)
    bad = ~((phi >= 0.0) & (phi <= high))
    if np.any(bad):
        raise ValueError(f"packing must lie in [0, {high:.6g}] ({why}), got "
                         f"{float(phi[bad].ravel()[0])!r}")
    return phi


def _scalar(z: np.ndarray):
    return float(z) if z.ndim == 0 else z


def virial_z(packing, *, order: int = 10):
    r"""The hard-disk virial series to :math:`B_{order}`.

    Parameters
    ----------
    packing : array_like
        Area fraction :math:`\varphi`, in ``[0, 0.5]`` (the series converges slowly beyond:
        at 0.5 its truncation at :math:`B_{10}` is already 0.6 % low).
    order : int
        The last coefficient kept, 2 to 10.

    Returns
    -------
    float or ndarray
        :math:`Z = 1 + \sum_{k=2}^{order} b_k (2\varphi)^{k-1}` (`VIRIAL_COEFFICIENTS`).

    Examples
    --------
    >>> round(float(virial_z(0.1, order=2)), 6)
    1.2
    >>> round(float(virial_z(0.4)), 4)
    2.8273
    """
    if isinstance(order, bool) or not isinstance(order, int | np.integer):
        raise TypeError(f"order must be an integer, got {type(order).__name__}")
    if not 2 <= order <= 1 + len(VIRIAL_COEFFICIENTS):
        raise ValueError(f"order must lie in [2, {1 + len(VIRIAL_COEFFICIENTS)}] (the known "
                         f"coefficients), got {order}")
    phi = _packing(packing, 0.5, "the series' range")
    y = 2.0 * phi
    z = np.ones_like(y)
    for k, b in enumerate(VIRIAL_COEFFICIENTS[: order - 1], start=2):
        z = z + b * y ** (k - 1)
    return _scalar(z)


def kolafa_rottner_z(packing):
    r"""Kolafa & Rottner's equation of state of the hard-disk fluid.

    Parameters
    ----------
    packing : array_like
        Area fraction :math:`\varphi`, in ``[0, KOLAFA_ROTTNER_MAX]`` (0.7069, the fit's
        densest data; the fluid ends near 0.70).

    Returns
    -------
    float or ndarray
        :math:`Z = \sum_i A_i x^i`, :math:`x = \varphi / (1 - \varphi)` (`KOLAFA_ROTTNER`;
        Mol. Phys. 104, 3435 (2006), eq. (7)).

    Examples
    --------
    >>> round(float(kolafa_rottner_z(0.6)), 5)
    6.45534
    """
    phi = _packing(packing, KOLAFA_ROTTNER_MAX, "the fit's range, rho sigma^2 <= 0.90")
    x = phi / (1.0 - phi)
    z = np.zeros_like(x)
    for i, a in KOLAFA_ROTTNER.items():
        z = z + a * x ** i
    return _scalar(z)


def contact_from_z(z, packing):
    r"""The pair correlation at contact from the compressibility factor:
    :math:`g(\sigma) = (Z - 1) / (2\varphi)`, the two-dimensional contact theorem
    :math:`Z = 1 + 2\varphi g(\sigma)` (exact for hard disks).

    >>> round(float(contact_from_z(3.0, 0.5)), 6)
    2.0
    """
    phi = np.asarray(packing, dtype=float)
    if np.any(~(phi > 0.0)):
        raise ValueError(f"packing must be > 0, got {float(phi[~(phi > 0.0)].ravel()[0])!r}")
    zz = np.asarray(z, dtype=float)
    if np.any(~np.isfinite(zz)):
        raise ValueError("z must be finite")
    return _scalar((zz - 1.0) / (2.0 * phi))
