"""The studies: one package per results page, each built by ``kicktimes reproduce --study NAME``.

A study holds its computation (or the presets it sweeps), its tables as DataFrames and its
page writer, and nothing else; what every study shares (the verdict rules of
`kicktimes.stats`, the Markdown and figure helpers and the store loading of
`kicktimes.report`) stays below it. `STUDIES` registers them: the command line's
``--study`` choices and their help come from it.

Adding a study is one folder and one entry here (docs/architecture.md, "Add a study").

Examples
--------
>>> from kicktimes.studies import STUDIES
>>> sorted(STUDIES)
['disks', 'paper', 'protocol']
>>> STUDIES["protocol"].page
'paper.md'
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["STUDIES", "Study"]


@dataclass(frozen=True)
class Study:
    """A registered study: its name (``--study NAME``), the page it writes into
    ``--results`` and one line for ``kicktimes reproduce --help``."""

    name: str
    page: str
    summary: str


STUDIES = {
    s.name: s
    for s in (
        Study("paper", "README.md",
              "the paper's two families and their controls, the sweep report, and with "
              "--results the page README.md"),
        Study("protocol", "paper.md",
              "the paper's claims by its own protocol: every reading of its eq. (4) on both "
              "panels of Fig. 6, its RR and R_1, claim by claim"),
        Study("disks", "disks.md",
              "the tagged disk among N = 2..1000 disks: Poisson or not, Enskog's rate, the "
              "kicked comparison"),
    )
}
