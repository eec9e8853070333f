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
>>> list(STUDIES)[:3]
['paper', 'protocol', 'science']
>>> STUDIES["protocol"].page
'paper.md'
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["STUDIES", "Study", "studies_help"]


@dataclass(frozen=True)
class Study:
    """A registered study: its name (``--study NAME``), the page it writes into
    ``--results``, one line for ``kicktimes reproduce --help``, and the names of the
    other studies whose stores or tables it reads (``needs``; ``--study all`` runs those
    first: the protocol study's count claims come from the paper study's
    ``family_*_findings.csv`` in the same ``--results`` folder).

    Its package ``kicktimes.studies.<name>`` provides ``reproduce(out, *, scale,
    results_dir, workers, progress, command)``, which runs (or resumes, from ``out``) its
    computation and writes its page into ``results_dir``; it returns the page's path.
    """

    name: str
    page: str
    summary: str
    needs: tuple[str, ...] = ()
    #: the keyword arguments its ``reproduce`` takes beyond the common ones (``scale,
    #: results_dir, workers, progress, command``): ``findings_dir``, ``scheduler``,
    #: ``content``, ``wait``, ``pdf``; the command line refuses the others' options
    options: tuple[str, ...] = ()
    #: whether ``--results`` is part of its command (the paper study writes its page only
    #: when given one; the others write theirs always, by default in ``out``)
    results_in_command: bool = False

    @property
    def module(self) -> str:
        """The study's package, ``kicktimes.studies.<name>``."""
        return f"{__name__}.{self.name}"

    def command(self, scale: str, results_dir=None) -> str:
        """The command its page's "Generated" line names by default.

        >>> STUDIES["escape"].command("paper", "docs/results")
        'kicktimes reproduce --study escape --scale paper'
        """
        text = f"kicktimes reproduce --study {self.name} --scale {scale}"
        if self.results_in_command and results_dir is not None:
            text += f" --results {results_dir}"
        return text

    def reproduce(self, out, **options):
        """Import the study's package and run its ``reproduce(out, **options)``."""
        import importlib

        return importlib.import_module(self.module).reproduce(out, **options)


STUDIES = {
    s.name: s
    for s in (
        Study("paper", "README.md",
              "the paper's two families under every control; the sweep report",
              options=("content", "scheduler", "wait", "pdf"), results_in_command=True),
        Study("protocol", "paper.md",
              "the paper's claims by its own protocol (eq. (4), Fig. 6, RR, R_1)",
              needs=("paper",), options=("findings_dir",)),
        Study("science", "science.md",
              "stretching and decorrelation per kick, the rate over the run, sticky orbits",
              needs=("paper",), options=("findings_dir",)),
        Study("mechanism", "mechanism.md",
              "why the collision times are not Poisson, under both collision rules"),
        Study("escape", "escape.md",
              "escape through a hole: kicked disk against two disks"),
        Study("unequal", "unequal.md",
              "unequal disks: collision times and kicked FTLE against the size ratio"),
        Study("scatter", "scatter.md",
              "scatter kicks against two disks: the FTLE per IC"),
        Study("mmpp", "mmpp.md",
              "MMPP fits to the two-disk collision times"),
        Study("disks", "disks.md",
              "a tagged disk among N = 2..1000 disks: Poisson or not, Enskog, kicked",
              options=("scheduler",)),
        Study("small_r", "small_r.md",
              "the premise at its limit r -> 0: low-density theory and FTLE to r = 1e-4",
              options=("scheduler",)),
        Study("tables", "tables.md",
              "the paper's comparison in the circle, the ellipse and the stadium",
              options=("scheduler",)),
        Study("eos", "eos.md",
              "the N-disk engine's equation of state against the literature, 0.05-0.68"),
    )
}


def studies_help() -> str:
    """One line per study, ``NAME  PAGE  summary``, for ``kicktimes reproduce --help``."""
    return "\n".join(f"  {s.name:<11}{s.page:<14}{s.summary}" for s in STUDIES.values())
