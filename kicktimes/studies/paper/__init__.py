"""The paper study: Ranković & Porter's two families under every control, and its page.

``kicktimes reproduce --study paper --scale paper --out OUT --results docs/results``
(:func:`reproduce`) runs
the presets of `SCALES` (`presets.py`) (both families and the 2 x 2 design of
collision rule x initial conditions, `kicktimes.experiment.CONTROL_PRESETS`) into
``OUT/store-<name>``, builds the sweep report (:mod:`kicktimes.report`) into ``OUT/report``
and writes the page ``README.md`` with :func:`write_results`: the answers first (each
comparison under its controls, :mod:`kicktimes.report.answers`), the headline figure, the
findings tables ``<family>_findings.csv`` and the gap decomposition.

:func:`write_results` is the page's only writer, in one command: its first screen points
to the protocol study's page (``PROTOCOL_POINTER``) without quoting its numbers, so the
study needs no other (the protocol study reads this one's findings tables and runs after
it). :func:`copy_first_screen` copies the first screen into the repository's
README (``python -m kicktimes.studies.paper docs/results --readme README.md``).

Examples
--------
>>> from kicktimes.studies.paper import copy_first_screen, write_results
>>> callable(write_results) and callable(copy_first_screen)
True
"""

from __future__ import annotations

from kicktimes.studies.paper.page import (
    BEGIN,
    END,
    PROTOCOL_POINTER,
    copy_first_screen,
    write_results,
)
from kicktimes.studies.paper.presets import SCALES, scale_presets
from kicktimes.studies.paper.run import reproduce

__all__ = ["BEGIN", "END", "PROTOCOL_POINTER", "SCALES", "copy_first_screen", "reproduce",
           "scale_presets", "write_results"]
