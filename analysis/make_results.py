"""Write the reproduction's results for readers: figures (PNG) and a findings page.

From paper-scale stores (``kicktimes reproduce --scale paper --out paper/``)::

    python analysis/make_results.py paper/store-family_a paper/store-family_b --out docs/results

writes ``docs/results/README.md`` (the Findings of each store: effect sizes, 95 %
confidence intervals and verdicts, all computed from the stores; a banner when a store is
below paper scale) and one PNG per report figure beside it. Every number is computed by
:func:`kicktimes.report.write_results`, the same code as the HTML report.
"""

from __future__ import annotations

import argparse
import sys
import time


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("stores", nargs="*", help="result stores (e.g. family_a, family_b)")
    parser.add_argument("--out", default="docs/results", help="output folder (docs/results)")
    parser.add_argument("--dpi", type=int, default=110, help="PNG resolution (110)")
    parser.add_argument("--workers", type=int, default=1, help="processes for the tests (1)")
    parser.add_argument("--n-mc", type=int, default=199, help="Monte Carlo samples (199)")
    parser.add_argument("--n-boot", type=int, default=2000, help="bootstrap resamples (2000)")
    parser.add_argument(
        "--fits", type=int, default=12, help="ICs per radius with their own renewal fits (12)"
    )
    parser.add_argument(
        "--readme", default=None,
        help="also replace the block between <!-- results:begin --> and <!-- results:end --> "
        "of this file (the repository's README.md) by the page's first screen")
    parser.add_argument(
        "--screen-only", action="store_true",
        help="only rewrite the first screen of OUT/README.md from the findings tables beside "
        "it (no store is read; the stores argument is ignored)")
    args = parser.parse_args(argv)
    if not args.stores and not args.screen_only:
        parser.error("give the result stores, or --screen-only")
    from kicktimes.report import write_results

    if args.screen_only:
        from kicktimes.report.results import copy_first_screen, refresh_first_screen

        path = refresh_first_screen(args.out)
        print(f"{path}: first screen rewritten")
        if args.readme:
            copy_first_screen(path, args.readme)
        return 0

    t0 = time.perf_counter()
    try:
        path = write_results(
            args.stores,
            args.out,
            command="python analysis/make_results.py",
            dpi=args.dpi,
            workers=args.workers,
            n_mc=args.n_mc,
            n_boot=args.n_boot,
            max_ics_model_fits=args.fits,
        )
    except (ValueError, TypeError) as exc:
        parser.exit(2, f"error: {exc}\n")
    print(f"{path} written in {time.perf_counter() - t0:.0f} s")
    if args.readme:
        from kicktimes.report.results import copy_first_screen

        copy_first_screen(path, args.readme)
        print(f"{args.readme}: its results block replaced")
    return 0


if __name__ == "__main__":
    sys.exit(main())
