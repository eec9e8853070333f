"""From two disks to a gas (issue 42): run the disks sweeps and write docs/results/disks.md.

::

    python analysis/make_disks.py --stores stores-disks --out docs/results

runs (or resumes) every preset of ``kicktimes.experiment.DISKS_PRESETS``, their controls
``DISKS_CONTROLS`` and the two-disk references ``DISKS_REFERENCES`` into
``STORES/store-<name>`` on one worker, then writes ``OUT/disks.md``, its CSV tables and
figures (:func:`kicktimes.report.disks_page.reproduce_disks`). The same as
``kicktimes reproduce --study disks --out STORES --results OUT``.
"""

from __future__ import annotations

import argparse


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stores", default="stores-disks", help="folder of the stores")
    parser.add_argument("--out", default="docs/results", help="folder of the page")
    parser.add_argument("--workers", type=int, default=1, help="local processes (1)")
    parser.add_argument("--only", nargs="*", default=None, help="these presets only")
    args = parser.parse_args(argv)
    from kicktimes.report.disks_page import reproduce_disks

    page = reproduce_disks(args.stores, results_dir=args.out, names=args.only,
                           workers=args.workers,
                           command="python analysis/make_disks.py")
    print(f"written {page}")


if __name__ == "__main__":
    main()
