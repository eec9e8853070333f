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
    # the log rows (mirror, elastic) on top, the linear rows below: mirror's zoom is row 3
    full, zoomed = fig.axes[0], fig.axes[2]
    assert full.get_yscale() == "log" and "log y" in full.get_title()
    assert zoomed.get_yscale() == "linear" and "linear y" in zoomed.get_title()
    assert zoomed.get_ylim() == ZOOM_LIMITS and ZOOM_MIN_N <= 10
    assert sorted(t.get_text() for t in zoomed.texts) == ["1.6", "1.6"]  # one per N
    edge = [line for line in zoomed.get_lines() if not line.get_clip_on()]
    filled = [line for line in edge if line.get_markerfacecolor() != "none"]
    assert len(edge) == 4 and len(filled) == 2  # two open: the band alone leaves
    assert not full.texts  # within the full row's limits: nothing marked
    # the two labels of one bin are stacked, not printed on one another
    assert len({tuple(t.xy) for t in zoomed.texts}) == 1  # one anchor, the bin's edge
    offsets = sorted(t.xyann[1] for t in zoomed.texts)
    assert offsets[1] - offsets[0] >= 8
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_the_rates_figure_names_each_boltzmann_level_and_no_dip():
    import matplotlib.pyplot as plt

    from kicktimes.studies.disks.figures import rates_figure

    rows = []
    for rule in ("mirror", "elastic"):
        for n in (10, 100):
            row = {"experiment": f"e-{rule}", "geometry": "packing 0.02", "rule": rule,
                   "n_disks": n}
            for key in ("rate_enskog", "dispersion", "hazard_first"):
                row.update({key: 1.0, f"{key}_low": 0.9, f"{key}_high": 1.1})
            rows.append(row)
    fig = rates_figure(pd.DataFrame(rows), boltzmann={"dispersion": 1.14,
                                                       "hazard_first": 1.06})
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    boltz = [lab for lab in labels if lab.startswith("linear Boltzmann")]
    assert len(boltz) == len(set(boltz)) == 2
    assert any("D∞" in lab for lab in boltz) and any("h(0.005)" in lab for lab in boltz)
    assert not any("dip" in ax.get_title() for ax in fig.axes)
    plt.close(fig)



def test_every_control_of_the_page_has_a_style_in_the_controls_figure():
    from kicktimes.studies.disks.controls import CONTROL_NAMES
    from kicktimes.studies.disks.figures import CONTROL_STYLES

    assert set(CONTROL_NAMES) <= set(CONTROL_STYLES)
