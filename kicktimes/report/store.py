"""The sweep store as the report reads it: the reference system and the kicked ones, the
paper's scale, the thresholds, the results in their categorical form, the wide tables
of one diagnostic and the store's header on the page."""

from __future__ import annotations

import html
import os
from pathlib import Path

import numpy as np

from kicktimes import __version__
from kicktimes.render.html import table_html

__all__ = ["PAPER_SCALE", "REFERENCE", "distinct", "eps_values", "is_paper_scale",
           "kicked_systems", "load_report_store", "nearest", "report_store", "store_header",
           "wide"]

#: the reference system every other ("kicked") system is compared with
REFERENCE = "two_particle"
#: ICs and steps of the paper's smaller family (A): below this a report is a smoke test
PAPER_SCALE = {"n_ics": 200, "n_steps": 15000}


def nearest(radii, target):
    """The radius of ``radii`` closest to ``target``."""
    radii = np.asarray(radii, dtype=float)
    return float(radii[np.argmin(np.abs(radii - target))])


def kicked_systems(results):
    """Every system of the store except the reference, in a stable order."""
    from kicktimes.render.figures import SYSTEMS

    present = set(results["system"].unique())
    known = [s for s in SYSTEMS if s in present and s != REFERENCE]
    return known + sorted(present - set(SYSTEMS))


def is_paper_scale(exp):
    return exp.n_ics >= PAPER_SCALE["n_ics"] and exp.n_steps >= PAPER_SCALE["n_steps"]


def eps_values(exp):
    """The experiment's recurrence thresholds as a tuple (old stores: one float)."""
    eps = exp.eps
    return tuple(float(e) for e in eps) if isinstance(eps, list | tuple) else (float(eps),)


def report_store(store):
    """The store as the report reads it: ``results`` with ``system`` and ``diagnostic`` as
    categoricals (sorted categories) and without the ``note`` column no section reads.

    The sections filter the results by system and diagnostic dozens of times, and ask
    which are present (``set(results["diagnostic"])``); on Arrow strings each filter copies
    every string and each ``set`` iterates the rows in Python (~1 s per call on a paper
    store's 2 million rows); on categoricals both work on integer codes. Groupings and
    sort orders are unchanged (sorted categories sort as the strings; groupby keeps the
    observed groups only), and so is every table written.
    """
    import copy
    import dataclasses

    import pandas as pd

    res = store.results
    if isinstance(res["diagnostic"].dtype, pd.CategoricalDtype):
        return store
    res = res.drop(columns=[c for c in ("note",) if c in res.columns])
    res = res.astype({"system": "category", "diagnostic": "category"})
    if dataclasses.is_dataclass(store):
        return dataclasses.replace(store, results=res)
    view = copy.copy(store)  # a store-like namespace (tests, notebooks)
    view.results = res
    return view


def load_report_store(path):
    """``report_store(load_store(path))``, read straight into that form: the results
    without ``note``, ``system`` and ``diagnostic`` read from Parquet as dictionaries
    (categoricals, then their categories sorted), never as 2 million strings. The same
    frames (a test compares them), read faster
    (``python benchmarks/bench_report.py --load-only --stores ...``; docs/benchmarks.md).
    """
    from kicktimes.experiment import load_store

    columns = ["radius", "ic", "system", "diagnostic", "value"]
    return load_store(path, result_columns=columns, categories=("system", "diagnostic"))


def distinct(frame, column):
    """The distinct values of ``frame[column]`` as a set (fast on categoricals: only the
    observed values, not the categories)."""
    return set(frame[column].unique())


def wide(results, diagnostic):
    """``value`` of one diagnostic as a (radius, ic) x system table."""
    part = results[results["diagnostic"] == diagnostic]
    return part.pivot_table(index=["radius", "ic"], columns="system", values="value", dropna=False,
                            observed=True)


def store_header(store, notes):
    """Metadata of one store and its experiment: (HTML, parameter table)."""
    import pandas as pd

    exp = store.experiment
    man = store.manifest
    # unequal disks (docs/unequal.md): the partner, and the pair the ICs are drawn at
    partner = exp.partner_line() if hasattr(exp, "partner_line") else ""
    ic_at = exp.ic_radius_label() if hasattr(exp, "ic_radius_label") else f"{exp.r_max:g}"
    meta = [
        ("experiment", f"{exp.name} (hash {man.get('experiment_hash', exp.hash())})"),
        ("description", exp.description or "—"),
        ("seed", str(exp.seed)),
        ("rule", exp.rule),
        *([("disks", partner)] if partner else []),
        ("IC method", f"{exp.ic_method}, {exp.n_ics} ICs drawn at r_max = {ic_at}"),
        ("steps", f"{exp.n_steps} steps of τ = {exp.tau:g} ({exp.sampling} sampling)"),
        ("kicktimes version (store)", str(man.get("kicktimes_version", "unknown"))),
        ("kicktimes version (report)", __version__),
        ("store", os.fspath(Path(store.path).resolve())),
        ("store created / updated", f"{man.get('created', '?')} / {man.get('updated', '?')}"),
        ("tasks", f"{len(exp.tasks()) - len(store.missing_tasks)}/{len(exp.tasks())} finished"),
    ]
    rows = "".join(
        f"<tr><td><b>{html.escape(k)}</b></td><td>{html.escape(v)}</td></tr>" for k, v in meta
    )
    params = pd.DataFrame(
        [
            (k, ", ".join(map(str, v)) if isinstance(v, list | tuple) else str(v))
            for k, v in exp.to_dict().items()
        ],
        columns=["parameter", "value"],
    )
    parts = [f'<table class="meta">{rows}</table>']
    if store.missing_tasks:
        parts.append(
            f'<p class="note">The store is unfinished: {len(store.missing_tasks)} tasks '
            "are missing; every number below uses the finished tasks only.</p>"
        )
    if notes:
        items = "".join(f"<li>{html.escape(n)}</li>" for n in notes)
        parts.append(f'<div class="note"><b>Subsampling (deterministic):</b><ul>{items}</ul></div>')
    parts.append("<h3>Parameters</h3>" + table_html(params))
    return "\n".join(parts), params
