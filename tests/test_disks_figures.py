"""The disks study's figures (kicktimes.studies.disks.figures): nothing leaves an axis
unmarked."""

import numpy as np
import pandas as pd

from kicktimes.studies.disks.figures import ZOOM_LIMITS, ZOOM_MIN_N, hazard_figure


def _table_and_hazard(values):
    edges = np.array([0.0, 0.01, 0.1, 1.0, 5.0])
    rows = [{"experiment": "e", "rule": "mirror", "n_disks": n, "t_low": a, "t_high": b,
             "hazard": v, "ci_low": v - 0.02, "ci_high": v + d}
            for n in (10, 100) for a, b, v, d in zip(edges[:-1], edges[1:], values,
                                                      (0.02, 0.02, 0.4, 0.02), strict=True)]
    table = pd.DataFrame({"experiment": ["e"], "rule": ["mirror"], "geometry": ["packing 0.02"]})
    return pd.DataFrame(rows), table


def test_hazard_bins_beyond_the_zoom_are_marked_at_the_edge_with_their_value():
    # bin 2 (1.6) leaves the zoomed axis; bin 3 (1.0) stays but its band reaches 1.4
    hazard, table = _table_and_hazard([1.0, 1.6, 1.0, 1.0])
    fig = hazard_figure(hazard, table, n_shown=(10, 100))
    zoomed = fig.axes[1]
    assert zoomed.get_ylim() == ZOOM_LIMITS and ZOOM_MIN_N <= 10
    assert sorted(t.get_text() for t in zoomed.texts) == ["1.6", "1.6"]  # one per N
    edge = [line for line in zoomed.get_lines() if not line.get_clip_on()]
    filled = [line for line in edge if line.get_markerfacecolor() != "none"]
    assert len(edge) == 4 and len(filled) == 2  # two open: the band alone leaves
    assert not fig.axes[0].texts  # within the full row's limits: nothing marked
    import matplotlib.pyplot as plt

    plt.close(fig)



def test_every_control_of_the_page_has_a_style_in_the_controls_figure():
    from kicktimes.studies.disks.controls import CONTROL_NAMES
    from kicktimes.studies.disks.figures import CONTROL_STYLES

    assert set(CONTROL_NAMES) <= set(CONTROL_STYLES)
