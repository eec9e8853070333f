"""``python -m kicktimes.studies.paper RESULTS [--readme README.md]``: rewrite the first
screen of ``RESULTS/README.md`` from the findings tables beside it (no store is read;
for instance after the protocol study's ``paper_findings.csv`` changed) and, with
``--readme``, replace that file's block between ``<!-- results:begin -->`` and
``<!-- results:end -->`` by it."""

from __future__ import annotations

import argparse
import sys

from kicktimes.studies.paper import copy_first_screen, refresh_first_screen


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m kicktimes.studies.paper",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("results", help="the folder of the page README.md (docs/results)")
    parser.add_argument("--readme", help="also replace this file's results block")
    args = parser.parse_args(argv)
    try:
        page = refresh_first_screen(args.results)
        print(f"{page}: first screen rewritten")
        if args.readme:
            copy_first_screen(page, args.readme)
            print(f"{args.readme}: its results block replaced")
    except (OSError, ValueError) as exc:
        parser.exit(2, f"error: {exc}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
