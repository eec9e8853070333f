"""Cost of a wall step in the stadium and the ellipse, as a ratio to the circle (docs/tables.md).

One free disk (`kicktimes.tables.free_run`, unit speed, no kicks) over ``--bounces`` wall
contacts per table, at ``--r``: the circle, ``Stadium(1)``, ``Ellipse(1.5, 1)``, and
``Ellipse(2, 1)`` at the larger radius ``--r-large`` (farther from a conic: more Newton
iterations). Each figure is the best of ``--repeat`` CPU times (``time.process_time``,
robust to a shared machine), interleaved table by table in this process, so the ratios
compare like with like. Without and with the tangent vector. The issue's targets: the
stadium at most 1.3x the circle, the ellipse at most 3x.

Section "kicked" (``--section kicked``): the kicked disk of `simulate_one_particle`
(``table=``, Poisson kicks at ``--kick-rate``, no samples) and its tangent FTLE
(`kicktimes.diagnostics.lyapunov`, one step), in the circle (``table=None``, the
simulator's own code) and in ``Stadium(1)`` and ``Ellipse(1.5, 1)`` at the same ``r``, kick
rate and horizon (``--bounces`` mean free times of the table, so about that many contacts);
the cost per event (contacts + kicks) as a ratio to the circle's.

The section ``two`` times two disks (`kicktimes.simulate_two_particle`, no samples, and
the tangent FTLE `kicktimes.diagnostics.lyapunov`) in the same tables at the same ``--r``
over the horizon ``--two-horizon``, per event (disk-disk and wall), as a ratio to the
circle (``table=None``, the circle's own kernels).

Run: python benchmarks/bench_tables.py [--bounces 1000000] [--repeat 5] [--r 0.02]
     [--section free|two|kicked|all] [--two-horizon 20000]
     [--kick-rate 0.1]
"""

import argparse
import time

from _timing import best_time

from kicktimes import initial_conditions, schedules, simulate_one_particle, simulate_two_particle
from kicktimes.diagnostics import lyapunov
from kicktimes.tables import Circle, Ellipse, Stadium, free_run, uniform_state


def two_disks(args):
    """Two disks, mirror rule, per event: the simulation and the tangent FTLE."""
    horizon = args.two_horizon
    cases = [("Circle()", None), ("Stadium(1)", Stadium(1.0)),
             ("Ellipse(1.5, 1)", Ellipse(1.5, 1.0))]
    ics = {name: initial_conditions(1, args.r, rng=1, method="uniform", table=table)[0]
           for name, table in cases}
    n_steps = int(horizon / 0.5)
    for name, table in cases:  # compile and warm up
        simulate_two_particle(ics[name], args.r, t_max=10.0, table=table)
        lyapunov(ics[name], args.r, n_steps=20, tau=0.5, table=table)
    best, events = {}, {}
    for _ in range(args.repeat):
        for name, table in cases:
            ic = ics[name]
            sim = best_time(lambda ic=ic, t=table: simulate_two_particle(
                ic, args.r, t_max=horizon, table=t), 1, clock=time.process_time)
            tan = best_time(lambda ic=ic, t=table: lyapunov(
                ic, args.r, n_steps=n_steps, tau=0.5, table=t), 1, clock=time.process_time)
            best[(name, False)] = min(best.get((name, False), float("inf")), sim)
            best[(name, True)] = min(best.get((name, True), float("inf")), tan)
            if name not in events:
                run = simulate_two_particle(ic, args.r, t_max=horizon, table=table)
                events[name] = run.n_pp + run.n_boundary
    print(f"\ntwo disks, mirror rule, r = {args.r:g}, t_max = {horizon:g}, best of "
          f"{args.repeat} CPU times (tangent: lyapunov, tau = 0.5)")
    print("| table | events | ns/event | × circle | ns/event, tangent | × circle |")
    print("|---|---|---|---|---|---|")
    c_sim = best[("Circle()", False)] / events["Circle()"]
    c_tan = best[("Circle()", True)] / events["Circle()"]
    for name, _ in cases:
        sim = best[(name, False)] / events[name]
        tan = best[(name, True)] / events[name]
        print(f"| {name} | {events[name]} | {1e9 * sim:.1f} | {sim / c_sim:.2f} | "
              f"{1e9 * tan:.1f} | {tan / c_tan:.2f} |")


def kicked(args):
    """The kicked disk's cost per event in each table against the circle's."""
    r = args.r
    cases = [("Circle()", None), ("Stadium(1)", Stadium(1.0)),
             ("Ellipse(1.5, 1)", Ellipse(1.5, 1.0))]
    horizon = args.bounces * Circle().mean_free_time(r)
    law = schedules.Poisson(args.kick_rate)

    def sim(table, state):
        return simulate_one_particle(state, r, t_max=horizon, kicks=law, rng=1, table=table,
                                     max_events=10 * args.bounces)

    def ftle(table, state):
        return lyapunov(state, r, n_steps=1, tau=horizon, kicks=law, rng=1, table=table)

    states = {name: uniform_state(table or Circle(), r, rng=1) for name, table in cases}
    events = {}
    for name, table in cases:  # compile, warm up, count the events
        small = simulate_one_particle(states[name], r, t_max=10.0, kicks=law, rng=1,
                                      table=table)
        lyapunov(states[name], r, n_steps=1, tau=10.0, kicks=law, rng=1, table=table)
        del small
        run = sim(table, states[name])
        events[name] = run.n_boundary + run.n_kicks
    best = {}
    for _ in range(args.repeat):
        for name, table in cases:
            for what, fn in (("sim", sim), ("ftle", ftle)):
                seconds = best_time(lambda f=fn, t=table, s=states[name]: f(t, s), 1,
                                    clock=time.process_time)
                best[(name, what)] = min(best.get((name, what), float("inf")), seconds)
    print(f"\nkicked disk: r = {r:g}, Poisson kicks at rate {args.kick_rate:g}, horizon "
          f"{horizon:.4g}, best of {args.repeat} CPU times")
    print("| table | events | ns/event | × circle | ns/event, tangent FTLE | × circle |")
    print("|---|---|---|---|---|---|")
    per = {k: 1e9 * v / events[k[0]] for k, v in best.items()}
    for name, _ in cases:
        print(f"| {name} | {events[name]} | {per[(name, 'sim')]:.1f} | "
              f"{per[(name, 'sim')] / per[('Circle()', 'sim')]:.2f} | "
              f"{per[(name, 'ftle')]:.1f} | "
              f"{per[(name, 'ftle')] / per[('Circle()', 'ftle')]:.2f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bounces", type=int, default=10**6)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--r", type=float, default=0.02)
    parser.add_argument("--r-large", type=float, default=0.3)
    parser.add_argument("--section", choices=("free", "two", "kicked", "all"), default="all")
    parser.add_argument("--two-horizon", type=float, default=2e4)
    parser.add_argument("--kick-rate", type=float, default=0.1)
    args = parser.parse_args()
    if args.section in ("free", "all"):
        free_disk(args)
    if args.section in ("two", "all"):
        two_disks(args)
    if args.section in ("kicked", "all"):
        kicked(args)


def free_disk(args):
    """One free disk per table: the wall step alone."""
    cases = [("Circle()", Circle(), args.r), ("Stadium(1)", Stadium(1.0), args.r),
             ("Ellipse(1.5, 1)", Ellipse(1.5, 1.0), args.r),
             (f"Ellipse(2, 1), r = {args.r_large:g}", Ellipse(2.0, 1.0), args.r_large)]
    best = {}
    for _name, table, r in cases:  # compile and warm up
        free_run(table, uniform_state(table, r, rng=0), r, n_bounces=100, n_record=0)
        free_run(table, uniform_state(table, r, rng=0), r, n_bounces=100, n_record=0,
                 tangent=False)
    for _ in range(args.repeat):
        for name, table, r in cases:
            state = uniform_state(table, r, rng=1)
            for tangent in (False, True):
                seconds = best_time(lambda t=table, s=state, r=r, g=tangent: free_run(
                    t, s, r, n_bounces=args.bounces, n_record=0, tangent=g, rng=1), 1,
                    clock=time.process_time)
                key = (name, tangent)
                best[key] = min(best.get(key, float("inf")), seconds)
    print(f"{args.bounces} wall contacts per run, r = {args.r:g}, best of {args.repeat} "
          f"CPU times")
    print("| table | ns/contact | × circle | ns/contact, tangent | × circle |")
    print("|---|---|---|---|---|")
    for name, _, _ in cases:
        plain, tan = best[(name, False)], best[(name, True)]
        print(f"| {name} | {1e9 * plain / args.bounces:.1f} | "
              f"{plain / best[('Circle()', False)]:.2f} | {1e9 * tan / args.bounces:.1f} | "
              f"{tan / best[('Circle()', True)]:.2f} |")


if __name__ == "__main__":
    main()
