"""Rebuild every generated science page of docs/results, one script after another.

After ``kicktimes reproduce --scale paper --out paper/`` and ``analysis/make_results.py``
(whose findings tables science.md reads)::

    python analysis/make_science.py --paper paper --work paper/science

runs, in order (each writes its page with its "Generated ..." line, its tables and its
figures under ``docs/results``):

* ``science.py`` (science.md) from the stores ``family_a`` and ``family_b``;
* ``mechanism.py`` under the mirror and the elastic rule, then ``mechanism_page.py``
  (mechanism.md);
* ``escape.py`` (escape.md);
* ``size_ratio.py`` (unequal.md), ``scatter_ftle.py`` (scatter.md),
  ``mmpp_billiard.py`` (mmpp.md).

``--reuse`` keeps what is expensive and already there: science.py's cached simulations
in ``--work``, size_ratio's and scatter_ftle's CSVs (the statistics and pages are
recomputed from them). Each step's wall time is printed; a failing step stops the rest.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def steps(paper, work, workers, reuse):
    """(name, argv) of every script to run, in order."""
    py = [sys.executable]
    science = [*py, str(HERE / "science.py"), str(Path(paper) / "store-family_a"),
               str(Path(paper) / "store-family_b"), "--out", "docs/results", "--work", work,
               "--workers", str(workers)] + (["--reuse"] if reuse else [])
    return [
        ("science.md", science),
        ("mechanism, mirror", [*py, str(HERE / "mechanism.py"), "--rule", "mirror",
                               "--out", "docs/results/mechanism", "--workers", str(workers)]),
        ("mechanism, elastic", [*py, str(HERE / "mechanism.py"), "--rule", "elastic",
                                "--out", "docs/results/mechanism/elastic",
                                "--workers", str(workers)]),
        ("mechanism.md", [*py, str(HERE / "mechanism_page.py"), "docs/results/mechanism",
                          "docs/results/mechanism/elastic", "--out",
                          "docs/results/mechanism.md"]),
        ("escape.md", [*py, str(HERE / "escape.py"), "--out", "docs/results/escape"]),
        ("unequal.md", [*py, str(HERE / "size_ratio.py")] + (["--page-only"] if reuse else [])),
        ("scatter.md", [*py, str(HERE / "scatter_ftle.py")]
         + (["--from-csv", "analysis/scatter_ftle.csv"] if reuse else
            ["--workers", str(workers)])),
        ("mmpp.md", [*py, str(HERE / "mmpp_billiard.py")]),
    ]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--paper", default="paper", help="folder of the paper-scale stores")
    ap.add_argument("--work", default="paper/science", help="work folder of science.py")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--reuse", action="store_true",
                    help="recompute statistics from the cached simulations and CSVs")
    ap.add_argument("--only", nargs="*", help="run only these steps (names as printed)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    for name, cmd in steps(args.paper, args.work, args.workers, args.reuse):
        if args.only and name not in args.only:
            continue
        t = time.perf_counter()
        print(f"== {name}", flush=True)
        done = subprocess.run(cmd, check=False)
        if done.returncode:
            print(f"{name} failed (exit {done.returncode})", file=sys.stderr)
            return done.returncode
        print(f"== {name}: {time.perf_counter() - t:.0f} s", flush=True)
    print(f"all pages in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
