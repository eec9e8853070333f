"""Two hard disks in a billiard table (the unit circle, a stadium, an ellipse): the
simulator's Python layer.

`simulate_two_particle` checks its arguments, sets up the run (`kernel_args`: state, event
budget, first log sizes) and turns the kernel's output into a `TwoParticleRun`
(`two_particle_run`). The event loop itself is the kernel layer's
(`kicktimes.billiard.kernels.two` for the event step, `.drive_two` for the loop): it advances
from event to event (boundary collision of either disk, disk-disk collision) with exact
collision times; samples at fixed times are interpolated along the free flight between
events. Nothing is ever stepped through time and tested for overlap.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from kicktimes._old_keywords import old_keywords, translator, warn_old
from kicktimes.billiard import checks as chk
from kicktimes.billiard.checks import STALL_EVENTS
from kicktimes.billiard.kernels import two
from kicktimes.billiard.kernels.drive_two import simulate_two_kernel
from kicktimes.billiard.kernels.observe import DONE, OVER_BUDGET, STALLED
from kicktimes.billiard.runs import BoundaryLog, TwoParticleRun, sampling_fields
from kicktimes.billiard.tables import Circle, check_table


def raise_for_status(status: int, st_time: float, n_events: int, *, max_events: int,
                     name: str, where: str) -> None:
    """Turn a kernel's early stop into a ValueError naming the input (no-op for `DONE`)."""
    if status == OVER_BUDGET:
        raise ValueError(
            f"max_events: the run needed more than max_events={max_events} collisions "
            f"(stopped at t = {float(st_time)!r}); a disk grazing the wall makes one collision "
            f"every 2e-4 (1 - r) / |v|; pass a larger max_events or a shorter run"
        )
    if status == STALLED:
        raise ValueError(
            f"{name}: the run makes no progress: {STALL_EVENTS} collisions in less than "
            f"{STALL_EVENTS} x 1e-9 (1 - r) / |v| at t = {float(st_time)!r} ({n_events} collisions "
            f"so far; {where}); the state is stuck (e.g. disks jammed against the wall)"
        )


def check_two_particle_ic(ic, r, rule: str, name: str = "ic", table=None) -> np.ndarray:
    """Validate a two-disk initial condition for radius ``r`` (or radii ``(r0, r1)``) in
    ``table`` (``None``: the unit circle; another table: equal disks, each centre inside
    its region, ``table.contains``); returns a float64 (2, 4) copy."""
    arr = chk.check_state(name, ic, (2, 4))
    radii = tuple(r) if isinstance(r, tuple) else (r, r)
    # plain floats: the checks run on every simulator call, and numpy scalars cost ~10x
    rows = arr.tolist()
    if table is not None and table != Circle():
        inside = table.contains(arr[:, :2], radii[0])
    for i, (x, y, vx, vy) in enumerate(rows):
        which = "disk 0" if i == 0 else "disk 1"
        if table is None or table == Circle():
            chk.check_inside(name, x, y, 1.0 - radii[i], radii[i], which)
        elif not inside[i]:
            raise ValueError(f"{name}: {which}'s centre ({x!r}, {y!r}) keeps no disk of "
                             f"radius {radii[i]!r} inside {table!r}")
        if rule == "mirror":
            chk.check_unit_speed(name, vx, vy, which)
        else:
            chk.check_speed(name, vx, vy, which, allow_zero=True)
    (x0, y0, vx0, vy0), (x1, y1, vx1, vy1) = rows
    if rule != "mirror" and not (vx0 or vy0 or vx1 or vy1):
        raise ValueError(f"{name}: both disks are at rest; give a non-zero velocity")
    gap = math.hypot(x0 - x1, y0 - y1)
    sigma = radii[0] + radii[1] if isinstance(r, tuple) else 2.0 * r
    if gap < sigma - chk.CONTACT_TOL:
        raise ValueError(
            f"{name}: the disks overlap (centre distance {gap:.15g} < r0 + r1 = {sigma:.15g})"
        )
    return arr


@translator("seed")
def _old_two_particle(args, kwargs):
    kwargs = dict(kwargs)
    seed = kwargs.pop("seed")
    warn_old("simulate_two_particle(seed=...)", "dataclasses.replace(run, seed=...) (the "
             "keyword only recorded a number in run.seed; the simulation is deterministic)")
    return kwargs, lambda run: dataclasses.replace(run, seed=seed)


@old_keywords(_old_two_particle)
def simulate_two_particle(ic, r, *, t_max=None, rule="mirror", sampling="uniform", n_steps=None,
                          tau=None, track=0, max_events=None, log_collisions=False, holes=None,
                          masses=None, table=None) -> TwoParticleRun:
    """Simulate two disks of radius ``r`` in the unit circular table, or in another table.

    Event-driven and exact: the disks move freely between collisions whose times are
    roots of quadratics (docs/architecture.md); boundary collisions are specular, disk-disk
    collisions follow ``rule``.

    Parameters
    ----------
    ic : array_like, shape (2, 4)
        Rows ``(x, y, vx, vy)`` of disk 0 and disk 1. Centres must lie in the table
        (``|x| <= 1 - r``) without overlap; speeds must be 1 under the mirror rule.
    r : float or (float, float)
        Disk radius, ``0 < r < 0.5``; or the two disks' radii ``(r0, r1)`` (unequal
        disks: disk ``i`` keeps its centre in ``|x| <= 1 - r_i``, contact at ``r0 + r1``).
    t_max : float, optional
        End time. With ``n_steps`` and ``tau`` (uniform sampling) it defaults to
        ``n_steps * tau``; it must not be given with ``sampling="paper"``.
    rule : {"mirror", "elastic"}
        Disk-disk collision rule: ``"mirror"`` (the paper's: each disk reflects off the
        other as off a fixed wall, speeds stay 1) or ``"elastic"`` (equal masses).
    sampling : {"uniform", "paper"}
        ``"uniform"``: the tracked disk's centre at ``t_k = k tau``, ``k = 0..n_steps``.
        ``"paper"``: step ``k`` ends at ``min(t_{k-1} + tau, next collision)``, samples at
        step ends; the run ends after ``n_steps`` steps (``t_max`` is that time).
    n_steps : int, optional
        Number of sampling steps (``>= 1``).
    tau : float, optional
        Step length (``> 0``).
    track : {0, 1}
        The disk whose centre is sampled.
    max_events : int, optional
        Stop with a ValueError after this many collisions (``>= 1``). The default is a
        hundred times the expected number plus 10^6, at most 2e7; a run expected to need
        more than 5e6 is refused unless ``max_events`` is given.
    log_collisions : bool
        Also log every disk-disk collision: contact centres and both velocities before
        and after (``run.pp_log``, ``run.collisions`` with the contact normal).
    masses : (float, float), optional
        The disks' masses under the elastic rule (default equal): a collision exchanges
        momentum, ``v0' = v0 - 2 m1/(m0 + m1) (w.n) n``, ``v1' = v1 + 2 m0/(m0 + m1) (w.n) n``.
    holes : array_like, shape (n, 2), optional
        Holes in the table's wall: rows ``(centre angle, half-width)`` in radians. A disk
        whose wall contact lies in a hole escapes there: the run ends at that time
        (``run.escape_time``, ``run.escaped`` the disk; ``inf`` and -1 if none escaped by
        the end), and its samples stop there. The unit circle only (a ValueError in
        another table).
    table : Circle, Stadium or Ellipse, optional
        The table (`kicktimes.tables`; ``None``: ``Circle()``, the unit circle, whose runs
        are bitwise those without the keyword). In a `Stadium` or an `Ellipse` the disks
        must be equal (one ``r``, which the table must admit: ``table.check_radius``, e.g.
        ``r < b^2 / a`` in the ellipse) and ``holes`` is refused; each disk's centre keeps
        to the table's inner parallel curve at distance ``r`` (docs/tables.md), its wall
        contacts found, put back on the wall and reflected by
        `kicktimes.billiard.kernels.tables` (``hit``, ``contact``, ``bounce``), its speed
        kept by one Newton step after each reflection. The run records the table
        (``run.table``) and ``run.boundary`` gives the contacts' Birkhoff coordinates
        (``arc``, ``s = 2 pi arc / L``, ``sin_theta``).

    Returns
    -------
    TwoParticleRun
        ``pp_times``, ``boundary`` (DataFrame ``time, particle, s, sin_theta``),
        ``final_state``, ``sample_times``, ``samples`` and the parameters.

    Notes
    -----
    ``sin_theta = L / (1 - r)`` is the tangential component of the incoming unit
    velocity at a boundary collision (``L = x vy - y vx``); ``s`` is the polar angle of
    the contact point in ``[0, 2 pi)``. Events at exactly ``t_max`` are included.

    A contact within 5e-5 rad of tangent (an exactly tangent one included) slides on
    along the wall instead of being reflected: the disk leaves along the
    whispering-gallery chord of angle ``2e-4`` (`kicktimes.billiard.geometry.graze`).
    Speeds must be 1 (mirror) or 0 or in ``[1e-6, 1e6]`` (elastic); ``t_max``, ``tau`` and
    ``n_steps * tau`` at most 1e12, ``n_steps`` at most 1e8.

    Raises
    ------
    ValueError
        For arguments out of range, and when the run exceeds ``max_events`` or stops
        making progress (``10^4`` consecutive collisions at one instant).

    Warns
    -----
    RuntimeWarning
        A ``sampling="paper"`` run that covers no time (``t_max = 0``): every one of its
        ``n_steps`` steps ended at a collision at ``t = 0`` (disks starting in contact with
        each other or the wall, e.g. pinched between them).

    Examples
    --------
    >>> from kicktimes import simulate_two_particle, initial_conditions
    >>> ic = initial_conditions(1, 0.02, rng=1)[0]
    >>> run = simulate_two_particle(ic, 0.02, t_max=200.0)
    >>> bool((run.pp_times > 0).all() and (run.pp_times <= 200.0).all())
    True

    In a stadium (initial conditions drawn from its invariant measure):

    >>> from kicktimes.tables import Stadium
    >>> ic = initial_conditions(1, 0.02, rng=1, method="uniform", table=Stadium(1.0))[0]
    >>> run = simulate_two_particle(ic, 0.02, t_max=200.0, table=Stadium(1.0))
    >>> run.table, bool(Stadium(1.0).contains(run.final_state[:, :2], 0.02).all())
    (Stadium(a=1.0), True)
    """
    _, _, r = chk.check_radii(r)
    table = check_table(table)
    circle = table == Circle()
    if not circle:
        if isinstance(r, tuple):
            raise ValueError(f"r: two disks in {table!r} must be equal (one radius), got "
                             f"{r!r}; unequal disks run in the unit circle only")
        r = table.check_radius(r)
        if holes is not None:
            raise ValueError(f"holes: holes are arcs of the unit circle's wall; {table!r} "
                             "has none")
    chk.check_choice("rule", rule, chk.RULES)
    t_max, n_steps, tau, mode = chk.check_sampling(t_max, n_steps, tau, sampling)
    track = chk.check_int("track", track, low=0)
    if track > 1:
        raise ValueError(f"track must be 0 or 1, got {track}")
    masses = chk.check_masses(masses, rule)
    ic = check_two_particle_ic(ic, r, rule, table=None if circle else table)
    if not isinstance(log_collisions, bool | np.bool_):
        raise TypeError(f"log_collisions must be a bool, got {type(log_collisions).__name__}")
    arcs = chk.check_holes(holes)
    if circle:
        args = kernel_args(ic, r, rule, mode, t_max, n_steps, tau, track, max_events, masses)
        out = simulate_two_kernel(*args, bool(log_collisions), arcs)
    else:
        args = kernel_args(ic, r, rule, mode, t_max, n_steps, tau, track, max_events, masses,
                           table=table)
        out = simulate_two_kernel(*args, bool(log_collisions), None, table.kernel(r))
    return two_particle_run(out, args, r=r, rule=rule, sampling=sampling, tau=tau,
                            n_steps=n_steps, ic=ic, track=track, seed=None, name="ic",
                            table=table)


def kernel_args(ic, r, rule, mode, t_max, n_steps, tau, track, max_events, masses=None, *,
                table=None) -> tuple:
    """`simulate_two_kernel`'s arguments (all but ``log_pp``) for validated inputs.

    ``ic``, ``r``, ``rule``, ``track`` validated, ``(t_max, n_steps, tau, mode)`` from
    `check_sampling`, ``max_events`` as given (``None``: the default budget); ``table``
    another table than the circle (its mean free path sets the budget). Shared with
    the one-pass FTLE (`kicktimes.diagnostics.lyapunov`), which must run the very same
    simulation.
    """
    x0, y0, vx0, vy0, x1, y1, vx1, vy1 = ic.ravel().tolist()
    r0, r1 = r if isinstance(r, tuple) else (r, r)
    # the budget counts collisions per mean free path, pi rho / 2 in the circle: in another
    # table the radius of the circle of the same mean free path (pi A / L, Santalo)
    budget_rho = (min(1.0 - r0, 1.0 - r1) if table is None
                  else 2.0 * table.mean_free_time(r0) / math.pi)
    table = two.table(1.0 - r0, 1.0 - r1, *(masses if masses is not None else (1.0, 1.0)))
    # the initial kinetic energy, summed in this order (numpy's, bits of older runs kept);
    # with masses, k1 |v0|^2 + k0 |v1|^2, as the kernels' anchor computes it
    if masses is None:
        e0 = vx0 * vx0 + vy0 * vy0 + vx1 * vx1 + vy1 * vy1
    else:
        e0 = table[3] * (vx0 * vx0 + vy0 * vy0) + table[2] * (vx1 * vx1 + vy1 * vy1)
    st = np.array([0.0, x0, y0, vx0, vy0, x1, y1, vx1, vy1, 0.0, e0])
    horizon = t_max if mode < 2 else n_steps * tau
    rho = min(1.0 - r0, 1.0 - r1)
    # the largest speed a disk can reach: all the kinetic energy in one disk
    speed = 1.0 if rule == "mirror" else math.sqrt(e0 / min(table[2], table[3]))
    max_events = chk.event_budget(max_events, horizon=horizon,
                                  horizon_name="t_max" if mode < 2 else "n_steps * tau",
                                  speed=speed, rho=budget_rho, n_disks=2)
    # capacities are only a first guess: the kernel grows its buffers when needed
    b_cap = int(3.0 * speed * horizon) + 64
    pp_cap = int(10.0 * (r0 + r1) * speed * horizon) + 16
    sigma = r0 + r1 if isinstance(r, tuple) else 2.0 * r
    return (st, table, sigma, chk.RULES[rule], 0.0 if mode == 2 else t_max,
            mode, n_steps if n_steps is not None else 0, tau if tau is not None else 0.0,
            track, pp_cap, b_cap, max_events, chk.stall_time(rho, speed))


def two_particle_run(out, args, *, r, rule, sampling, tau, n_steps, ic, track, seed,
                     name, table=None) -> TwoParticleRun:
    """The `TwoParticleRun` of `simulate_two_kernel`'s output ``out`` for ``args``
    (`kernel_args`); raises the ValueError of an early stop, naming the argument ``name``."""
    pp, bt, bp, bx, by, bs, stimes, samples, t_end, ppl, status = out[:11]
    escape = out[11] if len(out) > 11 else (math.inf, -1.0)
    st, mode, max_events = args[0], args[5], args[11]
    if status != DONE:  # (the message is formatted only when it is needed)
        raise_for_status(status, st[0], pp.shape[0] + bt.shape[0], max_events=max_events,
                         name=name, where=f"disks at ({st[1]:.6g}, {st[2]:.6g}) and "
                                          f"({st[5]:.6g}, {st[6]:.6g}), r={r!r}")
    if mode == 2 and t_end == 0.0 and escape[1] < 0:
        # every paper step was cut short by a collision at t = 0 (fewer than the STALL_EVENTS
        # a stuck state needs to end in the stall error)
        warnings.warn(
            f"{name}: the paper-sampled run covers no time (t_max = 0.0): all n_steps = "
            f"{n_steps} steps ended at collisions at t = 0 ({pp.shape[0]} disk-disk, "
            f"{bt.shape[0]} boundary), the disks starting in contact with each other or the "
            "wall; more steps may resolve the contacts (a state that stays stuck ends in an "
            f"error after {STALL_EVENTS} collisions), or start the disks apart",
            RuntimeWarning, stacklevel=3,
        )
    return TwoParticleRun(
        r=r,
        ic=ic,
        final_state=st[1:9].reshape(2, 4).copy(),
        boundary_log=BoundaryLog(bt, bp, bx, by, bs),
        seed=seed,
        rule=rule,
        track=track,
        pp_times=pp,
        pp_log=ppl,
        escape_time=float(escape[0]),
        escaped=int(escape[1]),
        masses=None if args[1][2] == 1.0 == args[1][3] else (args[1][3], args[1][2]),
        table=Circle() if table is None else table,
        **sampling_fields(t_end, mode, sampling, tau, n_steps, stimes, samples),
    )
