"""The randomly perturbed ("kicked") one-disk billiard: the simulator's Python layer.

One disk of radius ``r`` moves in the unit circular table, or in a stadium or an ellipse
(``table=``, `kicktimes.tables`; docs/tables.md, "The kicked disk in a table"); at each
kick time its velocity direction is changed (docs/architecture.md, "Perturbed one-particle
billiard"). Kicks are events of the event loop, applied at their exact times
(`kicktimes.billiard.kernels.one` is the event step, `.drive_one` the loop).

Ties: a kick at the same instant as a boundary collision is applied *after* the
reflection. If the new direction points out of the table, the disk is reflected again
at once (a second boundary collision at the same time, logged as such). This makes the
outcome a deterministic function of the kick times and angles.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from kicktimes._old_keywords import old_keywords, pop_old, translator, warn_old
from kicktimes.billiard import checks as chk
from kicktimes.billiard.kernels.drive_one import simulate_one_kernel
from kicktimes.billiard.kernels.one import KICK_ANGLES
from kicktimes.billiard.kick_law import (
    KickLaw,
    _is_schedule,
    as_kick_law,
    check_kick_angles,
    check_kick_times,
)
from kicktimes.billiard.runs import BoundaryLog, OneParticleRun, sampling_fields
from kicktimes.billiard.scatter import PARTNER_LAWS, draw_scatter_uniforms
from kicktimes.billiard.tables import Circle, Ellipse, Stadium, check_table
from kicktimes.billiard.two_particle import raise_for_status
from kicktimes.validation import check_rng

#: The largest radius of a single disk: the table left to its centre, 1 - r, stays >= 1e-6,
#: far above the contact tolerance (1e-12).
R_MAX_ONE = 1.0 - 1e-6



def _is_kicktimes_schedule(kicks) -> bool:
    from kicktimes.schedules import Schedule

    return isinstance(kicks, Schedule)

def check_one_particle_state(state, r: float, name: str = "state", *,
                             table=None) -> np.ndarray:
    """Validate a one-disk state ``(x, y, vx, vy)`` for radius ``r``; a float64 copy.

    ``table`` (`check_table`; ``None``: the unit circle): the centre must keep the disk
    inside it (``table.contains``), anywhere in a stadium or an ellipse.
    """
    table = check_table(table)
    if table == Circle() and r > R_MAX_ONE:
        raise ValueError(f"r must lie in (0.0, {R_MAX_ONE!r}] for one disk, got {float(r)!r}")
    arr = chk.check_state(name, state, (4,))
    if table == Circle():
        chk.check_inside(name, arr[0], arr[1], 1.0 - r, r, "the disk's")
    elif not table.contains(arr[:2], r):
        raise ValueError(f"{name}: the centre ({arr[0]!r}, {arr[1]!r}) keeps no disk of radius "
                         f"{r!r} inside {table!r}")
    if math.hypot(arr[2], arr[3]) == 0.0:
        raise ValueError(f"{name}: the velocity (vx, vy) must be non-zero, got (0, 0)")
    chk.check_speed(name, arr[2], arr[3], "the disk's", allow_zero=False)
    return arr


def table_args(table, r, kick_angle="uniform", partner_radius=None):
    """The kernels' table tuple ``(kind, p0, p1, p2, q0, q1, q2)`` of a kicked run in
    ``table`` (`kicktimes.billiard.kernels.one`), or ``None`` for the circle (its own code,
    bitwise the circle's runs).

    ``(kind, p0, p1, p2)`` is the centre's curve for the radius ``r``; ``(q0, q1, q2)`` the
    table's curve for a scattering partner's centre (radius ``partner_radius``, default
    ``r``), which sets the kick log's "outside" flag; a partner the table cannot hold is a
    ValueError naming ``partner_radius``.
    """
    if table == Circle():
        return None
    kind, p0, p1, p2 = table.kernel(r)
    r1 = r if partner_radius is None or kick_angle != "scatter" else partner_radius
    try:
        _, q0, q1, q2 = table.kernel(r1)
    except ValueError as exc:
        raise ValueError(f"partner_radius: the partner disk must fit the table: {exc}") from None
    return (kind, p0, p1, p2, q0, q1, q2)


def check_table_kicks(table, kicks, holes) -> None:
    """What a stadium or an ellipse refuses: kinetic kicks (`KineticRate`: a rate that is
    a function of the circle's conserved angular momentum, which these tables lack; the
    ellipse conserves the product of the momenta about its foci instead) and holes (arcs
    of the circle's wall)."""
    from kicktimes.schedules import KineticRate

    if table == Circle():
        return
    if isinstance(kicks, KineticRate):
        raise ValueError(f"kicks: kinetic kicks (KineticRate) are a rate of the circle's "
                         f"conserved angular momentum, which {table!r} does not conserve; use "
                         "kick times or a schedule (Poisson, Replay, ...) in this table")
    if holes is not None:
        raise ValueError(f"holes: holes are arcs of the circle's wall (centre angle, "
                         f"half-width); {table!r} takes none (table=None or Circle() for holes)")


def table_sizes(table, r) -> tuple[float, float]:
    """``(length, curvature radius)`` of the budgets of a run in ``table``: the radius of
    the circle with the same mean free path (``2 / pi`` times the mean free time at unit
    speed; ``1 - r`` in the circle), and the smallest radius of curvature of the centre's
    curve (the grazing chord of `kicktimes.billiard.checks.stall_time`)."""
    if table == Circle():
        return 1.0 - r, 1.0 - r
    length = 2.0 * table.mean_free_time(r) / math.pi
    if isinstance(table, Stadium):
        return length, 1.0 - r
    assert isinstance(table, Ellipse)
    return length, table.b * table.b / table.a - r


def draw_kick_angles(n: int, kick_angle: str, sigma: float, rng: np.random.Generator):
    """Kick angles for ``n`` kicks: new directions uniform on [0, 2 pi) (``"uniform"``) or
    from N(0, sigma^2) (``"normal"``), or rotations from N(0, sigma^2) (``"gaussian"``).

    For ``"scatter"`` the per-kick numbers are two uniforms on (-1, 1), shape ``(n, 2)``
    (`kicktimes.billiard.scatter.draw_scatter_uniforms`).
    """
    if kick_angle == "uniform":
        return rng.uniform(0.0, 2.0 * np.pi, size=n)
    if kick_angle == "scatter":
        return draw_scatter_uniforms(n, rng)
    return rng.normal(0.0, sigma, size=n)


def resolve_kicks(kicks, kick_angles, *, kick_angle, sigma, rng, horizon, t_max, r=None):
    """Kick times and angles of a run, the generator used (``None`` if none was) and the
    kinetic-kick arguments of the kernels (``None`` but for a `KineticRate`).

    ``kicks`` is ``None``, an array of times (checked against ``t_max`` when it is not
    ``None``), a schedule sampled on ``(0, horizon]`` with ``rng``, or a
    `kicktimes.schedules.KineticRate`: then ``times`` is a buffer the event loop fills, and
    the standard exponential numbers of the intervals are drawn from ``rng`` first, for a
    run of ``horizon`` (`KineticRate.capacity`). ``kick_angles`` is given (one per kick;
    shape ``(n, 2)`` for scattering kicks) or drawn from the same generator, after the
    times (or numbers).
    """
    from kicktimes.schedules import KineticRate

    gen = None
    kinetic = None
    if kicks is None:
        times = np.empty(0)
    elif isinstance(kicks, KineticRate):
        if kick_angles is not None:
            raise ValueError("kick_angles: kinetic kicks draw their angles with their times; "
                             "to replay a kinetic run pass kicks=run.kick_times and "
                             "kick_angles=run.kick_angles")
        gen = check_rng(rng)
        n = kicks.capacity(horizon)
        kinetic = (gen.standard_exponential(n), *kicks.kernel_table(r))
        times = np.full(n, np.inf)
    elif _is_schedule(kicks):
        gen = check_rng(rng)
        # (a kicktimes Schedule takes rng= by keyword; any other object with the schedule
        # protocol sample(t_max, rng) gets it by position, as before 0.2.0)
        drawn = (kicks.sample(horizon, rng=gen) if _is_kicktimes_schedule(kicks)
                 else kicks.sample(horizon, gen))
        times = check_kick_times(drawn, horizon, name="kicks.sample()")
    else:
        times = check_kick_times(kicks, t_max)
    if kick_angles is None:
        if not times.size:
            empty = np.empty((0, 2)) if kick_angle == "scatter" else times.copy()
            return times, empty, gen, kinetic
        gen = gen if gen is not None else check_rng(rng)
        return times, draw_kick_angles(times.size, kick_angle, sigma, gen), gen, kinetic
    return times, check_kick_angles(kick_angles, times, kick_angle), gen, kinetic


def check_kinetic(kinetic, state, kick_angle, rule, sp=None) -> None:
    """Kinetic kicks need the speeds their table is for.

    A mirror-rule table (one row, `kicktimes.schedules.KineticRate`): unit speed for the
    whole run, so no elastic scattering kicks. An elastic-rule table: a speed below
    ``sqrt(2)`` (kicktimes' elastic energy shell ``|v0|^2 + |v1|^2 = 2``), and scattering
    kicks, if any, under the elastic rule with that shell's partner: ``e0 = 1`` and equal
    masses (checked when the scattering parameters ``sp`` are given).
    """
    if kinetic is None:
        return
    speed = math.hypot(state[2], state[3])
    if kinetic[1].shape[0] == 1:
        if abs(speed - 1.0) > 1e-12:
            raise ValueError("kicks: kinetic kicks of a mirror-rule KineticRate are tabulated "
                             f"for unit speed; the disk's speed is {speed!r} (build "
                             "KineticRate(r, rule='elastic') for other speeds)")
        if kick_angle == "scatter" and rule != "mirror":
            raise ValueError(f"rule={rule!r}: a mirror-rule KineticRate needs unit speeds, "
                             "which elastic scattering kicks change; build "
                             "KineticRate(r, rule='elastic')")
        return
    if not speed < math.sqrt(2.0):
        raise ValueError("kicks: an elastic-rule KineticRate is tabulated for speeds below "
                         f"sqrt(2) (|v0|^2 + |v1|^2 = 2); the disk's speed is {speed!r}")
    if kick_angle != "scatter":
        return
    if rule != "elastic":
        raise ValueError(f"rule={rule!r}: an elastic-rule KineticRate averages over a partner "
                         "on the elastic energy shell; scattering kicks with it need "
                         "rule='elastic' (or use KineticRate(r) with the mirror rule)")
    if sp is not None and abs(sp[2] - 1.0) > 1e-9:
        raise ValueError(f"e0={float(sp[2])!r}: an elastic-rule KineticRate is tabulated for "
                         "the pair's energy e0 = 1 (|v0|^2 + |v1|^2 = 2)")
    if sp is not None and sp[5] != sp[6]:
        raise ValueError("partner_mass: an elastic-rule KineticRate is tabulated for equal "
                         f"masses, got partner_mass = {float(sp[6] / sp[5])!r}")


def check_kinetic_capacity(kinetic, n_applied: int) -> None:
    """The run used every kinetic number drawn (probability < 1e-15): an error, since the
    loop could not draw a further kick."""
    if kinetic is not None and n_applied >= kinetic[0].size:
        raise RuntimeError(f"kicks: the run applied all {n_applied} kinetic kicks drawn for "
                           "its horizon (KineticRate.capacity); this should not happen, "
                           "please report it")


def check_scatter_options(state, r, kick_angle, rule, e0, partner, partner_radius=None,
                          partner_mass=None):
    """Validate the scattering-kick options; returns ``(sp, options)``.

    ``sp = [r + r1, rule code, e0, partner-law code, 1 - r1, m0, m1]`` for the kernels
    (`kicktimes.billiard.kernels.one.SCATTER_PARAMS`): ``r1`` the partner's radius
    (``partner_radius``, default ``r``) and the masses normalised to ``(m0 + m1) / 2 = 1``
    from ``partner_mass = m1 / m0`` (default 1). ``options`` are the run's record
    ``{"rule", "e0", "partner", "partner_radius", "partner_mass"}`` (``None`` where they do
    not apply or keep their default). Raises ValueError for options that only make sense
    with ``kick_angle="scatter"``, or that the rule does not have.
    """
    chk.check_choice("rule", rule, chk.RULES)
    chk.check_choice("partner", partner, PARTNER_LAWS)
    if kick_angle != "scatter":
        if (rule != "mirror" or e0 is not None or partner != "weighted"
                or partner_radius is not None or partner_mass is not None):
            raise ValueError(
                f"rule, e0, partner, partner_radius and partner_mass describe scattering "
                f"kicks; they need kick_angle='scatter', got kick_angle={kick_angle!r}"
            )
        return np.zeros(7), dict.fromkeys(SCATTER_OPTIONS)
    if not r < 0.5:
        raise ValueError(f"r must be < 0.5 for scattering kicks (two disks), got {r!r}")
    r1 = r
    if partner_radius is not None:
        r1 = partner_radius = chk.check_real("partner_radius", partner_radius, low=0.0,
                                             high=0.5)
    m0 = m1 = 1.0
    if partner_mass is not None:
        if rule != "elastic":
            raise ValueError(f"partner_mass applies to rule='elastic' (the mirror rule keeps "
                             f"the disk's speed whatever the masses), got rule={rule!r}")
        partner_mass = chk.check_real("partner_mass", partner_mass, low=0.0)
        # normalised to (m0 + m1) / 2 = 1, as the two-disk system's masses
        m0 = 2.0 / (1.0 + partner_mass)
        m1 = 2.0 * partner_mass / (1.0 + partner_mass)
    v2 = float(state[2] ** 2 + state[3] ** 2)
    if rule == "mirror":
        if e0 is not None:
            raise ValueError("e0 (the pair's kinetic energy) applies to rule='elastic' only")
        e0_val = 0.0
    else:
        e0_val = 1.0 if e0 is None else chk.check_real("e0", e0, low=0.0)
        if m0 * v2 > 2.0 * e0_val * (1.0 + 1e-12):
            raise ValueError(
                f"e0={e0_val!r}: the pair's kinetic energy must be at least the disk's, "
                f"m0 |v|^2 / 2 = {m0 * v2 / 2.0!r} (masses normalised to (m0 + m1) / 2 = 1)"
            )
        e0 = e0_val
    sp = np.array([r + r1, chk.RULES[rule], e0_val, PARTNER_LAWS[partner], 1.0 - r1, m0, m1],
                  dtype=np.float64)
    return sp, {"rule": rule, "e0": e0, "partner": partner, "partner_radius": partner_radius,
                "partner_mass": partner_mass}


#: the scattering kicks' options a `OneParticleRun` records (`check_scatter_options`)
SCATTER_OPTIONS = ("rule", "e0", "partner", "partner_radius", "partner_mass")


#: the flat kick keywords of `simulate_one_particle` and `lyapunov` before 0.2.0 and the
#: `KickLaw` field each became (``kicks`` stays: it takes a `KickLaw`, or its times)
OLD_KICK_KEYWORDS = {"kick_angle": "angle", "kick_angles": "angles", "sigma": "sigma",
                     "rule": "rule", "e0": "e0", "partner": "partner",
                     "partner_radius": "partner_radius", "partner_mass": "partner_mass"}


def law_from_old_keywords(kwargs: dict, old: dict, where: str) -> None:
    """Replace ``kwargs["kicks"]`` by the `KickLaw` of the old flat keywords ``old``
    (already popped), warning once that names the replacement."""
    if isinstance(kwargs.get("kicks"), KickLaw):
        raise TypeError(f"{where}: kicks is a KickLaw; give {', '.join(old)} as its fields, "
                        "not as keywords")
    fields = ", ".join(f"{OLD_KICK_KEYWORDS[k]}=..." for k in old)
    warn_old(", ".join(f"{where}({k}=...)" for k in old),
             f"{where}(..., kicks=KickLaw(times, {fields})) (kicktimes.billiard.KickLaw)",
             stacklevel=5)
    law = as_kick_law(kwargs.get("kicks"))
    kwargs["kicks"] = law.replace(**{OLD_KICK_KEYWORDS[k]: v for k, v in old.items()})


def seed_after(seed):
    """The deprecated ``seed=`` of the simulators: the run with ``seed`` in its metadata."""
    import dataclasses

    return lambda run: dataclasses.replace(run, seed=seed)


@translator("seed", *OLD_KICK_KEYWORDS)
def _old_one_particle(args, kwargs):
    kwargs = dict(kwargs)
    after = None
    if "seed" in kwargs:
        seed = kwargs.pop("seed")
        warn_old("simulate_one_particle(seed=...)", "dataclasses.replace(run, seed=...) (the "
                 "keyword only recorded a number in run.seed; the random numbers come from rng)")
        after = seed_after(seed)
    old = pop_old(kwargs, OLD_KICK_KEYWORDS)
    if old:
        law_from_old_keywords(kwargs, old, "simulate_one_particle")
    return kwargs, after


@old_keywords(_old_one_particle)
def simulate_one_particle(state, r, *, t_max=None, kicks=None, rng=None, sampling="uniform",
                          n_steps=None, tau=None, max_events=None,
                          holes=None, table=None) -> OneParticleRun:
    """Simulate one disk of radius ``r`` in the unit table (or a stadium, an ellipse),
    kicked at given times.

    Parameters
    ----------
    state : array_like, shape (4,)
        ``(x, y, vx, vy)`` at ``t = 0``; ``|x| <= 1 - r`` (in another table: any centre
        that keeps the disk inside it), non-zero velocity (the speed is kept by boundary
        collisions and kicks).
    r : float
        Disk radius, ``0 < r < 1`` (the table's `check_radius`: an ellipse needs
        ``r < b^2 / a``).
    t_max, sampling, n_steps, tau
        As in `simulate_two_particle`. Under ``sampling="paper"`` a step is cut short by a
        boundary collision or a kick.
    kicks : KickLaw, array_like or schedule, optional
        The kick law (`kicktimes.billiard.KickLaw`): when the disk is kicked (times, a
        schedule sampled here with ``rng``, or kinetic kicks of a
        `kicktimes.schedules.KineticRate`, whose times the run draws) and what a kick does
        (a new direction, a rotation, or a collision with a virtual partner disk; the
        partner's rule, energy, radius and mass). Kick times or a schedule alone are
        short for ``KickLaw(kicks)``: new directions uniform on [0, 2 pi), the paper's
        choice. Times must lie in ``[0, t_max]``. ``None``: no kicks (the integrable
        billiard).
    rng : None, int, SeedSequence or numpy.random.Generator, optional
        Source of the schedule's times (first) and the kick angles (second).
    max_events : int, optional
        Stop with a ValueError after this many boundary collisions (as in
        `simulate_two_particle`; kicks do not count).
    holes : array_like, shape (n, 2), optional
        Holes in the table's wall, rows ``(centre angle, half-width)`` in radians: the
        disk escapes at a wall contact in a hole and the run ends there
        (``run.escape_time``; ``inf`` if it did not escape by the end). Circle only.
    table : Circle, Stadium or Ellipse, optional
        The table (`kicktimes.tables`; ``None``: ``Circle()``, the computation it always
        was, to the bit). In a stadium or an ellipse the wall contacts are those of the
        centre's parallel curve (`kicktimes.billiard.kernels.tables`: contact put back on
        the wall, reflection or grazing slide, the speed kept by a Newton step); every
        kick law but the kinetic one applies (a scattering kick's partner needs no wall).
        ``boundary.s`` is then the arc length along the centre's curve and ``sin_theta``
        the incoming ``v.t / |v|`` (Birkhoff's coordinates,
        `kicktimes.billiard.kernels.tables.boundary_coordinates`).
    -------
    OneParticleRun
        ``kick_times``, ``kick_angles`` (what was applied), ``boundary`` (DataFrame
        ``time, s, sin_theta``), ``final_state``, ``sample_times``, ``samples``, ``table``.

    Raises
    ------
    TypeError
        ``table`` is not a table.
    ValueError
        A radius the table refuses (its ``check_radius``); kinetic kicks (``kicks``) or
        ``holes`` in a stadium or an ellipse.

    Notes
    -----
    A kick at the same instant as a boundary collision is applied after the reflection;
    a kick exactly at the end of the run is applied. The random numbers are drawn after
    the schedule's times, from the same generator, whatever the kick law. A contact within
    5e-5 rad of tangent slides on along the wall (`kicktimes.billiard.geometry.graze`),
    whether the IC or a kick put the disk there. ``r <= 1 - 1e-6``; the speed must lie in
    ``[1e-6, 1e6]``; other ranges as in `simulate_two_particle`.

    Examples
    --------
    >>> import numpy as np
    >>> from kicktimes import simulate_one_particle, schedules
    >>> from kicktimes.billiard import KickLaw
    >>> state = np.array([0.1, 0.2, 0.6, 0.8])
    >>> run = simulate_one_particle(state, 0.02, t_max=100.0, kicks=schedules.Poisson(0.1),
    ...                             rng=1)
    >>> bool(np.all(run.kick_times <= 100.0))
    True
    >>> hit = simulate_one_particle(state, 0.02, t_max=100.0,
    ...                             kicks=KickLaw(schedules.Poisson(0.1), angle="scatter"), rng=1)
    >>> hit.kick_log.shape[0] == hit.n_kicks
    True

    A partner of another radius (and, under the elastic rule, mass), e.g. the other disk
    of an unequal pair (docs/unequal.md):

    >>> law = KickLaw(schedules.Poisson(0.1), angle="scatter", rule="elastic",
    ...               partner_radius=0.05, partner_mass=3.0)
    >>> big = simulate_one_particle(state, 0.02, t_max=100.0, kicks=law, rng=1)
    >>> big.partner_radius, big.partner_mass
    (0.05, 3.0)

    The same kicks in Bunimovich's stadium (every centre stays inside it):

    >>> from kicktimes.tables import Stadium, uniform_state
    >>> table = Stadium(1.0)
    >>> st = uniform_state(table, 0.02, rng=2)
    >>> run = simulate_one_particle(st, 0.02, t_max=100.0, kicks=schedules.Poisson(0.1),
    ...                             rng=1, table=table)
    >>> run.table, bool(table.contains(run.samples, 0.02).all())
    (Stadium(a=1.0), True)
    """
    table = check_table(table)
    r = (chk.check_real("r", r, low=0.0, high=1.0) if table == Circle()
         else table.check_radius(r))
    law = as_kick_law(kicks)
    check_table_kicks(table, law.times, holes)
    kicks, kick_angles, kick_angle, sigma = law.times, law.angles, law.angle, law.sigma
    rule, e0, partner = law.rule, law.e0, law.partner
    partner_radius, partner_mass = law.partner_radius, law.partner_mass
    t_max, n_steps, tau, mode = chk.check_sampling(t_max, n_steps, tau, sampling)
    state = check_one_particle_state(state, r, table=table)
    sp, options = check_scatter_options(state, r, kick_angle, rule, e0, partner,
                                        partner_radius, partner_mass)
    rule = options["rule"]
    tab = table_args(table, r, kick_angle, partner_radius)
    horizon = t_max if mode < 2 else n_steps * tau  # paper steps are at most tau long
    times, angles, _, kinetic = resolve_kicks(kicks, kick_angles, kick_angle=kick_angle,
                                              sigma=sigma, rng=rng, horizon=horizon,
                                              t_max=t_max if mode < 2 else None, r=r)
    check_kinetic(kinetic, state, kick_angle, rule, sp)
    arcs = chk.check_holes(holes)
    st = np.zeros(7)
    st[1:5] = state
    st[6] = state[2] ** 2 + state[3] ** 2
    scatter = kick_angle == "scatter"
    rho, max_events, b_cap, stall_dt = kernel_limits(st, r, sp, scatter, horizon, mode,
                                                     max_events, table=table)
    out = simulate_one_kernel(
        st, rho, times, np.zeros(times.size) if scatter else angles,
        KICK_ANGLES[kick_angle], 0.0 if mode == 2 else t_max, mode,
        n_steps if n_steps is not None else 0, tau if tau is not None else 0.0,
        b_cap, angles if scatter else np.zeros((0, 2)), sp, max_events, stall_dt, kinetic, arcs,
        tab,
    )
    raise_for_status(out[9], st[0], out[0].shape[0], max_events=max_events, name="state",
                     where=f"disk at ({st[1]:.6g}, {st[2]:.6g}), r={r!r}")
    check_kinetic_capacity(kinetic, out[6])
    if mode == 2 and out[7] == 0.0:
        # every paper step was cut short at t = 0 (kicks at 0, or the disk on the wall)
        warnings.warn(
            f"state: the paper-sampled run covers no time (t_max = 0.0): all n_steps = "
            f"{n_steps} steps ended at events at t = 0 ({out[6]} kicks, {out[0].shape[0]} "
            "boundary collisions); more steps, or kicks after t = 0, give it a duration",
            RuntimeWarning, stacklevel=3,  # through the old_keywords wrapper
        )
    return one_particle_run(st, r, state, out[:9], sampling=sampling, mode=mode, tau=tau,
                            n_steps=n_steps, seed=None, kick_angle=kick_angle, sigma=sigma,
                            times=times, applied=angles, escape_time=float(out[10][0]),
                            table=table, **options)


def kernel_limits(st, r, sp, scatter, horizon, mode, max_events=None, *, table=None):
    """``(rho, max_events, b_cap, stall_dt)`` of a kicked run from the state ``st``.

    The event budget (`event_budget` at the largest speed the disk can reach: elastic
    scattering can give it all of the pair's energy), the initial size of the boundary
    log and the stall time, shared by `simulate_one_particle` and the one pass of
    `kicktimes.diagnostics.lyapunov` so that both set up the very same run. In another
    ``table`` the lengths are its `table_sizes` (``rho`` stays ``1 - r``, which the
    table's kernels do not read).
    """
    rho = 1.0 - r
    size, bend = table_sizes(check_table(table), r)
    speed = math.sqrt(st[6])
    if scatter and sp[1] != 0.0:
        speed = max(speed, math.sqrt(2.0 * sp[2] / sp[5]))
    max_events = chk.event_budget(max_events, horizon=horizon,
                                  horizon_name="t_max" if mode < 2 else "n_steps * tau",
                                  speed=speed, rho=size, n_disks=1)
    return rho, max_events, int(2.0 * speed * horizon / size) + 64, chk.stall_time(bend, speed)


def one_particle_run(st, r, state, out, *, sampling, mode, tau, n_steps, seed, kick_angle,
                     sigma, times, applied, rule, e0, partner, partner_radius=None,
                     partner_mass=None, escape_time=math.inf, table=None) -> OneParticleRun:
    """The `OneParticleRun` of a finished kicked run: ``out`` is the kernel's
    ``(b_time, b_x, b_y, b_sin, sample_times, samples, n_kicks_applied, t_end,
    kick_log)``, ``st`` its final state, ``applied`` the kick angles (or, for scattering
    kicks, their random numbers) of which the first ``n_kicks_applied`` were used."""
    bt, bx, by, bs, stimes, samples, n_applied, t_end, klog = out
    return OneParticleRun(
        r=r,
        ic=state,
        final_state=st[1:5].copy(),
        boundary_log=BoundaryLog(bt, np.zeros(bt.shape[0], dtype=np.int8), bx, by, bs),
        seed=seed,
        **sampling_fields(t_end, mode, sampling, tau, n_steps, stimes, samples),
        kick_angle=kick_angle,
        sigma=sigma if kick_angle in ("gaussian", "normal") else None,
        kick_times=times[:n_applied],
        kick_angles=applied[:n_applied],
        rule=rule,
        e0=e0,
        partner=partner,
        partner_radius=partner_radius,
        partner_mass=partner_mass,
        kick_log_array=klog,
        escape_time=escape_time,
        escaped=0 if math.isfinite(escape_time) else -1,
        table=check_table(table),
    )
