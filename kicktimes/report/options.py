"""Option groups of `kicktimes.report.build_report`: what its figures look like (`Render`)
and how far its fits and tests subsample a large store (`Subsampling`)."""

from __future__ import annotations

from dataclasses import dataclass

from kicktimes._results import Result
from kicktimes.validation import check_int

__all__ = ["Render", "Subsampling"]


@dataclass(frozen=True, repr=False)
class Render(Result):
    """How `build_report` writes its figures.

    Parameters
    ----------
    dpi : int
        Resolution of the PNG files (``>= 30``).
    pdf : bool
        Also write a PDF of every figure (the page embeds the PNGs; default False).

    Examples
    --------
    >>> from kicktimes.report import Render
    >>> Render(dpi=110, pdf=True)
    Render(dpi=110, pdf=True)
    """

    _title = 'Figure options of build_report'

    dpi: int = 150
    pdf: bool = False

    def __post_init__(self):
        object.__setattr__(self, "dpi", check_int("dpi", self.dpi, low=30))
        if not isinstance(self.pdf, bool):
            raise TypeError(f"pdf must be True or False, got {type(self.pdf).__name__}")


@dataclass(frozen=True, repr=False)
class Subsampling(Result):
    """How far `build_report`'s tests and fits subsample a store (every subsampling is
    listed in the report).

    Parameters
    ----------
    max_ics_tests : int, optional
        Use only the first ``max_ics_tests`` ICs (by index) per radius in the Poisson
        tests (``>= 2``; default: all).
    max_ics_model_fits : int
        ICs (first by index) per radius whose intervals get a per-IC renewal-model
        comparison (6 censored fits each, ~0.4 s per IC; ``>= 1``).
    max_pooled_intervals : int
        Interval budget of the pooled fits per radius (whole ICs in index order; ``>= 100``).

    Examples
    --------
    >>> from kicktimes.report import Subsampling
    >>> Subsampling(max_ics_model_fits=2)
    Subsampling(max_ics_tests=None, max_ics_model_fits=2, max_pooled_intervals=200000)
    """

    _title = 'Subsampling options of build_report'

    max_ics_tests: int | None = None
    max_ics_model_fits: int = 12
    max_pooled_intervals: int = 200_000

    def __post_init__(self):
        if self.max_ics_tests is not None:
            object.__setattr__(self, "max_ics_tests",
                               check_int("max_ics_tests", self.max_ics_tests, low=2))
        object.__setattr__(self, "max_ics_model_fits",
                           check_int("max_ics_model_fits", self.max_ics_model_fits, low=1))
        object.__setattr__(self, "max_pooled_intervals",
                           check_int("max_pooled_intervals", self.max_pooled_intervals,
                                     low=100))
