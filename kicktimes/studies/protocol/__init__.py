"""The paper's claims by its own protocol (``kicktimes reproduce --study protocol``).

Ranković & Porter's eq. (4) admits several readings (`compute.CHOICES`); this study
computes the paper's three systems on both panels of its Fig. 6 under each, decomposes
the kicked/two-disk FTLE ratio by choice (Shapley shares), checks convergence at
``T .. 8T``, and writes ``paper.md``: each claim of the paper, its reproduction by the
paper's protocol, the verdict, and the choice that decides it.

Examples
--------
>>> from kicktimes.studies.protocol import panels
>>> [p.figure for p in panels("paper")]
['Fig. 6 top', 'Fig. 6 bottom']
"""

from __future__ import annotations

import os
from pathlib import Path

from kicktimes.studies.options import check_workers
from kicktimes.studies.protocol.compute import CHOICES, panels, run_rows
from kicktimes.studies.protocol.page import build_page, fig6_figure
from kicktimes.studies.protocol.run import load_rows, run_protocol_study
from kicktimes.studies.protocol.tables import Ratios, per_radius_table, ratio_table

__all__ = ["CHOICES", "Ratios", "build_page", "fig6_figure", "load_rows", "panels",
           "per_radius_table", "ratio_table", "reproduce", "run_rows",
           "run_protocol_study"]


def reproduce(out: str | os.PathLike, *, scale: str = "quick",
              results_dir: str | os.PathLike | None = None, workers: int | None = None,
              progress=None, command: str | None = None,
              findings_dir: str | os.PathLike | None = None) -> Path:
    """Run (or resume) the study into ``out/store-protocol[-quick]`` and write ``paper.md``.

    ``results_dir``: the page's folder (default ``out/results-protocol``); ``findings_dir``:
    the paper study's findings tables at the paper's scale (``family_a_findings.csv``,
    ``family_b_findings.csv``, e.g. ``docs/results``), which give the count claims; default
    ``results_dir`` if it holds them, else none (the page then leaves the counts out).
    """
    names = [f"{p.name}_findings.csv" for p in panels(scale)]  # (refuses an unknown scale)
    if workers is not None:
        workers = check_workers(workers)
    out = Path(out)
    store = out / ("store-protocol" if scale == "paper" else f"store-protocol-{scale}")
    results = Path(results_dir) if results_dir is not None else out / "results-protocol"
    if findings_dir is not None:
        findings = Path(findings_dir)
        missing = [n for n in names if not (findings / n).exists()]
        if missing:
            raise FileNotFoundError(
                f"findings_dir: {findings / missing[0]} is missing; the count claims come "
                "from the paper study's findings at the paper's scale "
                "(docs/results holds them)")
    else:
        findings = results if all((results / n).exists() for n in names) else None
    rows = run_protocol_study(store, scale, workers=workers, progress=progress)
    command = command or f"kicktimes reproduce --study protocol --scale {scale}"
    return build_page(rows, results, findings, command=command, scale=scale,
                      store=store.name)
