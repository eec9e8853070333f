"""Cost of a wall step in the stadium and the ellipse, as a ratio to the circle (docs/tables.md).

One free disk (`kicktimes.tables.free_run`, unit speed, no kicks) over ``--bounces`` wall
contacts per table, at ``--r``: the circle, ``Stadium(1)``, ``Ellipse(1.5, 1)``, and
``Ellipse(2, 1)`` at the larger radius ``--r-large`` (farther from a conic: more Newton
iterations). Each figure is the best of ``--repeat`` CPU times (``time.process_time``,
robust to a shared machine), interleaved table by table in this process, so the ratios
compare like with like. Without and with the tangent vector. The issue's targets: the
stadium at most 1.3x the circle, the ellipse at most 3x.

Run: python benchmarks/bench_tables.py [--bounces 1000000] [--repeat 5] [--r 0.02]
"""

import argparse
import time

from _timing import best_time

from kicktimes.tables import Circle, Ellipse, Stadium, free_run, uniform_state


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bounces", type=int, default=10**6)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--r", type=float, default=0.02)
    parser.add_argument("--r-large", type=float, default=0.3)
    args = parser.parse_args()
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
