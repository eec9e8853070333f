"""Speed of the N-disk engine (issue 40): disk-disk collisions per second on one core.

For N = 10^2, 10^3, 10^4 disks at packings 0.1, 0.3, 0.5 (mirror rule, every event
processed, the collision log on): `kicktimes.simulate_disks` as a user calls it (argument
checks, engine set-up, log), about ``--collisions`` collisions per run, CPU seconds
(``time.process_time``: the machine is shared), the best of ``--repeats``. The cost per
collision at 10^4 disks is compared with that at 10^2 (the target: at most 1.5x).

Same-output baselines, where they finish:

* python-billiards (``billiards``, GPL, the optional ``outside`` extra; imported, never
  copied): its ``Billiard`` keeps an O(N^2) table of pair times. It has no concave wall, so
  the table's wall is an ``Obstacle`` subclass here (`ConcaveCircle`). Elastic rule, the
  same initial state; its first collisions must equal the engine's (pairs, times to 1e-6)
  before it is timed.
* the brute-force reference of the tests (``tests/_disks_reference.py``: all pairs at every
  event, NumPy), mirror rule, same state and output.

Also the robustness run of the issue: ``--robust 1e8`` collisions at packing 0.6 (N = 1000),
checked for overlaps and disks outside at the end.

The periodic box (issue 51): ``--box K`` runs N = 1000 disks at packing 0.3 (true area
fraction, mirror rule) in the unit table and in the periodic box ``[0, 1)^2`` one after the
other, K rounds, and prints both rates of each round and the ratio box / table (median and
range): the machine is shared, so only the ratio measured in the same run means much.
``--only-box`` skips the main table.

Large N (issue 64): ``--sizes 1e3 1e4 1e5 1e6`` times N disks at packing 0.3, mirror
rule, in the unit table and in the periodic box, as a user calls `kicktimes.simulate_disks`
(the collision log on), and prints the cost per collision at each N and its ratio to the
smallest N, both geometries in one run. The cost is marginal: the CPU time of a run of
``--per-disk`` collisions per disk less that of a run of 1 per disk from the same state,
over the collisions between them, so the set-up (O(N): cells, calendar, every disk's
first prediction) and the first disks' compilation are left out; the best of
``--repeats``. The states (`kicktimes.initial_state`, RSA then relaxation) are timed too.

Run: python benchmarks/bench_disks.py [--quick] [--packings 0.1 0.3 0.5] [--rounds 5]
[--robust 1e8] [--box 5 [--only-box]] [--sizes 1e3 1e4 1e5 1e6 [--per-disk 5]]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
import _disks_reference as ref  # noqa: E402

import kicktimes as kt  # noqa: E402
from kicktimes.stats import enskog_frequency  # noqa: E402


def cpu_best(func, repeats):
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.process_time()
        out = func()
        best = min(best, time.process_time() - t0)
    return best, out


def engine_rate(n, phi, collisions, repeats, rule="mirror", box=None):
    """``(collisions per CPU second, run)`` of simulate_disks at ``n``, ``phi`` (in the
    periodic box of side ``box``: ``phi = n pi r^2 / box^2``)."""
    area = math.pi if box is None else box * box
    r = math.sqrt(phi / n) if box is None else math.sqrt(phi * area / (math.pi * n))
    state = kt.initial_state(n, r, rng=1, rule=rule, box=box)
    t_max = collisions / (0.5 * n * enskog_frequency(r, n, area=area))
    kt.simulate_disks(state, r, t_max=t_max / 100, rule=rule, box=box)  # compiled, warm
    sec, run = cpu_best(lambda: kt.simulate_disks(state, r, t_max=t_max, rule=rule, box=box),
                        repeats)
    return run.n_pp / sec, run, state, r


def marginal_cost(n, phi, per_disk, repeats, box=None):
    """``(seconds per collision, initial_state's CPU seconds)`` of `kicktimes.simulate_disks`
    at ``n`` disks, packing ``phi``, mirror rule: a run of ``per_disk`` collisions per disk
    less a run of one, from the same state, over the collisions between them."""
    area = math.pi if box is None else box * box
    r = math.sqrt(phi * area / (math.pi * n))
    t0 = time.process_time()
    state = kt.initial_state(n, r, rng=1, box=box)
    t_state = time.process_time() - t0
    per = n / (0.5 * n * enskog_frequency(r, n, area=area))  # time per collision per disk
    best = math.inf
    for _ in range(repeats):
        cost = []
        for k in (1.0, per_disk):
            t0 = time.process_time()
            run = kt.simulate_disks(state, r, t_max=k * per, box=box)
            cost.append((time.process_time() - t0, run.n_pp))
            del run
        best = min(best, (cost[1][0] - cost[0][0]) / (cost[1][1] - cost[0][1]))
    return best, t_state


def sizes_table(sizes, per_disk, repeats, phi=0.3):
    """The cost per collision at each of ``sizes`` in the table and the box, as a ratio to
    the smallest size, one geometry after the other in this process."""
    kt.simulate_disks(kt.initial_state(100, 0.02, rng=1), 0.02, t_max=0.1)  # compiled
    kt.simulate_disks(kt.initial_state(100, 0.02, rng=1, box=1.0), 0.02, t_max=0.1, box=1.0)
    print(f"kicktimes {kt.__version__}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}: "
          f"packing {phi}, mirror rule, marginal CPU cost per collision between 1 and "
          f"{per_disk:g} collisions per disk, best of {repeats}")
    print("| geometry | N | ns / collision | collisions / CPU s | × N = "
          f"{sizes[0]:.0e} | initial_state, CPU s |")
    print("|---|---|---|---|---|---|")
    for name, box in (("circle", None), ("box", 1.0)):
        first = None
        for n in sizes:
            cost, t_state = marginal_cost(n, phi, per_disk, repeats, box=box)
            first = cost if first is None else first
            print(f"| {name} | {n:.0e} | {1e9 * cost:.0f} | {1.0 / cost:.3g} | "
                  f"{cost / first:.2f} | {t_state:.1f} |", flush=True)


def box_rounds(rounds, collisions, n=1000, phi=0.3):
    """The table and the box at ``n``, ``phi``, alternated: ``(table rates, box rates)``."""
    table, box = [], []
    for k in range(rounds):
        table.append(engine_rate(n, phi, collisions, 1)[0])
        box.append(engine_rate(n, phi, collisions, 1, box=1.0)[0])
        print(f"  round {k + 1}: table {table[-1]:.4g} coll/s, box {box[-1]:.4g} coll/s, "
              f"ratio {box[-1] / table[-1]:.3f}", flush=True)
    return np.array(table), np.array(box)


class ConcaveCircle:
    """The unit table's wall as a python-billiards obstacle: a disk of radius ``r`` inside
    ``|x| <= 1`` hits it when its centre reaches ``1 - r``, and is reflected."""

    def calc_toi(self, pos, vel, radius):
        rho = 1.0 - radius
        b = pos[0] * vel[0] + pos[1] * vel[1]
        vv = vel[0] * vel[0] + vel[1] * vel[1]
        if vv == 0.0:
            return math.inf
        c = rho * rho - pos[0] * pos[0] - pos[1] * pos[1]
        disc = max(b * b + vv * c, 0.0)
        t = c / (b + math.sqrt(disc)) if b > 0.0 else (-b + math.sqrt(disc)) / vv
        return max(t, 0.0)

    def collide(self, pos, vel, radius):
        n = pos / math.hypot(pos[0], pos[1])
        return vel - 2.0 * (vel @ n) * n


def billiards_rate(state, r, n_events):
    """``(collisions per CPU second, log)`` of python-billiards, or ``(None, why)``."""
    try:
        import billiards
        from billiards.obstacles import Obstacle
    except ImportError:
        return None, "billiards not installed (pip install kicktimes[outside])"
    wall = type("Wall", (ConcaveCircle, Obstacle), {})()
    # its set-up fills the O(N^2) table of pair times: timed apart from the run
    sim = billiards.Billiard(obstacles=[wall])
    for row in state:
        sim.add_ball(row[:2], row[2:], radius=r, mass=1.0)
    # run until n_events disk-disk collisions: step the horizon
    t0 = time.process_time()
    log, t = [], 0.0
    step = n_events / (0.5 * len(state) * enskog_frequency(r, len(state), rule="elastic")) / 8
    while len(log) < n_events:
        t += step
        log += [c for c in sim.evolve(t) if isinstance(c[2], int | np.integer)]
    sec = time.process_time() - t0
    return len(log) / sec, np.array([(c[0], c[1], c[2]) for c in log], dtype=float)


def agree(log_a, times_b, i_b, j_b, k):
    """The first ``k`` collisions are the same pairs at times within 1e-6."""
    k = min(k, len(log_a), len(times_b))
    same = (log_a[:k, 1] == i_b[:k]).all() and (log_a[:k, 2] == j_b[:k]).all()
    return bool(same and np.abs(log_a[:k, 0] - times_b[:k]).max() < 1e-6), k


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer collisions per run")
    ap.add_argument("--collisions", type=float, default=3e6)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--packings", type=float, nargs="+", default=[0.1, 0.3, 0.5])
    ap.add_argument("--rounds", type=int, default=0,
                    help="also measure the cost ratio N=1e4 / N=1e2 in this many alternated "
                         "rounds (one run of each per round): median and range")
    ap.add_argument("--robust", type=float, default=0.0,
                    help="also run this many collisions at packing 0.6, N = 1000")
    ap.add_argument("--box", type=int, default=0,
                    help="also compare the periodic box with the table at N = 1000, packing "
                         "0.3, in this many alternated rounds")
    ap.add_argument("--only-box", action="store_true", help="only the --box comparison")
    ap.add_argument("--sizes", type=float, nargs="+", default=None,
                    help="only the large-N table: the cost per collision at these N, the "
                         "table and the box, as a ratio to the first")
    ap.add_argument("--per-disk", type=float, default=5.0,
                    help="collisions per disk of the --sizes runs (the marginal cost is "
                         "taken from 1 to this many)")
    args = ap.parse_args(argv)
    if args.sizes:
        sizes_table([int(n) for n in args.sizes], args.per_disk, args.repeats)
        return
    collisions = 3e5 if args.quick else args.collisions
    if args.box:
        print(f"kicktimes {kt.__version__}, "
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}: N=1000, packing 0.3, "
              f"mirror, ~{collisions:.2g} collisions per run, CPU seconds, table and box "
              f"alternated")
        table, box = box_rounds(args.box, collisions)
        ratio = box / table
        print(f"table: median {np.median(table):.4g} coll/s (range {table.min():.4g}-"
              f"{table.max():.4g}); box: median {np.median(box):.4g} coll/s (range "
              f"{box.min():.4g}-{box.max():.4g}); ratio box/table: median "
              f"{np.median(ratio):.3f} (range {ratio.min():.3f}-{ratio.max():.3f})")
        print(f"target: box >= 1.5e6 coll/s: {np.median(box):.3g}")
        if args.only_box:
            return
    rows = {}
    print(f"kicktimes {kt.__version__}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"CPU seconds, best of {args.repeats}, ~{collisions:.2g} collisions per run")
    print(f"{'N':>6} {'packing':>7} {'coll/s':>10} {'ns/coll':>8} {'billiards':>10} "
          f"{'brute':>10}")
    for phi in args.packings:
        for n in (100, 1000, 10000):
            rate, run, state, r = engine_rate(n, phi, collisions, args.repeats)
            rows[n, phi] = rate
            bil = brute = "-"
            if n == 100:
                # python-billiards: elastic rule, the same state, same output first
                es = kt.initial_state(n, r, rng=1, rule="elastic")
                ours = kt.simulate_disks(es, r, t_max=200 / (0.5 * n * enskog_frequency(
                    r, n, rule="elastic")), rule="elastic")
                b_rate, b_log = billiards_rate(es, r, 1000 if not args.quick else 300)
                if b_rate is not None:
                    ok, k = agree(b_log, ours.pp_times, ours.pp_i, ours.pp_j, 20)
                    e_rate, *_ = engine_rate(n, phi, collisions, 1, rule="elastic")
                    bil = f"{e_rate / b_rate:.0f}x" + ("" if ok else "(!)")
                    print(f"  python-billiards N={n} phi={phi}: {b_rate:.3g} coll/s, first {k} "
                          f"collisions {'agree' if ok else 'DIFFER'}; engine elastic "
                          f"{e_rate:.3g} coll/s")
                else:
                    print(f"  python-billiards skipped: {b_log}")
            if n <= 1000:
                k = 300 if n == 100 else 40
                t0 = time.process_time()
                log, _ = ref.simulate(state, r, run.t_max, n_pp=k)
                b_rate = len(log) / (time.process_time() - t0)
                ok, kk = agree(log, run.pp_times, run.pp_i, run.pp_j, 20)
                brute = f"{rate / b_rate:.0f}x" + ("" if ok else "(!)")
            print(f"{n:>6} {phi:>7} {rate:>10.3g} {1e9 / rate:>8.0f} {bil:>10} {brute:>10}",
                  flush=True)
    for phi in args.packings:
        print(f"cost per collision N=1e4 / N=1e2 at packing {phi}: "
              f"{rows[100, phi] / rows[10000, phi]:.2f}")
    if (1000, 0.3) in rows:
        print(f"target: >= 1.0e6 coll/s at N=1000, packing 0.3: {rows[1000, 0.3]:.3g}")
    for phi in args.packings if args.rounds else ():
        # the two sizes run one after the other in each round, so that a change of the
        # machine's load (other processes in the shared L3) falls on both alike
        ratios = [engine_rate(100, phi, collisions, 1)[0] / engine_rate(10000, phi, collisions,
                                                                          1)[0]
                  for _ in range(args.rounds)]
        print(f"cost ratio N=1e4 / N=1e2 at packing {phi}, {args.rounds} alternated rounds: "
              f"median {np.median(ratios):.2f}, range {min(ratios):.2f}-{max(ratios):.2f}")
    if args.robust:
        n, phi = 1000, 0.6
        from scipy.spatial import cKDTree

        from kicktimes.billiard.many_disks import engine_run

        r = math.sqrt(phi / n)
        state = kt.initial_state(n, r, rng=7)
        t_max = args.robust / (0.5 * n * enskog_frequency(r, n))
        t0 = time.process_time()
        out = engine_run(state, np.full(n, r), 0, t_max, log=False)
        sec = time.process_time() - t0
        end = out["final_state"]
        pairs = cKDTree(end[:, :2]).query_pairs(2 * r * (1 - 1e-10))
        outside = (np.hypot(end[:, 0], end[:, 1]) > 1 - r + 1e-12).sum()
        total = out["n_pp_total"]
        print(f"robustness: packing 0.6, N=1000, t_max={t_max:.4g}: status {out['status']}, "
              f"{total:.4g} disk-disk collisions in {sec:.0f} s ({total / sec:.3g}/s), "
              f"overlapping pairs at the end {len(pairs)}, disks outside {outside}")


if __name__ == "__main__":
    main()
