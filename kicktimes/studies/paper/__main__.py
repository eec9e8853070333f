"""``python -m kicktimes.studies.paper RESULTS --readme README.md``: copy the first screen
of ``RESULTS/README.md`` (which ``kicktimes reproduce --study paper --results RESULTS``
writes, in one command) into the block between ``<!-- results:begin -->`` and
``<!-- results:end -->`` of the repository's README. ``RESULTS/README.md`` itself is not
touched."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from kicktimes.studies.paper import copy_first_screen


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m kicktimes.studies.paper",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("results", help="the folder of the page README.md (docs/results)")
    parser.add_argument("--readme", required=True,
                        help="the file whose results block receives the first screen")
    args = parser.parse_args(argv)
    try:
        copy_first_screen(Path(args.results) / "README.md", args.readme)
        print(f"{args.readme}: its results block replaced")
    except (OSError, ValueError) as exc:
        parser.exit(2, f"error: {exc}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
