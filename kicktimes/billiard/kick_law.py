"""The kicked disk's kick law as one value: `KickLaw`.

A kick law says *when* the disk is kicked (given times, a schedule that draws them, or the
kinetic rate of `kicktimes.schedules.KineticRate`) and *what* a kick does (a new direction,
a rotation, or a collision with a virtual partner disk; docs/architecture.md, "Perturbed
one-particle billiard"). `simulate_one_particle`, `kicktimes.diagnostics.lyapunov` and the
sweeps' kicked systems take it as ``kicks=``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import KW_ONLY, dataclass

import numpy as np

from kicktimes.billiard import checks as chk
from kicktimes.billiard.kernels.one import KICK_ANGLES
from kicktimes.billiard.scatter import PARTNER_LAWS

__all__ = ["KickLaw", "as_kick_law", "check_kick_times"]

#: the scattering kicks' fields, which need ``angle="scatter"``
SCATTER_FIELDS = ("rule", "e0", "partner", "partner_radius", "partner_mass")

_MEANING = {
    "uniform": "a kick replaces the direction by an angle uniform on [0, 2 pi)",
    "normal": "a kick replaces the direction by an angle from N(0, sigma^2)",
    "gaussian": "a kick rotates the direction by an angle from N(0, sigma^2)",
    "scatter": "a kick is a collision with a virtual partner disk (docs/scatter.md)",
}



def check_kick_times(kicks, t_max: float | None, name: str = "kicks") -> np.ndarray:
    """Sorted, finite, non-negative kick times, none beyond ``t_max`` (if known)."""
    if isinstance(kicks, str | bytes):
        raise TypeError(
            f"{name} must be None, a sequence of kick times or a schedule (e.g. "
            f"kicktimes.schedules.Poisson(rate)), got the string {kicks!r}"
        )
    try:
        times = np.array(kicks, dtype=np.float64, copy=True).ravel()
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"{name} must be None, a sequence of kick times or a schedule, got "
            f"{type(kicks).__name__} ({exc})"
        ) from None
    if not np.isfinite(times).all():
        raise ValueError(f"{name} must be finite; got NaN or inf")
    if times.size and times.min() < 0.0:
        raise ValueError(f"{name} must be >= 0, got {float(times.min())!r}")
    if times.size > 1 and (np.diff(times) < 0.0).any():
        raise ValueError(f"{name} must be sorted in increasing order")
    if t_max is not None and times.size and times[-1] > t_max:
        raise ValueError(
            f"{name} must lie in [0, t_max={float(t_max)!r}], got a kick at {float(times[-1])!r}"
        )
    return times


def _is_schedule(kicks) -> bool:
    """A kick schedule: a `Schedule`, or any object with a ``sample`` method that is not
    array-like (a pandas Series has a ``sample`` method too, but it holds times)."""
    from kicktimes.schedules import Schedule

    if isinstance(kicks, Schedule):
        return True
    if isinstance(kicks, np.ndarray) or hasattr(kicks, "__array__") or hasattr(kicks, "__len__"):
        return False
    return callable(getattr(kicks, "sample", None))


def check_kick_angles(kick_angles, times: np.ndarray, kick_angle: str,
                      name: str = "kick_angles") -> np.ndarray:
    """``kick_angles`` (named ``name`` in errors) checked against the times and the law."""
    if isinstance(kick_angles, str | bytes):
        raise TypeError(f"{name} must be a sequence of angles, got the string {kick_angles!r}")
    try:
        arr = np.array(kick_angles, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"{name} must be a sequence of angles, got {type(kick_angles).__name__} ({exc})"
        ) from None
    if kick_angle == "scatter":
        if arr.shape != (times.size, 2):
            raise ValueError(
                f"{name} of scattering kicks must have shape ({times.size}, 2) (two "
                f"uniforms on (-1, 1) per kick), got {arr.shape}"
            )
        if not np.isfinite(arr).all() or (np.abs(arr) > 1.0).any():
            raise ValueError(f"{name} of scattering kicks must lie in [-1, 1]")
        return arr
    angles = arr.ravel()
    if angles.shape != times.shape:
        raise ValueError(
            f"{name} must have one angle per kick ({times.size}), got {angles.size}"
        )
    if not np.isfinite(angles).all():
        raise ValueError(f"{name} must be finite; got NaN or inf")
    return angles


def _is_kinetic(kicks) -> bool:
    from kicktimes.schedules import KineticRate

    return isinstance(kicks, KineticRate)


def _frozen(arr: np.ndarray) -> np.ndarray:
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False, repr=False)
class KickLaw:
    """How and when the kicked disk is kicked.

    Parameters
    ----------
    times : array_like, schedule or KineticRate, optional
        When: kick times (sorted, ``>= 0``; a run checks them against its ``t_max``), a
        schedule with a ``sample(horizon, rng)`` method (`kicktimes.schedules`), sampled
        by the run with its ``rng``, or a `kicktimes.schedules.KineticRate` (kinetic kicks:
        the rate after each kick is the kinetic collision rate of the disk's state; the
        event loop draws the times). ``None``: no kicks (the integrable billiard).
    angle : {"uniform", "gaussian", "normal", "scatter"}
        What a kick does. ``"uniform"``: the direction is replaced by an angle uniform on
        [0, 2 pi) (the paper's choice). The paper's other choice, angles from N(0, 1), has
        two readings: ``"gaussian"``, the direction is rotated by ``N(0, sigma^2)``;
        ``"normal"``, it is replaced by an angle from ``N(0, sigma^2)``. ``"scatter"``: a
        collision with a virtual partner disk drawn from the two-disk collision
        statistics (docs/scatter.md).
    angles : array_like, optional
        Explicit angles, one per kick (new directions for ``"uniform"`` and ``"normal"``,
        rotations for ``"gaussian"``, shape ``(n, 2)`` uniforms on [-1, 1] for
        ``"scatter"``), e.g. ``run.kick_angles`` of another run (common random numbers).
        Drawn from the run's ``rng``, after the times, when omitted.
    sigma : float
        Standard deviation of the gaussian rotation or of the normal new angle (``> 0``).
    rule : {"mirror", "elastic"}
        Scattering kicks: the collision rule with the partner. The mirror partner has the
        disk's speed; the elastic partner has speed ``sqrt((2 e0 - m0 |v|^2) / m1)``.
    e0 : float, optional
        Scattering kicks, ``rule="elastic"``: the pair's kinetic energy
        ``(m0 |v|^2 + m1 |u|^2) / 2``, masses normalised to ``(m0 + m1) / 2 = 1`` (``>= 0``;
        default 1, the two-disk invariant measure's).
    partner : {"weighted", "uniform"}
        Scattering kicks: the partner's direction, weighted by ``|v - u|`` as at a real
        collision (default), or uniform.
    partner_radius : float, optional
        Scattering kicks: the partner's radius ``r1``, ``0 < r1 < 0.5`` (default the disk's
        own ``r``).
    partner_mass : float, optional
        Scattering kicks, ``rule="elastic"``: the partner's mass in units of the disk's,
        ``m1 / m0 > 0`` (default 1).

    Raises
    ------
    ValueError, TypeError
        A field out of range (naming it and its valid range), or a scattering field
        (``rule``, ``e0``, ``partner``, ``partner_radius``, ``partner_mass``) without
        ``angle="scatter"``.

    Notes
    -----
    The fields are the flat keywords ``kicks``, ``kick_angle``, ``kick_angles``,
    ``sigma``, ``rule``, ``e0``, ``partner``, ``partner_radius``, ``partner_mass`` that
    `simulate_one_particle` took before 0.2.0, under shorter names; a run records them as
    ``kick_times``, ``kick_angle``, ``kick_angles``, ... (`KickLaw.from_run`). The random
    numbers are drawn as before, whichever spelling: the schedule's times first, then the
    angles, from the run's ``rng``.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import simulate_one_particle, schedules
    >>> from kicktimes.billiard import KickLaw
    >>> law = KickLaw(schedules.Poisson(0.1), angle="gaussian", sigma=0.5)
    >>> law
    KickLaw(Poisson(rate=0.1), angle='gaussian', sigma=0.5)
    >>> run = simulate_one_particle(np.array([0.1, 0.2, 0.6, 0.8]), 0.02, t_max=100.0,
    ...                             kicks=law, rng=1)
    >>> KickLaw.from_run(run).angle
    'gaussian'
    >>> KickLaw(angle="uniform", partner_mass=3.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: rule, e0, partner, partner_radius and partner_mass describe scattering ...
    >>> print(KickLaw(schedules.Poisson(0.1), angle="scatter").summary())
    Kick law
      when   : at the times of Poisson(rate=0.1), drawn with the run's rng
      what   : a kick is a collision with a virtual partner disk (docs/scatter.md)
      angles : drawn from the run's rng after the times
      partner: rule='mirror', direction 'weighted', radius r (the disk's own), mass 1
    """

    times: object = None
    _: KW_ONLY
    angle: str = "uniform"
    angles: object = None
    sigma: float = 1.0
    rule: str = "mirror"
    e0: float | None = None
    partner: str = "weighted"
    partner_radius: float | None = None
    partner_mass: float | None = None

    def __post_init__(self):
        setattr_ = object.__setattr__
        times = self.times
        if times is not None and not (_is_kinetic(times) or _is_schedule(times)):
            times = _frozen(check_kick_times(times, None, name="times"))
            setattr_(self, "times", times)
        chk.check_choice("angle", self.angle, KICK_ANGLES)
        setattr_(self, "sigma", chk.check_real("sigma", self.sigma, low=0.0))
        chk.check_choice("rule", self.rule, chk.RULES)
        chk.check_choice("partner", self.partner, PARTNER_LAWS)
        scatter = self.angle == "scatter"
        if not scatter and (self.rule != "mirror" or self.e0 is not None
                            or self.partner != "weighted" or self.partner_radius is not None
                            or self.partner_mass is not None):
            raise ValueError(
                "rule, e0, partner, partner_radius and partner_mass describe scattering "
                f"kicks; they need angle='scatter', got angle={self.angle!r}")
        if self.partner_radius is not None:
            setattr_(self, "partner_radius", chk.check_real(
                "partner_radius", self.partner_radius, low=0.0, high=0.5))
        if self.partner_mass is not None:
            if self.rule != "elastic":
                raise ValueError("partner_mass applies to rule='elastic' (the mirror rule "
                                 "keeps the disk's speed whatever the masses), got "
                                 f"rule={self.rule!r}")
            setattr_(self, "partner_mass",
                     chk.check_real("partner_mass", self.partner_mass, low=0.0))
        if self.e0 is not None:
            if self.rule != "elastic":
                raise ValueError("e0 (the pair's kinetic energy) applies to rule='elastic' "
                                 "only")
            setattr_(self, "e0", chk.check_real("e0", self.e0, low=0.0))
        if self.angles is not None:
            if _is_kinetic(times):
                raise ValueError("angles: kinetic kicks draw their angles with their times; "
                                 "to replay a kinetic run pass KickLaw.from_run(run)")
            if isinstance(times, np.ndarray):
                angles = check_kick_angles(self.angles, times, self.angle, name="angles")
            else:  # checked against the times a run draws
                if isinstance(self.angles, str | bytes):
                    raise TypeError("angles must be a sequence of angles, got the string "
                                    f"{self.angles!r}")
                angles = np.array(self.angles, dtype=np.float64, copy=True, order="C")
            setattr_(self, "angles", _frozen(angles))

    @classmethod
    def from_run(cls, run, *, until=None) -> KickLaw:
        """The kick law that replays ``run``'s kicks: its times and angles (those up to
        ``until`` if given), its angle law and scattering partner."""
        times, angles = run.kick_times, run.kick_angles
        if until is not None:
            keep = times <= until
            times, angles = times[keep], angles[keep]
        scatter = {}
        if run.kick_angle == "scatter":
            scatter = {"rule": run.rule, "e0": run.e0, "partner": run.partner,
                       "partner_radius": run.partner_radius, "partner_mass": run.partner_mass}
        return cls(times, angle=run.kick_angle, angles=angles,
                   sigma=run.sigma if run.sigma is not None else 1.0, **scatter)

    def replace(self, **changes) -> KickLaw:
        """A copy with some fields changed (and checked again)."""
        return dataclasses.replace(self, **changes)

    def _changed(self):
        for f in dataclasses.fields(self):
            if f.name in ("times", "_"):
                continue
            value = getattr(self, f.name)
            if value is not f.default and not (
                    not isinstance(value, np.ndarray) and value == f.default):
                yield f.name, value

    def __eq__(self, other):
        if not isinstance(other, KickLaw):
            return NotImplemented
        for f in dataclasses.fields(self):
            a, b = getattr(self, f.name), getattr(other, f.name)
            if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
                if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)
                        and a.shape == b.shape and np.array_equal(a, b)):
                    return False
            elif a != b:
                return False
        return True

    __hash__ = None

    def _times_text(self) -> str:
        t = self.times
        if t is None:
            return "None"
        if isinstance(t, np.ndarray):
            if not t.size:
                return "<no kick times>"
            return f"<{t.size} kick times in [{t[0]:.6g}, {t[-1]:.6g}]>"
        return repr(t)

    def __repr__(self) -> str:
        parts = [] if self.times is None else [self._times_text()]
        for name, value in self._changed():
            if isinstance(value, np.ndarray):
                value = f"<{value.shape[0]} given>"
                parts.append(f"{name}={value}")
            else:
                parts.append(f"{name}={value!r}")
        return f"KickLaw({', '.join(parts)})"

    def summary(self) -> str:
        """A few lines saying when the disk is kicked and what a kick does."""
        t = self.times
        if t is None:
            when = "never (no kicks: the integrable billiard)"
        elif isinstance(t, np.ndarray):
            when = f"at {t.size} given times" + (f" in [{t[0]:.6g}, {t[-1]:.6g}]" if t.size
                                                 else "")
        elif _is_kinetic(t):
            when = f"at the kinetic collision rate of the disk's state ({t!r})"
        else:
            when = f"at the times of {t!r}, drawn with the run's rng"
        lines = ["Kick law", f"  when   : {when}", f"  what   : {_MEANING[self.angle]}"]
        if self.angle in ("gaussian", "normal"):
            lines.append(f"  sigma  : {self.sigma:g}")
        if self.angles is not None:
            lines.append(f"  angles : {self.angles.shape[0]} given (not drawn)")
        else:
            lines.append("  angles : drawn from the run's rng after the times")
        if self.angle == "scatter":
            radius = "r (the disk's own)" if self.partner_radius is None else self.partner_radius
            lines.append(f"  partner: rule={self.rule!r}, direction {self.partner!r}, radius "
                         f"{radius}"
                         f", mass {1.0 if self.partner_mass is None else self.partner_mass:g}"
                         + ("" if self.rule == "mirror" else
                            f", e0={1.0 if self.e0 is None else self.e0:g}"))
        return "\n".join(lines)


def as_kick_law(kicks, name: str = "kicks") -> KickLaw:
    """``kicks`` as a `KickLaw`: a kick law itself, or its times (an array, a schedule, a
    `KineticRate` or ``None``: the shorthand for ``KickLaw(kicks)``, uniform new angles)."""
    if isinstance(kicks, KickLaw):
        return kicks
    if kicks is not None and not (_is_kinetic(kicks) or _is_schedule(kicks)):
        kicks = check_kick_times(kicks, None, name=name)
    return KickLaw(kicks)
