"""The largest Lyapunov exponent of N hard disks: tangent vectors, or a twin trajectory.

`disks_lyapunov` has two methods (docs/lyapunov.md, "N disks"; docs/disks.md, "The tangent
observer"):

* ``method="tangent"`` (default): one tangent vector ``(dq_k, dv_k)`` per disk, carried
  exactly along one uninterrupted run of the N-disk engine by its tangent observer
  (`kicktimes.billiard.kernels.disks.drive` with ``tan``): free flight ``dq += dv t`` when
  an event touches the disk, the linearised collision and wall maps of
  `kicktimes.billiard.kernels.tangent` (Dellago, Posch & Hoover, Phys. Rev. E 53, 1485
  (1996)) at its events. At the end of each segment of length ``segment`` the vector is
  brought to the common time, projected off the trivial directions (the flow, and the
  velocity constraints of the rule), its log-norm summed and rescaled to 1 (Benettin,
  Galgani & Strelcyn, Phys. Rev. A 14, 2338 (1976)).
* ``method="twin"``: a reference state and a twin a distance ``d0`` away, each segment a
  fresh `kicktimes.simulate_disks` call from the two states; after it the separation
  ``d_k`` is measured, ``log(d_k / d0)`` summed and the twin put back at distance ``d0``
  along the separation. Kept as the check of the tangent method: over 32 states the
  ratio of their means is within 2 % at N = 10, 100, 1000 under both rules and at N = 2
  under the elastic one (kicktimes.studies.disks.ftle_check, docs/results/disks_ftle_check.csv).

Both estimate ``lambda = sum_k log(growth of segment k) / t``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from kicktimes._results import Result
from kicktimes.validation import check_choice, check_real, check_rng

__all__ = ["DisksLyapunov", "disks_lyapunov", "project_trivial"]

METHODS = ("tangent", "twin")


@dataclass(frozen=True, repr=False)
class DisksLyapunov(Result):
    """Result of `disks_lyapunov`.

    Attributes
    ----------
    lam : float
        ``sum(logs) / t_max``, per unit time: the largest exponent, named as
        `LyapunovResult.lam` (``exponent`` is its deprecated alias, until 0.3.0).
    logs : ndarray
        The log-growth of each segment: ``log |u_k|`` of the tangent vector (rescaled to 1
        at each segment's start), or ``log(d_k / d0)`` of the twin.
    segment, t_max : float
        ``t_max`` is the time run, ``len(logs) * segment``.
    d0 : float or None
        The twin's distance (``None`` for the tangent method).
    n_collisions : int
        Disk-disk collisions of the reference run.
    final_state : ndarray
        The reference's state at ``t_max``.
    method : str
        ``"tangent"`` or ``"twin"``.
    """

    _title = "Largest Lyapunov exponent of the N-disk gas (disks_lyapunov)"
    _summary_fields = ("lam", "method", "t_max", "segment", "d0", "n_collisions", "logs")

    lam: float
    logs: np.ndarray
    segment: float
    t_max: float
    d0: float | None
    n_collisions: int
    final_state: np.ndarray
    method: str = "twin"

    @property
    def exponent(self) -> float:
        """Deprecated alias of `lam` (since 0.2.0, until 0.3.0)."""
        warnings.warn("DisksLyapunov.exponent is deprecated since 0.2.0 and will be removed in "
                      "0.3.0; use DisksLyapunov.lam", DeprecationWarning, stacklevel=2)
        return self.lam

    def __repr__(self) -> str:
        d0 = "" if self.d0 is None else f", d0={self.d0:g}"
        return (f"DisksLyapunov(lam={self.lam:.5g}, method={self.method!r}, "
                f"segments={self.logs.size}, t_max={self.t_max:g}{d0})")


def _twin(state, offset, d0, rule):
    twin = state + offset * (d0 / np.linalg.norm(offset))
    if rule == "mirror":
        # unit speeds: the deviation is second order in d0, put back on the constraint
        speed = np.hypot(twin[:, 2], twin[:, 3])
        twin[:, 2:] /= speed[:, None]
    return twin


def project_trivial(u, v, rule):
    """Project the tangent vector ``u`` (n, 4), in place, off its trivial directions at a
    state of velocities ``v`` (n, 2): the flow ``(dq_k, dv_k) = (v_k, 0)`` (a shift along
    the trajectory, neither growing nor shrinking); under the mirror rule each disk's speed
    ``(0, v_k)`` (``|v_k| = 1`` is kept: the deviation obeys ``v_k . dv_k = 0``); under the
    elastic rule the energy ``(0, v)`` (``sum_k v_k . dv_k = 0``). The three kinds of
    direction are orthogonal to each other, so one pass projects off all of them."""
    ff = float(np.sum(v * v))
    if ff > 0.0:
        u[:, :2] -= (float(np.sum(u[:, :2] * v)) / ff) * v
    if rule == "mirror":
        vv = np.sum(v * v, axis=1)
        vdv = np.sum(v * u[:, 2:], axis=1)
        u[:, 2:] -= np.divide(vdv, vv, out=np.zeros_like(vv), where=vv > 0.0)[:, None] * v
    elif ff > 0.0:
        u[:, 2:] -= (float(np.sum(u[:, 2:] * v)) / ff) * v


def _tangent(state, radii, rule, n_seg, segment, gen):
    """The tangent method: ``(logs, n_collisions, final_state)``."""
    from kicktimes.billiard import checks as chk
    from kicktimes.billiard.many_disks import engine_run, raise_for_status

    u0 = gen.normal(size=state.shape)
    project_trivial(u0, state[:, 2:], rule)
    u0 /= np.linalg.norm(u0)
    logs = []

    def renormalize(u, v, lg):
        project_trivial(u, v, rule)
        d = float(np.linalg.norm(u))
        logs.append(lg + math.log(d) if d > 0.0 else math.nan)
        if d > 0.0 and math.isfinite(d):
            u /= d

    out = engine_run(state, radii, chk.RULES[rule], n_seg * segment, log=False,
                     tangent=u0, segment=segment, on_segment=renormalize)
    raise_for_status(out, np.iinfo(np.int64).max)
    logs = np.array(logs)
    if not np.isfinite(logs).all():
        raise ValueError(
            "state: the linearised dynamics is singular along this trajectory (a contact "
            "tangent to the wall, v.n = 0, where the map's collision-time variation is "
            "infinite): the exponent is undefined; use method='twin' or another state")
    return logs, out["n_pp_total"], out["final_state"]


def disks_lyapunov(state, r, *, t_max, segment, rule="mirror", method="tangent", d0=1e-9,
                   rng=None) -> DisksLyapunov:
    r"""The largest Lyapunov exponent of an N-disk state, from tangent vectors or a twin.

    Parameters
    ----------
    state : array_like, shape (n_disks, 4)
        The reference's rows ``(x, y, vx, vy)`` (`kicktimes.initial_state`).
    r : float
        The disks' radius.
    t_max : float
        Duration (``> 0``); ``floor(t_max / segment)`` segments are run.
    segment : float
        Time between renormalisations (``> 0``, at most ``t_max``). Twin: short enough that
        the separation stays far below the disks' radius (``d0 e^{lambda segment}``).
        Tangent: any (the engine rescales the vector itself when it grows past 1e50); each
        segment end costs O(N) in NumPy (about 0.2 ms at 100 disks), so longer segments
        are cheaper (docs/disks.md, "The tangent observer").
    rule : {"mirror", "elastic"}
    method : {"tangent", "twin"}
        ``"tangent"``: the linearised dynamics along one run of the engine, exact.
        ``"twin"``: Benettin's twin at distance ``d0``, both restarted through
        `kicktimes.simulate_disks` at every segment.
    d0 : float
        Twin only (the tangent method has no scale): the twin's distance in phase space,
        ``1e-13 <= d0 <= 1e-5``.
    rng : Generator or int, optional
        The first tangent vector's or offset's direction (normal in every coordinate; the
        tangent vector is then projected off the trivial directions, the twin's speeds are
        put back to 1 under the mirror rule).

    Returns
    -------
    DisksLyapunov

    Raises
    ------
    ValueError
        Naming the argument: a bad state (overlaps, outside the table, speeds; as
        `kicktimes.simulate_disks`), ``r``, ``t_max``, ``segment``, ``rule``, ``method``,
        ``d0``; ``state`` also when the trajectory meets a contact exactly tangent to the
        wall (tangent method: the linearised dynamics is singular there).

    Notes
    -----
    **Tangent.** A tangent vector :math:`u = (\delta q_k, \delta v_k)_{k=1..N}` follows the
    linearised flow: :math:`\delta q_k \mathrel{+}= \delta v_k\, t` in free flight, and at
    an event of disks :math:`i, j` (or of disk :math:`i` and the wall) the map
    :math:`\delta q' = \delta q + (v - v')\delta\tau`,
    :math:`\delta v' = D_v f\,\delta v + D_q f\,(\delta q + v\,\delta\tau)` with
    :math:`\delta\tau = -n\cdot\delta q_{rel} / n\cdot v_{rel}` (docs/lyapunov.md derives
    each rule's). The other disks' rows pass unchanged. With :math:`u_k` the vector at the
    end of segment :math:`k`, projected off the flow :math:`(v, 0)` and the rule's
    constraints (`project_trivial`) and rescaled to 1 after,
    :math:`\lambda = \sum_k \log\lVert u_k\rVert / (K \Delta t)`. Holes and masses are
    not arguments here (the engine's observer zeroes an escaped disk's row and carries the
    mass factors of the elastic map: `kicktimes.billiard.many_disks.engine_run`).

    **Twin.** With :math:`X_k` and :math:`X'_k` the two states (all positions and velocities) at the
    end of segment :math:`k`, :math:`d_k = \lVert X'_k - X_k\rVert`, and the twin restarts
    at :math:`X_k + d_0 (X'_k - X_k) / d_k`; :math:`\lambda = \sum_k \log(d_k/d_0) / (K
    \Delta t)`. For a dilute hard-disk gas kinetic theory gives :math:`\lambda \propto \nu
    \ln(1/\tilde n)` (van Zon, van Beijeren & Dellago, Phys. Rev. Lett. 80, 2035 (1998)).
    A twin whose collision sequence departs from the reference's (a grazing collision
    missed) shows as one large ``log(d_k / d0)``; keep ``d0`` small. Each restart moves the
    reference by round-off, which the chaos amplifies: after some ``37 / lambda`` the
    reference is another trajectory than one uninterrupted run's, so the exponent of one
    state compares with another method's only on average over states (two disks: the mean
    of 12 states is 0.99 of `kicktimes.diagnostics.lyapunov`'s tangent mean,
    ``tests/test_disks_gas.py``). The tangent method has neither the restarts nor ``d0``.

    References
    ----------
    Benettin, Galgani & Strelcyn, Phys. Rev. A 14, 2338 (1976); Dellago, Posch & Hoover,
    Phys. Rev. E 53, 1485 (1996); van Zon, van Beijeren & Dellago, Phys. Rev. Lett. 80, 2035
    (1998).

    Examples
    --------
    >>> import kicktimes as kt
    >>> from kicktimes.diagnostics.gas_lyapunov import disks_lyapunov
    >>> s = kt.initial_state(20, 0.05, rng=3)
    >>> res = disks_lyapunov(s, 0.05, t_max=20.0, segment=1.0, rng=1)
    >>> res.logs.size, res.method, bool(res.lam > 0)
    (20, 'tangent', True)
    >>> twin = disks_lyapunov(s, 0.05, t_max=20.0, segment=1.0, method="twin", rng=1)
    >>> twin.d0
    1e-09
    """
    from kicktimes.billiard import simulate_disks
    from kicktimes.billiard.many_disks import check_disks

    check_choice("rule", rule, ("mirror", "elastic"))
    check_choice("method", method, METHODS)
    ref, radii, _ = check_disks(state, r, rule)
    t_max = check_real("t_max", t_max, low=0.0)
    segment = check_real("segment", segment, low=0.0, high=t_max, high_open=False)
    gen = check_rng(rng)
    n_seg = int(math.floor(t_max / segment + 1e-9))
    if method == "tangent":
        logs, n_pp, final = _tangent(ref, radii, rule, n_seg, segment, gen)
        return DisksLyapunov(float(logs.sum() / (n_seg * segment)), logs, segment,
                             n_seg * segment, None, int(n_pp), final, "tangent")
    d0 = check_real("d0", d0, low=1e-13, high=1e-5, low_open=False, high_open=False)
    offset = gen.normal(size=ref.shape)
    twin = _twin(ref, offset, d0, rule)
    logs = np.empty(n_seg)
    n_pp = 0
    for k in range(n_seg):
        a = simulate_disks(ref, r, t_max=segment, rule=rule)
        b = simulate_disks(twin, r, t_max=segment, rule=rule)
        ref, diff = a.final_state, b.final_state - a.final_state
        n_pp += a.n_pp
        d = float(np.linalg.norm(diff))
        logs[k] = math.log(d / d0)
        twin = _twin(ref, diff, d0, rule)
    return DisksLyapunov(float(logs.sum() / (n_seg * segment)), logs, segment,
                         n_seg * segment, d0, n_pp, ref, "twin")
