"""The paper study: Ranković & Porter's two families under every control, and its page.

``kicktimes reproduce --study paper --scale paper --out OUT --results docs/results`` runs
the presets of `kicktimes.experiment.SCALES` (both families and the 2 x 2 design of
collision rule x initial conditions, `kicktimes.experiment.CONTROL_PRESETS`) into
``OUT/store-<name>``, builds the sweep report (:mod:`kicktimes.report`) into ``OUT/report``
and writes the page ``README.md`` with :func:`write_results`: the answers first (each
comparison under its controls, :mod:`kicktimes.report.answers`), the headline figure, the
findings tables ``<family>_findings.csv`` and the gap decomposition.

:func:`refresh_first_screen` rewrites the page's first screen from the findings tables
beside it (no store read), for instance after the protocol study's ``paper_findings.csv``
changed; :func:`copy_first_screen` copies it into the repository's README.

Examples
--------
>>> from kicktimes.studies.paper import write_results, refresh_first_screen
>>> callable(write_results) and callable(refresh_first_screen)
True
"""

from __future__ import annotations

from kicktimes.studies.paper.page import (
    BEGIN,
    END,
    copy_first_screen,
    paper_protocol_sentence,
    refresh_first_screen,
    write_results,
)

__all__ = ["BEGIN", "END", "copy_first_screen", "paper_protocol_sentence",
           "refresh_first_screen", "write_results"]
