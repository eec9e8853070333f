"""What the paper study runs at each scale: its experiments, by preset name.

The experiments themselves (`kicktimes.experiment.preset`: family A and B, their quick
versions and the 2 x 2 controls of each) stay in the experiment layer, where
``kicktimes run NAME`` and ``kicktimes presets NAME`` read them and the protocol and
science studies run the same families; which of them make the paper study, at which
scale and content, is the study's own.
"""

from __future__ import annotations

from kicktimes.experiment.presets import CONTROL_PRESETS

__all__ = ["SCALES", "scale_presets"]

#: The experiments ``kicktimes reproduce --study paper --scale`` runs (with ``--content
#: paper``, the paper's own content, the control experiments of `CONTROL_PRESETS` are
#: left out).
SCALES = {
    "paper": ("family_a", "family_b", *CONTROL_PRESETS),
    "quick": ("quick_a", "quick_b"),
}


def scale_presets(scale: str, content: str = "full") -> tuple:
    """The preset names ``kicktimes reproduce --scale <scale> --content <content>`` runs.

    >>> scale_presets("paper", "paper")
    ('family_a', 'family_b')
    """
    names = SCALES[scale]
    return tuple(n for n in names if n not in CONTROL_PRESETS) if content == "paper" else names
