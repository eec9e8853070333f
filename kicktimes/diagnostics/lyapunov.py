"""Finite-time Lyapunov exponents of the two-disk and the kicked one-disk billiards.

Two methods (docs/lyapunov.md has the derivations):

* ``method=Tangent()`` (default, ``"tangent"``): the linearised dynamics, exact. A tangent vector
  ``(dq, dv)`` starts along ``x`` of the tracked disk and is carried through free flights,
  wall reflections, disk-disk collisions and kicks by the exact linearised event maps
  (`kicktimes.billiard.kernels.tangent`). No ``d0``, no round-off floor, no deferrals.
* ``method=Twin(d0=...)`` (``"twin"``): Benettin's twin at distance ``d0``, renormalised at
  the sample times (`kicktimes.billiard.kernels.twins`); kept for fidelity to the paper, which
  used it; for small enough ``d0`` it converges to the tangent result.

Both measure the same quantity: the growth rate of the tracked disk's position
deviation, ``lambda = log(|dq_track(T)| / |dq_track(0)|) / T`` (``|dx|`` and ``|dy|``
separately for the paper's variant).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from kicktimes._old_keywords import old_keywords, pop_old, translator, warn_old
from kicktimes._results import Result
from kicktimes.billiard import checks as chk
from kicktimes.billiard.kernels.drive_one import simulate_tangent_one_kernel, tangent_one_kernel
from kicktimes.billiard.kernels.drive_two import simulate_tangent_two_kernel, tangent_two_kernel
from kicktimes.billiard.kernels.tangent import MAX_SAME_INSTANT
from kicktimes.billiard.kernels.twins import ftle_one_kernel, ftle_two_kernel
from kicktimes.billiard.kick_law import as_kick_law
from kicktimes.billiard.one_particle import (
    KICK_ANGLES,
    OLD_KICK_KEYWORDS,
    check_kinetic,
    check_kinetic_capacity,
    check_one_particle_state,
    check_scatter_options,
    check_table_kicks,
    draw_kick_angles,
    kernel_limits,
    law_from_old_keywords,
    one_particle_run,
    resolve_kicks,
    table_args,
)
from kicktimes.billiard.runs import OneParticleRun, TwoParticleRun
from kicktimes.billiard.tables import Circle, check_table
from kicktimes.billiard.two_particle import (
    DONE,
    check_two_particle_ic,
    kernel_args,
    raise_for_status,
    two_particle_run,
)
from kicktimes.diagnostics.autocorrelation import UndefinedDiagnosticWarning
from kicktimes.diagnostics.ftle_methods import (
    D0_DEFAULT,
    D0_RANGE,
    OLD_METHOD_KEYWORDS,
    TWIN_KICKS,
    VARIANTS,
    Twin,
    as_method,
    method_from_old,
)
from kicktimes.validation import check_rng

METHODS = ("tangent", "twin")
MAX_HORIZON = 1e8
# Event budget per unit time: a unit-speed disk on a whispering-gallery orbit with chords
# of 1e-5 (|sin theta| = 1 - 1e-10) makes 1e5 boundary collisions per unit time.
EVENTS_PER_TIME = 1e5


@dataclass(frozen=True)
class LyapunovResult(Result):
    """A finite-time Lyapunov exponent and how it was obtained.

    Attributes
    ----------
    lam : float
        The exponent (per unit time): the 2-norm exponent, or ``max(lam_x, lam_y)`` for
        the paper's variant; ``nan`` when it is undefined (or a part is), see ``reason``.
    lam_x, lam_y : float
        The paper variant's parts (``nan`` for ``variant="norm"``, or when undefined).
    n_renorm : int
        Renormalisations (twin: one per sample and twin; tangent: rescalings of a tangent
        vector whose norm left ``[1e-100, 1e100]``).
    n_forced : int
        Twin only: renormalisations forced after ``max_defer`` deferrals (0 for tangent).
    n_deferred : int
        Twin only: samples at which a renormalisation was deferred (0 for tangent).
    total_time : float
        The time ``T`` over which the growth is measured.
    d0 : float or None
        The twin's initial separation (``None`` for ``method="tangent"``).
    variant : str
    method : str
    n_perturbations : int
        Disk-disk collisions (two disks) or kicks applied (one disk) up to ``total_time``.
    lam_per_perturbation : float
        ``lam * total_time / n_perturbations``: the stretching per perturbation in nats
        (``nan`` without perturbations).
    reason : str or None
        Why ``lam`` is ``nan`` (None when it is defined): the horizon covers no time
        (paper steps all ended at collisions at ``t = 0``); the measured deviation is
        exactly 0 at the end (a degenerate collision, e.g. head-on, or one that stops the
        tracked disk, moved the whole perturbation to the other disk: a growth factor 0,
        ``log 0 = -inf``); the tangent vector is not finite (a contact exactly tangent to
        the wall, where the linearised dynamics is singular); or the twin was never
        renormalised. `lyapunov` issues it as an `UndefinedDiagnosticWarning`.
    renormalized : bool
        False for a twin that was never renormalised (``renormalize=False``: eq. (4) of
        Ranković & Porter read literally; ``lam`` is then that sum, not an exponent, and
        ``n_renorm``, ``n_forced`` and ``n_deferred`` are 0).
    """

    _title = "Finite-time Lyapunov exponent (lyapunov)"
    _summary_fields = ("lam", "lam_x", "lam_y", "method", "variant", "total_time",
                       "n_perturbations", "lam_per_perturbation", "n_renorm", "n_forced",
                       "n_deferred", "d0", "renormalized")

    lam: float
    lam_x: float
    lam_y: float
    n_renorm: int
    n_forced: int
    n_deferred: int
    total_time: float
    d0: float | None
    variant: str
    method: str = "tangent"
    n_perturbations: int = 0
    lam_per_perturbation: float = math.nan
    reason: str | None = None
    renormalized: bool = True


def _twin_offsets(variant: str, d0: float, ok) -> tuple[np.ndarray, np.ndarray]:
    """Offsets of the twins and what each measures (0: 2-norm, 1: |dx|, 2: |dy|).

    The norm twin is offset along +x (along -x if that leaves the table or overlaps the
    other disk); the paper's twins along +x and +y (or their negatives).
    """
    axes = [(1.0, 0.0)] if variant == "norm" else [(1.0, 0.0), (0.0, 1.0)]
    measure = [0] if variant == "norm" else [1, 2]
    offsets = []
    for ax, ay in axes:
        for sign in (1.0, -1.0):
            off = (sign * d0 * ax, sign * d0 * ay)
            if ok(*off):
                offsets.append(off)
                break
        else:
            raise ValueError(f"d0={d0!r}: no twin offset of that size keeps the disk valid")
    return np.array(offsets), np.array(measure, dtype=np.int64)


def check_kernel_status(status: int, horizon: float, max_events: int) -> None:
    """Turn a kernel's status code into an error naming the inputs."""
    if status == 1:
        raise RuntimeError(
            f"the event loop exceeded its budget of {max_events} events for the horizon "
            f"n_steps * tau = {horizon!r} (at most {EVENTS_PER_TIME:g} events per unit time): "
            "check system and r (a near-grazing orbit with vanishing chords?)"
        )
    if status == 2:
        raise RuntimeError(
            f"more than {MAX_SAME_INSTANT} consecutive events at the same instant: the "
            "trajectory is stuck; check system (initial condition) and r"
        )
    if status == 3:
        raise ValueError(
            "a non-finite event time arose: check system (initial condition), r, kicks and "
            "kick_angles (all must be finite)"
        )


def _combine(lams, variant):
    if variant == "norm":
        return float(lams[0]), math.nan, math.nan
    lam_x, lam_y = float(lams[0]), float(lams[1])
    lam = max(lam_x, lam_y) if not (math.isnan(lam_x) or math.isnan(lam_y)) else math.nan
    return lam, lam_x, lam_y


def _per_perturbation(lam, t, n):
    return lam * t / n if n > 0 else math.nan


def _warn_undefined(res: LyapunovResult, stacklevel: int = 3) -> None:
    """Issue ``res.reason`` (an undefined exponent) as an `UndefinedDiagnosticWarning`."""
    if res.reason is not None:
        warnings.warn(f"lyapunov: lam is NaN: {res.reason}", UndefinedDiagnosticWarning,
                      stacklevel=stacklevel)


_PARTS = {"norm": ("the position deviation",), "paper": ("|dx|", "|dy|")}


def _twin_result(out, variant, d0, horizon, max_events, renormalize=True,
                 tau=None) -> LyapunovResult:
    log_sum, n_renorm, n_forced, n_deferred, t_last, n_pert, status = out
    check_kernel_status(status, horizon, max_events)
    if not renormalize:
        # eq. (4) as printed: the sum over the n samples divided by n tau
        with np.errstate(invalid="ignore", divide="ignore"):
            lams = np.where((n_renorm > 0) & np.isfinite(log_sum),
                            log_sum / (n_renorm * tau), np.nan)
        lam, lam_x, lam_y = _combine(lams, variant)
        reasons = [f"the twin measuring {part} "
                   + ("was at distance exactly 0 from the reference at a sample (log 0)"
                      if n > 0 else "was measured at no sample (the horizon covers no time)")
                   for part, n, v in zip(_PARTS[variant], n_renorm, lams, strict=True)
                   if not np.isfinite(v)]
        j = int(np.argmax(t_last))
        t, n = float(t_last[j]), int(n_pert[j])
        return LyapunovResult(
            lam=lam, lam_x=lam_x, lam_y=lam_y, n_renorm=0, n_forced=0, n_deferred=0,
            total_time=t, d0=d0, variant=variant, method="twin", n_perturbations=n,
            lam_per_perturbation=_per_perturbation(lam, t, n), reason="; ".join(reasons) or None,
            renormalized=False,
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        lams = np.where(t_last > 0, log_sum / t_last, np.nan)
    lam, lam_x, lam_y = _combine(lams, variant)
    reasons = [
        f"the twin was never renormalised (it measures {part}): at every sample it had met "
        "other collisions than the reference (renormalisation deferred) or its separation "
        "was 0, so no growth was measured"
        for part, t in zip(_PARTS[variant], t_last, strict=True) if not t > 0
    ]
    j = int(np.argmax(t_last))
    t, n = float(t_last[j]), int(n_pert[j])
    return LyapunovResult(
        lam=lam, lam_x=lam_x, lam_y=lam_y, n_renorm=int(n_renorm.sum()),
        n_forced=int(n_forced.sum()), n_deferred=int(n_deferred.sum()), total_time=t, d0=d0,
        variant=variant, method="twin", n_perturbations=n,
        lam_per_perturbation=_per_perturbation(lam, t, n), reason="; ".join(reasons) or None,
    )


def _tangent_result(out, U, cols, variant, horizon, max_events, who) -> LyapunovResult:
    """``cols``: the (x, y) columns of the tracked disk's position deviation in ``U``;
    ``who`` names that disk in the reason of an undefined exponent."""
    log_scale, n_resc, n_pert, t_end, status = out
    check_kernel_status(status, horizon, max_events)
    ix, iy = cols
    if variant == "norm":
        meas = [math.hypot(U[0, ix], U[0, iy])]
    else:
        meas = [abs(U[0, ix]), abs(U[1, iy])]
    lams = []
    nonfinite, vanished = [], []
    for j, d in enumerate(meas):
        if t_end > 0.0 and math.isfinite(d) and d > 0.0:
            lams.append((log_scale[j] + math.log(d)) / t_end)
        else:
            lams.append(math.nan)
            (vanished if d == 0.0 else nonfinite).append(_PARTS[variant][j])
    reasons = []
    if not t_end > 0.0:
        # only a paper step cut short by a collision at t = 0 has zero length
        reasons.append("the horizon covers no time (total_time = 0): every paper step ended "
                       "at a collision at t = 0")
    elif nonfinite:
        # the only source of NaN: wall_tangent at a contact with v.n = 0
        reasons.append(
            f"the tangent vector is not finite ({' and '.join(nonfinite)} of {who}): a contact "
            "exactly tangent to the wall (v.n = 0, e.g. a disk starting on the wall with a "
            "tangential velocity) makes the linearised dynamics singular")
    if t_end > 0.0 and vanished:
        how = ("a degenerate collision (head-on, or one that leaves the disk at rest) moved "
               "the whole perturbation to the other disk" if who.startswith("disk")
               else "an event of the trajectory annihilated the perturbation")
        reasons.append(
            f"{' and '.join(vanished)} of {who} {'is' if len(vanished) == 1 else 'are'} "
            f"exactly 0 at T = {float(t_end):.6g} (a growth factor 0, log 0 = -inf): {how}")
    lam, lam_x, lam_y = _combine(lams, variant)
    n = int(n_pert)
    return LyapunovResult(
        lam=lam, lam_x=lam_x, lam_y=lam_y, n_renorm=int(n_resc), n_forced=0, n_deferred=0,
        total_time=float(t_end), d0=None, variant=variant, method="tangent", n_perturbations=n,
        lam_per_perturbation=_per_perturbation(lam, float(t_end), n),
        reason="; ".join(reasons) or None,
    )


def _start_vectors(variant: str, size: int, offset: int) -> np.ndarray:
    """Unit tangent vectors along x (and y for the paper variant) of the tracked disk."""
    m = 1 if variant == "norm" else 2
    U = np.zeros((m, size))
    U[0, offset] = 1.0
    if m == 2:
        U[1, offset + 1] = 1.0
    return U


def _one_disk(system) -> bool:
    return isinstance(system, OneParticleRun) or (
        not isinstance(system, TwoParticleRun) and np.shape(system) == (4,))


@translator(*OLD_METHOD_KEYWORDS, *OLD_KICK_KEYWORDS)
def _old_lyapunov(args, kwargs):
    kwargs = dict(kwargs)
    system = args[0] if args else kwargs.get("system")
    old = pop_old(kwargs, OLD_METHOD_KEYWORDS)
    if old:
        method = kwargs.get("method", "tangent")
        kind = "Twin" if method == "twin" or "d0" in old else "Tangent"
        fields = ", ".join(f"{k}=..." for k in old)
        warn_old(", ".join(f"lyapunov({k}=...)" for k in old),
                 f"lyapunov(..., method={kind}({fields})) (kicktimes.diagnostics.{kind})")
        kwargs["method"] = method_from_old(method, old)
    names = [k for k in OLD_KICK_KEYWORDS if k != "rule" or _one_disk(system)]
    old = pop_old(kwargs, names)
    if old:
        law_from_old_keywords(kwargs, old, "lyapunov")
    return kwargs, None


def _flat(system, rule, kicks, method) -> dict:
    """The keywords of `_lyapunov` for the kick law ``kicks`` and the method object."""
    method = as_method(method)
    flat = {"method": method.name, "variant": method.variant, "rule": rule,
            "return_run": getattr(method, "return_run", False)}
    if isinstance(method, Twin):
        flat.update(d0=method.d0, max_defer=method.max_defer, renormalize=method.renormalize,
                    twin_kicks=method.twin_kicks)
    if kicks is None:
        return flat
    law = as_kick_law(kicks)
    if _one_disk(system):
        if rule != "mirror":
            raise ValueError(f"rule={rule!r}: a kicked disk's scattering rule is its kick "
                             "law's, kicks=KickLaw(..., angle='scatter', rule=...)")
        flat["rule"] = law.rule
    flat.update(kicks=law.times, kick_angles=law.angles, kick_angle=law.angle,
                sigma=law.sigma, e0=law.e0, partner=law.partner,
                partner_radius=law.partner_radius, partner_mass=law.partner_mass)
    return flat


@old_keywords(_old_lyapunov)
def lyapunov(system, r=None, *, n_steps=None, tau=None, sampling="uniform", rule="mirror",
             track=0, kicks=None, rng=None, method="tangent", holes=None, masses=None,
             table=None):
    """Finite-time Lyapunov exponent of a two-disk or a kicked one-disk billiard.

    Parameters
    ----------
    system : array_like or run
        A two-disk initial condition (shape (2, 4)), a one-disk state (shape (4,)), or a
        `TwoParticleRun` / `OneParticleRun`, whose setup (and kicks) is reused.
    r : float
        Disk radius (taken from the run if ``system`` is one).
    n_steps, tau, sampling
        The horizon, as in the simulators: ``uniform``, ``T = n_steps tau``; ``paper``,
        ``n_steps`` collision-truncated steps. The twin method renormalises at these
        sample times. ``n_steps * tau`` must be at most 1e8.
    rule, track
        Two-disk collision rule and the disk whose position deviation is measured. (A
        kicked disk's scattering rule is its kick law's, ``KickLaw(rule=...)``.)
    kicks : KickLaw, array_like or schedule, optional
        One-disk kicks, as in `simulate_one_particle` (`kicktimes.billiard.KickLaw`; times
        or a schedule alone: uniform new directions). Kick times and angles are given
        data, the same for every perturbed trajectory (common random numbers): a kick is
        linearised at fixed time and angle. A scattering kick (``angle="scatter"``) is a
        collision with a virtual partner placed in contact with the reference (at the
        distance ``r + partner_radius``): the tangent vector goes through the linearised
        collision with a partner of zero deviation; a twin meets the same partner at its
        own contact time, or misses it (docs/scatter.md).
    rng : None, int, SeedSequence or numpy.random.Generator, optional
        Source of a schedule's kick times and the kick angles (as in
        `simulate_one_particle`), then of independent twins' own angles.
    method : Tangent, Twin, "tangent" or "twin"
        `Tangent` (default, ``"tangent"``): exact propagation of tangent vectors; its
        options ``variant`` (``"norm"``: the 2-norm of the tracked disk's position
        deviation; ``"paper"``: ``|dx|`` and ``|dy|`` separately, ``lam = max(lam_x,
        lam_y)``) and ``return_run`` (also return the run, from the same single pass).
        `Twin` (``"twin"``): Benettin's twin at distance ``d0`` (the paper's method;
        converges to the tangent value as ``d0 -> 0`` until round-off takes over), with
        ``d0``, ``variant``, ``renormalize`` (``False``: eq. (4) of Ranković & Porter read
        literally), ``twin_kicks`` and ``max_defer``. A name stands for the method with
        its default options (`kicktimes.diagnostics.ftle_methods`).
    masses : (float, float), optional
        Two disks, elastic rule: their masses (as in `simulate_two_particle`).
    holes : array_like, shape (n, 2), optional
        Holes in the table's wall (as in `simulate_two_particle`): the exponent is
        measured up to the escape (``total_time`` the escape time), tangent method only.
    table : Circle, Stadium or Ellipse, optional
        The table (as in `simulate_two_particle` and `simulate_one_particle`; ``None``: the
        unit circle; taken from a run, and a ValueError if it contradicts the run's). In a
        stadium or an ellipse the tangent vector crosses a wall contact by
        `kicktimes.billiard.kernels.tangent.curved_wall_tangent` with the contact's normal
        and the local curvature of the centre's curve (0 on the stadium's segments); the
        disk-disk and kick maps do not depend on the table; the twins run through the same
        table kernels.

    Returns
    -------
    LyapunovResult, or ``(LyapunovResult, run)`` with ``Tangent(return_run=True)``

    Warns
    -----
    UndefinedDiagnosticWarning
        ``lam`` is undefined (NaN) for this input, with the reason (also in
        ``result.reason``): the horizon covers no time (every paper step ended at a
        collision at ``t = 0``); the measured deviation is exactly 0 at the end (a
        degenerate collision, e.g. head-on or one that stops the tracked disk, moved the
        whole perturbation to the other disk; it was reported as ``-inf``); a contact
        exactly tangent to the wall (the linearised dynamics is singular there; it raised
        ZeroDivisionError); or a twin that was never renormalised.

    Notes
    -----
    ``lambda = log(|dq(T)| / |dq(0)|) / T`` for the tracked disk's position deviation
    ``dq``. The tangent method carries ``(dq, dv)`` exactly: free flight ``dq += dv t``;
    wall reflection ``dq' = dq + (v - v') dtau``, ``dv' = R dv - (2/rho)[(v.u) n + (v.n) u]``
    with ``dtau = -(n.dq)/(n.v)``, ``u = dq + v dtau``; the disk-disk maps of each rule;
    a "uniform" or "normal" kick (a new direction) keeps only the speed deviation, a
    "gaussian" kick rotates ``dv``
    (derivations in docs/lyapunov.md). The vectors are rescaled only when their norm
    leaves ``[1e-100, 1e100]`` (the dynamics is linear, so the result does not depend on
    when), which keeps the cost near that of the bare simulation.

    The kicked exponent is about 1/3 of the two-disk exponent at the same collision rate:
    a kick is blind to the state, while a disk-disk collision defocuses (its stretching
    per collision, ``lam_per_perturbation``, is larger by about ``ln(1/r)``).

    The reference trajectory is bitwise the one `simulate_two_particle` /
    `simulate_one_particle` compute with the same arguments; with ``return_run=True`` one
    event loop (`kicktimes.billiard.kernels.drive_two`, `.drive_one`) produces both, each
    bitwise what its own call gives (the result, that of ``lyapunov`` without ``return_run``).

    Examples
    --------
    >>> from kicktimes import initial_conditions
    >>> from kicktimes.diagnostics import lyapunov
    >>> ic = initial_conditions(1, 0.03, rng=3)[0]
    >>> res = lyapunov(ic, 0.03, n_steps=2000, tau=0.2)
    >>> bool(res.lam > 0), res.method
    (True, 'tangent')
    >>> from kicktimes.diagnostics import Twin
    >>> twin = lyapunov(ic, 0.03, n_steps=2000, tau=0.2, method=Twin(d0=1e-8))
    >>> bool(abs(twin.lam - res.lam) < 0.02 * res.lam)
    True

    One pass for the exponent and the run (its samples, boundary log, collision times):

    >>> from kicktimes import simulate_two_particle
    >>> from kicktimes.diagnostics import Tangent
    >>> res2, run = lyapunov(ic, 0.03, n_steps=2000, tau=0.2,
    ...                      method=Tangent(return_run=True))
    >>> res2 == res
    True
    >>> same = simulate_two_particle(ic, 0.03, n_steps=2000, tau=0.2)
    >>> bool((run.pp_times == same.pp_times).all() and (run.samples == same.samples).all())
    True
    """
    flat = _flat(system, rule, kicks, method)
    res, run, _ = _lyapunov(system, r, n_steps=n_steps, tau=tau, sampling=sampling,
                            track=track, rng=rng, t_continue=0.0, holes=holes, masses=masses,
                            table=table, **flat)
    _warn_undefined(res, stacklevel=4)
    return (res, run) if flat["return_run"] else res


def lyapunov_pass(system, r=None, *, t_continue=0.0, uniform=False, rule="mirror", kicks=None,
                  method="tangent", **options):
    """`lyapunov` with ``Tangent(return_run=True)``, and the two-disk run continued: for
    the sweep (``method`` a `Tangent` or ``"tangent"``; its ``return_run`` is implied).

    Returns ``(result, run, pp_times)``. With two disks, ``sampling="paper"`` and a run
    that ends before ``t_continue``, the event loop goes on (no samples, no tangent work)
    to ``t_continue`` and ``pp_times`` holds the disk-disk times up to it, bitwise those
    of ``simulate_two_particle(ic, r, t_max=t_continue, rule=rule).pp_times``; otherwise
    ``pp_times`` is ``run.pp_times`` (``None`` for one disk). Warns as `lyapunov` when
    the exponent is undefined.

    ``uniform=True`` adds a fourth item: with ``sampling="paper"`` and no holes, the
    tracked disk's centre at ``k tau``, ``k = 0 .. floor(run.t_max / tau)``, recorded by
    the same event loop, bitwise the samples of the same trajectory re-simulated with
    uniform sampling to ``t_max = run.t_max`` (for a kicked disk, with the kicks it
    applied); otherwise ``None``.
    """
    t_continue = chk.check_real("t_continue", t_continue, low=0.0, low_open=False)
    if not isinstance(uniform, bool | np.bool_):
        raise TypeError(f"uniform must be a bool, got {type(uniform).__name__}")
    sink = [] if uniform else None
    flat = _flat(system, rule, kicks, method)
    if flat["method"] != "tangent":
        raise ValueError(f"method: lyapunov_pass is the tangent method's one pass, got {method!r}")
    flat["return_run"] = True
    out = _lyapunov(system, r, t_continue=t_continue, uniform_out=sink, **options, **flat)
    _warn_undefined(out[0])
    if not uniform:
        return out
    return (*out, sink[0] if sink else None)


def _lyapunov(system, r=None, *, n_steps=None, tau=None, sampling="uniform", rule="mirror",
              track=0, kicks=None, kick_angles=None, kick_angle="uniform", sigma=1.0, rng=None,
              method="tangent", variant="norm", d0=None, max_defer=10, e0=None,
              partner="weighted", partner_radius=None, partner_mass=None, return_run=False,
              t_continue=0.0, holes=None, masses=None, table=None, uniform_out=None,
              renormalize=True, twin_kicks="shared"):
    """`lyapunov`'s body: ``(result, run or None, pp_times or None)``; a list
    ``uniform_out`` receives the one pass's uniform samples (see `lyapunov_pass`)."""
    given_table = table is not None
    table = check_table(table)
    if not isinstance(renormalize, bool | np.bool_):
        raise TypeError(f"renormalize must be a bool, got {type(renormalize).__name__}")
    renormalize = bool(renormalize)
    chk.check_choice("twin_kicks", twin_kicks, TWIN_KICKS)
    if twin_kicks == "independent" and method != "twin":
        raise ValueError("twin_kicks='independent' applies to method='twin' only (a tangent "
                         f"vector has no kicks of its own), got method={method!r}")
    if not renormalize and method != "twin":
        raise ValueError("renormalize=False (eq. (4) read literally) applies to method='twin' "
                         f"only, got method={method!r}")
    arcs = chk.check_holes(holes)
    if arcs is not None:
        if method != "tangent":
            raise ValueError(f"holes: the FTLE up to an escape needs method='tangent', got "
                             f"method={method!r}")
        if t_continue:
            raise ValueError("holes: a run with holes ends at its escape; it cannot be "
                             "continued (t_continue)")
    if isinstance(system, TwoParticleRun | OneParticleRun):
        run = system
        if run.sampling is None:
            raise ValueError("system: the run has no sampling (n_steps, tau); the FTLE needs it")
        r, n_steps, tau, sampling = run.r, run.n_steps, run.tau, run.sampling
        if given_table and table != run.table:
            raise ValueError(f"table: the run was simulated in {run.table!r}, got "
                             f"table={table!r}")
        table = run.table
        if isinstance(run, TwoParticleRun):
            rule, track, system = run.rule, run.track, run.ic
        else:
            # the FTLE covers n_steps samples; a run may have gone on beyond them
            horizon = n_steps * tau
            keep = run.kick_times <= horizon
            kicks, kick_angles = run.kick_times[keep], run.kick_angles[keep]
            kick_angle = run.kick_angle
            sigma = run.sigma if run.sigma is not None else 1.0
            if kick_angle == "scatter":
                rule, e0, partner = run.rule, run.e0, run.partner
                partner_radius, partner_mass = run.partner_radius, run.partner_mass
            system = run.ic
    chk.check_choice("method", method, METHODS)
    chk.check_choice("variant", variant, VARIANTS)
    if return_run and method != "tangent":
        raise ValueError("return_run=True needs method='tangent' (the one-pass kernels carry "
                         "tangent vectors; for the twin method call simulate_two_particle / "
                         f"simulate_one_particle and lyapunov separately), got method={method!r}")
    if method == "twin":
        d0 = D0_DEFAULT if d0 is None else chk.check_real(
            "d0", d0, low=D0_RANGE[0], high=D0_RANGE[1], low_open=False, high_open=False)
        max_defer = chk.check_int("max_defer", max_defer, low=0)
    elif d0 is not None:
        raise ValueError(f"d0 applies to method='twin' only (the tangent method has no "
                         f"separation scale); got d0={d0!r} with method='tangent'")
    if n_steps is None or tau is None:
        raise ValueError("n_steps (>= 1) and tau (> 0) are required: the FTLE samples the flow")
    _, n_steps, tau, mode = chk.check_sampling(None, n_steps, tau, sampling)
    horizon = n_steps * tau
    if not horizon <= MAX_HORIZON:
        raise ValueError(f"the horizon n_steps * tau must be at most {MAX_HORIZON:g}, got "
                         f"{n_steps} * {tau!r} = {horizon!r}")
    max_events = int(EVENTS_PER_TIME * horizon) + 10**6
    arr = np.asarray(system, dtype=np.float64)
    if arr.shape == (2, 4):
        r0, r1, r = chk.check_radii(r)
        if table == Circle():
            table = None  # the circle's own kernels, bit for bit
        else:
            if isinstance(r, tuple):
                raise ValueError(f"r: two disks in {table!r} must be equal (one radius), got "
                                 f"{r!r}")
            r = table.check_radius(r)
            if arcs is not None:
                raise ValueError(f"holes: holes are arcs of the unit circle's wall; {table!r} "
                                 "has none")
        wall = None if table is None else table.kernel(r)
        chk.check_choice("rule", rule, chk.RULES)
        track = chk.check_int("track", track, low=0)
        if track > 1:
            raise ValueError(f"track must be 0 or 1, got {track}")
        if kicks is not None:
            raise ValueError("kicks apply to a one-disk state (shape (4,)), not to two disks")
        if twin_kicks != "shared":
            raise ValueError("twin_kicks='independent' applies to a kicked one-disk state "
                             "(shape (4,)), not to two disks")
        ic = check_two_particle_ic(arr, r, rule, name="system", table=table)
        masses = chk.check_masses(masses, rule)
        # the kernels' table and state, as the simulator sets them up
        args = kernel_args(ic, r, rule, 1, 1.0, 1, 1.0, 0, None, masses, table=table)
        rho, sig, st = args[1], args[2], args[0]
        if return_run or arcs is not None:
            res, run, pp = _pass_two(ic, r, rule, sampling, mode, n_steps, tau, track, variant,
                                     max_events, t_continue, arcs, masses, uniform_out, table)
            return (res, run, pp) if return_run else (res, None, None)
        if method == "tangent":
            U = _start_vectors(variant, 8, 4 * track)
            if wall is None:
                out = tangent_two_kernel(st, rho, sig, chk.RULES[rule], mode, n_steps, tau, U,
                                         max_events, 0)
            else:
                out = tangent_two_kernel(st, rho, sig, chk.RULES[rule], mode, n_steps, tau, U,
                                         max_events, 0, wall)
            return _tangent_result(out, U, (4 * track, 4 * track + 1), variant, horizon,
                                   max_events, f"disk {track}"), None, None
        o = track

        def ok(dx, dy):
            x, y = ic[o, 0] + dx, ic[o, 1] + dy
            other = ic[1 - o]
            inside = (math.hypot(x, y) <= rho[o] if table is None
                      else bool(table.contains(np.array([x, y]), r)))
            return inside and math.hypot(x - other[0], y - other[1]) >= sig

        offsets, measure = _twin_offsets(variant, d0, ok)
        if wall is None:
            out = ftle_two_kernel(st, rho, sig, chk.RULES[rule], mode, n_steps, tau, track,
                                  offsets, measure, d0, max_defer, max_events, renormalize)
        else:
            out = ftle_two_kernel(st, rho, sig, chk.RULES[rule], mode, n_steps, tau, track,
                                  offsets, measure, d0, max_defer, max_events, renormalize,
                                  wall)
        return _twin_result(out, variant, d0, horizon, max_events, renormalize, tau), None, None
    if arr.shape != (4,):
        raise ValueError(f"system must have shape (2, 4) or (4,), got {arr.shape}")
    r = (chk.check_real("r", r, low=0.0, high=1.0) if table == Circle()
         else table.check_radius(r))
    check_table_kicks(table, kicks, holes)
    chk.check_choice("kick_angle", kick_angle, KICK_ANGLES)
    sigma = chk.check_real("sigma", sigma, low=0.0)
    state = check_one_particle_state(arr, r, name="system", table=table)
    sp, options = check_scatter_options(state, r, kick_angle, rule, e0, partner,
                                        partner_radius, partner_mass)
    rule = options["rule"]
    tab = table_args(table, r, kick_angle, partner_radius)
    if twin_kicks == "independent":
        if kick_angle == "scatter":
            raise ValueError("twin_kicks='independent' needs kicks that set or rotate the "
                             "direction (kick_angle 'uniform', 'normal' or 'gaussian'), got "
                             "kick_angle='scatter'")
        # one generator for the run's kicks and then the twins' angles
        rng = check_rng(rng)
    times, angles, _, kinetic = resolve_kicks(kicks, kick_angles, kick_angle=kick_angle,
                                              sigma=sigma, rng=rng, horizon=horizon,
                                              t_max=horizon if mode == 1 else None, r=r)
    check_kinetic(kinetic, state, kick_angle, rule, sp)
    rho = 1.0 - r
    st = np.zeros(7)
    st[1:5] = state
    st[6] = state[2] ** 2 + state[3] ** 2
    # scattering kicks take (n, 2) numbers; the other kinds one angle per kick
    if kick_angle == "scatter":
        kick_u, angles = angles, np.zeros(times.size)
    else:
        kick_u = np.zeros((0, 2))
    if method == "tangent":
        U = _start_vectors(variant, 4, 0)
        if return_run or arcs is not None:
            res, run, _ = _pass_one(st, state, r, times, angles, kick_u, sp, mode, n_steps, tau,
                                    U, variant, max_events, sampling=sampling,
                                    kick_angle=kick_angle, sigma=sigma, options=options,
                                    kinetic=kinetic, holes=arcs, uniform_out=uniform_out,
                                    table=table, tab=tab)
            return res, (run if return_run else None), None
        out = tangent_one_kernel(st, rho, times, angles, KICK_ANGLES[kick_angle], mode, n_steps,
                                 tau, U, max_events, kick_u, sp, kinetic, tab)
        check_kinetic_capacity(kinetic, out[2])
        return _tangent_result(out, U, (0, 1), variant, horizon, max_events, "the disk"), None, None
    if tab is None:
        offsets, measure = _twin_offsets(
            variant, d0, lambda dx, dy: math.hypot(state[0] + dx, state[1] + dy) <= rho
        )
    else:
        offsets, measure = _twin_offsets(
            variant, d0, lambda dx, dy: bool(table.contains([state[0] + dx, state[1] + dy], r))
        )
    twin_angles = np.empty((0, times.size))
    if twin_kicks == "independent":
        if kinetic is not None:
            raise ValueError("twin_kicks='independent' needs given kick times: with "
                             "kinetic-rate kicks the times depend on the trajectory")
        twin_angles = np.empty((offsets.shape[0], times.size))
        for j in range(offsets.shape[0]):
            twin_angles[j] = draw_kick_angles(times.size, kick_angle, sigma, rng)
    out = ftle_one_kernel(st, rho, times, angles, KICK_ANGLES[kick_angle], mode, n_steps, tau,
                          offsets, measure, d0, max_defer, max_events, kick_u, sp, kinetic,
                          renormalize, twin_angles, tab)
    check_kinetic_capacity(kinetic, int(np.searchsorted(times, np.inf)))
    return _twin_result(out, variant, d0, horizon, max_events, renormalize, tau), None, None


def _pass_two(ic, r, rule, sampling, mode, n_steps, tau, track, variant, max_ev_tan,
              t_continue, holes=None, masses=None, uniform_out=None, table=None):
    """The two-disk run and its tangent FTLE from one pass (`simulate_tangent_two_kernel`);
    its uniform samples appended to the list ``uniform_out`` (see `_uniform_samples`);
    ``table`` another table than the circle (or ``None``)."""
    args = kernel_args(ic, r, rule, mode, n_steps * tau if mode == 1 else None, n_steps, tau,
                       track, None, masses, table=table)
    U = _start_vectors(variant, 8, 4 * track)
    if table is None:
        out = simulate_tangent_two_kernel(*args, U, max_ev_tan,
                                          t_continue if mode == 2 else 0.0, holes,
                                          uniform_out is not None and mode == 2)
    else:
        out = simulate_tangent_two_kernel(*args, U, max_ev_tan,
                                          t_continue if mode == 2 else 0.0, None,
                                          uniform_out is not None and mode == 2,
                                          table.kernel(r))
    (pp, n_pp_run, bt, bp, bx, by, bs, stimes, samples, t_end, status, log_scale, n_resc,
     n_pert, t_tan, status_tan, status_cont, escape, u_times, u_samples) = out
    # errors in the order of separate calls: the simulation's, the FTLE's, the continuation's
    out = (pp[:n_pp_run], bt, bp, bx, by, bs, stimes, samples, t_end, np.empty((0, 12)), status,
           escape)
    run = two_particle_run(out, args, r=r, rule=rule, sampling=sampling, tau=tau,
                           n_steps=n_steps, ic=ic, track=track, seed=None, name="system",
                           table=table)
    horizon = n_steps * tau
    res = _tangent_result((log_scale, n_resc, n_pert, t_tan, status_tan), U,
                          (4 * track, 4 * track + 1), variant, horizon, max_ev_tan,
                          f"disk {track}")
    if status_cont != DONE:
        raise_for_status(status_cont, t_continue, pp.shape[0], max_events=args[11],
                         name="system", where=f"continuing the run to t = {t_continue!r}")
    _uniform_samples(uniform_out, run, tau, holes, u_samples)
    return res, run, pp


def _uniform_samples(sink, run, tau, holes, samples):
    """Append to ``sink`` (a list, or ``None``: nothing) the uniform samples of a paper run
    recorded by its one pass, or ``None`` where the pass has none (uniform sampling,
    holes). A run shorter than one step has the start as its only uniform sample."""
    if sink is None:
        return
    if run.sampling != "paper" or holes is not None:
        sink.append(None)
    elif not run.t_max >= tau:
        sink.append(run.samples[:1])
    else:
        sink.append(samples)


def _pass_one(st, state, r, times, angles, kick_u, sp, mode, n_steps, tau, U, variant,
              max_ev_tan, *, sampling, kick_angle, sigma, options, kinetic=None,
              holes=None, uniform_out=None, table=None, tab=None):
    """The kicked run and its tangent FTLE from one pass (`simulate_tangent_one_kernel`;
    ``table`` the run's table, ``tab`` its kernels' tuple, `table_args`).

    The simulation is set up and recorded by `simulate_one_particle`'s own helpers
    (`kernel_limits`, `one_particle_run`), so the run is the very one it returns.
    """
    scatter = kick_angle == "scatter"
    horizon = n_steps * tau
    rho, max_events, b_cap, stall_dt = kernel_limits(st, r, sp, scatter, horizon, mode,
                                                     table=table)
    out = simulate_tangent_one_kernel(
        st, rho, times, angles, KICK_ANGLES[kick_angle], horizon if mode == 1 else 0.0, mode,
        n_steps, tau, b_cap, kick_u, sp, max_events, stall_dt, U, max_ev_tan, kinetic, holes,
        uniform_out is not None and mode == 2, tab)
    raise_for_status(out[9], st[0], out[0].shape[0], max_events=max_events, name="system",
                     where=f"disk at ({st[1]:.6g}, {st[2]:.6g}), r={r!r}")
    check_kinetic_capacity(kinetic, out[6])
    run = one_particle_run(st, r, state, out[:9], sampling=sampling, mode=mode, tau=tau,
                           n_steps=n_steps, seed=None, kick_angle=kick_angle, sigma=sigma,
                           times=times, applied=kick_u if scatter else angles,
                           escape_time=float(out[15][0]), table=table, **options)
    res = _tangent_result(out[10:15], U, (0, 1), variant, horizon, max_ev_tan, "the disk")
    _uniform_samples(uniform_out, run, tau, holes, out[17])
    return res, run, None
