r"""Collision times from an independent hard-disk simulator, ready for ``kicktimes analyze``.

The outside source is the ``billiards`` package (PyPI, v0.5.0, GPL-3.0-or-later, by Markus
Ebke; install it with ``pip install billiards`` or ``pip install kicktimes[outside]``; it is
imported, never copied). Its :class:`billiards.Billiard` is an event-driven simulator of
disks among obstacles whose ``evolve(t)`` returns its own collision log, a list of
``(time, i, j)`` (disk-disk) and ``(time, i, obstacle)`` (disk-wall) entries.

What this script does
---------------------
For each box side ``L`` (the density), ``n_runs`` runs of ``n_disks`` equal disks of
radius ``r`` and mass 1 in the square box ``[0, L]^2`` (four ``InfiniteWall`` obstacles):

* initial condition drawn from the equilibrium (microcanonical) measure: velocities
  uniform on the energy sphere :math:`\sum |v_i|^2 = 2 N k T` (``kT = 1``), positions by
  random sequential addition without overlap, followed by a burn-in ``t_burn`` (about 20
  collisions per disk) that relaxes the positions to the equilibrium ones;
* the log of ``evolve(t_burn + t_window)`` is converted to one **sequence per disk**: the
  times of its collisions with any other disk (wall bounces are not collisions between
  disks and are left out), observed on the window ``[t_burn, t_burn + t_window]``.

It writes two tidy tables (the input contract of ``kicktimes analyze``):

* ``events.csv``: ``sequence, time`` (one row per disk-disk collision and disk; every
  collision appears twice, once for each of its disks);
* ``sequences.csv``: ``sequence, t_start, t_end`` and covariates ``box``, ``density``
  (:math:`n = N / L^2`), ``packing_fraction`` (:math:`\eta = N\pi r^2 / L^2`), ``run``
  and ``kinetic_rate`` (the rate below).

The kinetic-theory rate
-----------------------
A disk collides with a given other disk at the rate of the pair's contact flux. With
:math:`\sigma = 2r` (contact distance), ``a = L - 2r`` (the side of the square the
centres move in) and equilibrium (uniform) positions, the density of pairs at contact is
:math:`2\pi\sigma W(a, \sigma) / a^4` with :math:`W = a^2 - 4a\sigma/\pi + \sigma^2/\pi`
(the area of the square overlapping its own translate by :math:`\sigma`, averaged over
directions: the walls remove partners), and the mean approach speed at contact is
:math:`\langle|v_{rel}|\rangle/\pi`. So, per disk, with :math:`g(\sigma)` the contact
value of the pair correlation,

.. math::

    \omega = (N - 1)\, 2\sigma\, \langle|v_{rel}|\rangle\, \frac{W(a, \sigma)}{a^4}\, g(\sigma),

the 2D Enskog collision frequency :math:`2 n\sigma g(\sigma)\sqrt{\pi kT/m}` with the
box's finite size and walls kept (the cross-section of a disk in 2D is the width
:math:`2\sigma` swept by the relative motion). :math:`\langle|v_{rel}|\rangle` is exact
for the microcanonical velocities (uniform on the sphere of radius
:math:`R = \sqrt{2NkT}` in :math:`2N` dimensions):
:math:`\sqrt2 R\,\Gamma(3/2)\Gamma(N)/\Gamma(N + 1/2)`, which tends to
:math:`\sqrt{\pi kT/m}` for large N. :math:`g(\sigma)` is Henderson's
:math:`(1 - 7\eta/16)/(1 - \eta)^2` (bulk hard disks); it is the one approximate factor,
good to a few per cent at :math:`\eta \le 0.15`.

Run::

    python analysis/outside_billiards.py --out /tmp/outside          # ~1 min
    kicktimes analyze /tmp/outside/events.csv --windows /tmp/outside/sequences.csv \
        --group density --reference kinetic_rate --out /tmp/outside/report
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd


def kinetic_rate_per_disk(n_disks, radius, box, kT=1.0):
    """Disk-disk collision rate of one disk (see the module notes), per unit time."""
    sigma, a = 2.0 * radius, box - 2.0 * radius
    r_sphere = math.sqrt(2.0 * n_disks * kT)
    v_rel = (
        math.sqrt(2.0)
        * r_sphere
        * math.exp(math.lgamma(1.5) + math.lgamma(n_disks) - math.lgamma(n_disks + 0.5))
    )
    w = a * a - 4.0 * a * sigma / math.pi + sigma * sigma / math.pi
    eta = n_disks * math.pi * radius**2 / box**2
    g = (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2
    return (n_disks - 1) * 2.0 * sigma * v_rel * w / a**4 * g


def _initial_state(n_disks, radius, box, rng, kT=1.0):
    """Random sequential addition of non-overlapping disks; microcanonical velocities."""
    pos = []
    for _ in range(200_000):
        p = rng.uniform(radius, box - radius, size=2)
        if all(np.hypot(*(p - q)) > 2.0 * radius for q in pos):
            pos.append(p)
            if len(pos) == n_disks:
                break
    else:
        raise ValueError(f"could not place {n_disks} disks of radius {radius} in a box {box}")
    v = rng.standard_normal((n_disks, 2))
    v *= math.sqrt(2.0 * n_disks * kT) / np.linalg.norm(v)  # exactly on the energy sphere
    return np.array(pos), v


def simulate_box(n_disks, radius, box, *, t_window, t_burn, seed):
    """One run of the outside simulator: its collision log as (time, i, j) disk-disk rows."""
    import billiards

    rng = np.random.default_rng(seed)
    walls = [
        billiards.InfiniteWall((0.0, 0.0), (box, 0.0)),  # inside is on the left of each
        billiards.InfiniteWall((box, 0.0), (box, box)),
        billiards.InfiniteWall((box, box), (0.0, box)),
        billiards.InfiniteWall((0.0, box), (0.0, 0.0)),
    ]
    sim = billiards.Billiard(obstacles=walls)
    pos, vel = _initial_state(n_disks, radius, box, rng)
    for p, v in zip(pos, vel, strict=True):
        sim.add_ball(p, v, radius=radius, mass=1.0)
    sim.evolve(t_burn)
    log = sim.evolve(t_burn + t_window)
    # disk-disk entries have an integer partner; wall bounces carry the obstacle object
    return [(t, i, j) for t, i, j in log if isinstance(j, int | np.integer)]


def generate(
    *,
    boxes=(0.45, 0.65, 0.95, 1.4),
    n_disks=12,
    radius=0.02,
    n_runs=2,
    collisions_per_disk=120.0,
    burn_collisions=20.0,
    seed=2024,
):
    """Simulate every box side and return the two tables ``(events, sequences)``."""
    events, seqs = [], []
    for b, box in enumerate(boxes):
        omega = kinetic_rate_per_disk(n_disks, radius, box)
        t_window = collisions_per_disk / omega
        t_burn = burn_collisions / omega
        for run in range(n_runs):
            log = simulate_box(
                n_disks,
                radius,
                box,
                t_window=t_window,
                t_burn=t_burn,
                seed=(seed, b, run),
            )
            name = [f"L{box:g}-run{run}-disk{k}" for k in range(n_disks)]
            for t, i, j in log:
                events.append((name[i], t))
                events.append((name[j], t))
            for k in range(n_disks):
                seqs.append(
                    {
                        "sequence": name[k],
                        "t_start": t_burn,
                        "t_end": t_burn + t_window,
                        "box": box,
                        "density": n_disks / box**2,
                        "packing_fraction": n_disks * math.pi * radius**2 / box**2,
                        "run": run,
                        "kinetic_rate": omega,
                    }
                )
    ev = pd.DataFrame(events, columns=["sequence", "time"])
    # the log is in time order; a stable sort by disk keeps each disk's times increasing
    ev = ev.sort_values("sequence", kind="stable", ignore_index=True)
    return ev, pd.DataFrame(seqs)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="output folder (created)")
    ap.add_argument("--boxes", type=float, nargs="+", default=[0.45, 0.65, 0.95, 1.4])
    ap.add_argument("--n-disks", type=int, default=12)
    ap.add_argument("--radius", type=float, default=0.02)
    ap.add_argument("--n-runs", type=int, default=2)
    ap.add_argument("--collisions-per-disk", type=float, default=120.0)
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    ev, seqs = generate(
        boxes=args.boxes,
        n_disks=args.n_disks,
        radius=args.radius,
        n_runs=args.n_runs,
        collisions_per_disk=args.collisions_per_disk,
        seed=args.seed,
    )
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    ev.to_csv(out / "events.csv", index=False)
    seqs.to_csv(out / "sequences.csv", index=False)
    print(
        f"{len(seqs)} sequences, {len(ev)} disk events ({len(ev) // 2} collisions) in "
        f"{time.perf_counter() - t0:.1f} s -> {out / 'events.csv'}, {out / 'sequences.csv'}"
    )


if __name__ == "__main__":
    main()
