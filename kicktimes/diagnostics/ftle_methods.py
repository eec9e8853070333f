"""The two methods of `kicktimes.diagnostics.lyapunov`, each with its own options.

``method=Tangent(...)`` carries tangent vectors through the exact linearised event maps;
``method=Twin(...)`` follows Benettin's twin trajectory at distance ``d0`` (docs/lyapunov.md).
The strings ``"tangent"`` and ``"twin"`` stay as the spelling of either with its defaults,
as scipy's ``method="..."``: the common call needs no import, and an option that belongs to
the other method cannot be given (``Tangent`` has no ``d0``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from kicktimes._results import Result
from kicktimes.validation import check_choice, check_int, check_real

__all__ = ["D0_DEFAULT", "D0_RANGE", "OLD_METHOD_KEYWORDS", "TWIN_KICKS", "Tangent", "Twin",
           "VARIANTS", "as_method", "method_from_old"]

VARIANTS = ("norm", "paper")
#: the kicked twins' kicks: the run's angles, or each twin's own at the same times
TWIN_KICKS = ("shared", "independent")
D0_DEFAULT = 1.0 / 5000.0  # the paper's
D0_RANGE = (1e-10, 1e-2)


def _check_bool(name, value) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be a bool, got {type(value).__name__}")
    return bool(value)


@dataclass(frozen=True, repr=False)
class Tangent(Result):
    """The tangent method of `lyapunov`: exact propagation of tangent vectors (default).

    Parameters
    ----------
    variant : {"norm", "paper"}
        ``"norm"``: one tangent vector along x of the tracked disk; the 2-norm of its
        position deviation is measured. ``"paper"``: vectors along x and along y,
        ``|dx|`` and ``|dy|`` measured separately, ``lam = max(lam_x, lam_y)``.
    return_run : bool
        Also return the simulated run, ``(result, run)``: the `TwoParticleRun` /
        `OneParticleRun` the simulator returns for the same arguments (every field bitwise
        equal, ``seed=None``), from the same single pass of the event loop that carries the
        tangent vectors. Only this method has one pass (the twin's needs a separate
        simulation).

    Examples
    --------
    >>> from kicktimes import initial_conditions
    >>> from kicktimes.diagnostics import Tangent, lyapunov
    >>> ic = initial_conditions(1, 0.03, rng=3)[0]
    >>> res, run = lyapunov(ic, 0.03, n_steps=2000, tau=0.2,
    ...                     method=Tangent(variant="paper", return_run=True))
    >>> res.variant, run.n_steps
    ('paper', 2000)
    """

    _title = 'FTLE method: tangent vectors'

    name: ClassVar[str] = "tangent"
    variant: str = "norm"
    return_run: bool = False

    def __post_init__(self):
        check_choice("variant", self.variant, VARIANTS)
        object.__setattr__(self, "return_run", _check_bool("return_run", self.return_run))


@dataclass(frozen=True, repr=False)
class Twin(Result):
    """Benettin's twin trajectory at distance ``d0``, renormalised at the sample times.

    The paper's method; for small enough ``d0`` it converges to the tangent result.

    Parameters
    ----------
    d0 : float
        Initial separation and renormalisation length, in ``[1e-10, 1e-2]`` (default the
        paper's 1/5000).
    variant : {"norm", "paper"}
        As for `Tangent`: one twin offset along x (2-norm measured), or twins along x and y
        (``|dx|``, ``|dy|``).
    renormalize : bool
        ``True`` (default): Benettin's algorithm, the twin renormalised to ``d0`` at every
        sample. ``False``: eq. (4) of Ranković & Porter (2013) read literally, the twin
        never renormalised, ``lam = sum_k log(d_k / d0) / (n tau)`` (not an exponent once
        the separation saturates; docs/lyapunov.md).
    twin_kicks : {"shared", "independent"}
        Kicked disk only. ``"shared"`` (default): the twins are kicked at the run's times
        with the run's angles (common random numbers). ``"independent"``: each twin gets
        angles of its own, drawn from ``rng`` by the same law after the run's kicks (not for
        scattering or kinetic-rate kicks).
    max_defer : int
        Consecutive deferred renormalisations after which one is forced (``>= 0``).

    Examples
    --------
    >>> from kicktimes import initial_conditions
    >>> from kicktimes.diagnostics import Twin, lyapunov
    >>> ic = initial_conditions(1, 0.03, rng=3)[0]
    >>> res = lyapunov(ic, 0.03, n_steps=2000, tau=0.2, method=Twin(d0=1e-8))
    >>> res.method, res.d0
    ('twin', 1e-08)
    """

    _title = 'FTLE method: Benettin twin trajectory'

    name: ClassVar[str] = "twin"
    d0: float = D0_DEFAULT
    variant: str = "norm"
    renormalize: bool = True
    twin_kicks: str = "shared"
    max_defer: int = 10

    def __post_init__(self):
        object.__setattr__(self, "d0", check_real(
            "d0", self.d0, low=D0_RANGE[0], high=D0_RANGE[1], low_open=False,
            high_open=False))
        check_choice("variant", self.variant, VARIANTS)
        object.__setattr__(self, "renormalize", _check_bool("renormalize", self.renormalize))
        check_choice("twin_kicks", self.twin_kicks, TWIN_KICKS)
        object.__setattr__(self, "max_defer", check_int("max_defer", self.max_defer, low=0))


_BY_NAME = {"tangent": Tangent, "twin": Twin}


def as_method(method) -> Tangent | Twin:
    """``method`` as a method object: one itself, or its name with the default options."""
    if isinstance(method, Tangent | Twin):
        return method
    if isinstance(method, str) and method in _BY_NAME:
        return _BY_NAME[method]()
    raise ValueError(f"method must be one of ['tangent', 'twin'] or a Tangent(...) / Twin(...), "
                     f"got {method!r}")


#: lyapunov's method options before 0.2.0: each became a field of `Tangent` / `Twin`
OLD_METHOD_KEYWORDS = ("variant", "d0", "max_defer", "renormalize", "twin_kicks", "return_run")
#: (default, message) of a twin option given with method="tangent", as before 0.2.0
_TWIN_ONLY = {
    "d0": (None, "d0 applies to method='twin' only (the tangent method has no separation "
                 "scale); got d0={!r} with method='tangent'"),
    "renormalize": (True, "renormalize=False (eq. (4) read literally) applies to "
                          "method='twin' only, got method='tangent'"),
    "twin_kicks": ("shared", "twin_kicks='independent' applies to method='twin' only (a "
                             "tangent vector has no kicks of its own), got method='tangent'"),
}


def method_from_old(method, old: dict):
    """The `Tangent` / `Twin` of a method name and its old flat options."""
    if not isinstance(method, str):
        raise TypeError(f"lyapunov: method is {method!r}; give {', '.join(old)} as its fields, "
                        "not as keywords")
    if method == "twin":
        if old.pop("return_run", False):
            raise ValueError("return_run=True needs method='tangent' (the one-pass kernels "
                             "carry tangent vectors; for the twin method call "
                             "simulate_two_particle / simulate_one_particle and lyapunov "
                             "separately), got method='twin'")
        if old.get("d0") is None:
            old.pop("d0", None)
        return Twin(**old)
    if method == "tangent":
        for name, (default, message) in _TWIN_ONLY.items():
            if name in old and old[name] != default:
                raise ValueError(message.format(old[name]))
        return Tangent(**{k: v for k, v in old.items() if k in ("variant", "return_run")})
    return as_method(method)
