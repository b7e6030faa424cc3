"""Fig. 7 (AP vs ratio): what it draws, within AP's range, and the PNG a person looks at."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.experiments.ap.figures import AP_RANGE, draw_ap_vs_ratio, ratio_panels
from graspaug.plots import DPI
from tests.test_plots import blank_below_title


def _table(augmented: bool = True, ceiling: bool = False) -> pd.DataFrame:
    """A network table like the default run's: B = 50 augmented at R = 1 (wide intervals of 2 seeds, one running
    past 0 and 1), B = 200 alone at R = 0 (the positive control)."""
    rows = [{"pool": "targeted", "base_size": 50, "ratio": 0.0, "test_ap": 0.55, "test_ap_ci": 0.9}]
    if augmented:
        for pool, ap in (("targeted", 0.6), ("random", 0.58), ("real", 0.9), ("recon", 0.1)):
            rows.append({"pool": pool, "base_size": 50, "ratio": 1.0, "test_ap": ap, "test_ap_ci": 0.25})
    rows.append({"pool": "targeted", "base_size": 200, "ratio": 0.0, "test_ap": 0.7, "test_ap_ci": 0.05})
    if ceiling:
        rows.append({"pool": "ceiling", "base_size": 0, "ratio": 0.0, "test_ap": 0.8, "test_ap_ci": np.nan})
    return pd.DataFrame(rows)


def _drawn(figure: dict) -> np.ndarray:
    """Every AP value the figure draws: points, interval ends, reference lines and bands."""
    values = [v for p in figure["panels"] for c in p["curves"] for k in ("ap", "low", "high") for v in c[k]]
    values += [r[k] for p in figure["panels"] for r in p["references"] for k in ("ap", "low", "high")]
    return np.array(values)


def test_ap_axis_and_intervals_stay_within_zero_and_one():
    """The default run's AP axis ran from -0.6 to 0.85 (issue #62, 8)."""
    for table in (_table(), _table(augmented=False), _table(ceiling=True)):
        figure = ratio_panels(table)
        low, high = figure["ylim"]
        drawn = _drawn(figure)
        assert AP_RANGE[0] <= low < high <= AP_RANGE[1]
        assert ((drawn >= AP_RANGE[0]) & (drawn <= AP_RANGE[1])).all()
        assert low <= drawn.min() and drawn.max() <= high  # nothing drawn falls off the axis
    curve = ratio_panels(_table())["panels"][0]["curves"][0]
    assert curve["low"][0] == 0.0 and curve["high"][0] == 1.0  # 0.55 ± 0.9, clipped at both ends


def test_a_base_size_alone_is_a_reference_not_a_panel():
    """B = 200 at R = 0 only was a panel of one point on an x axis from -0.04 to 0.04 (issue #62, 14)."""
    figure = ratio_panels(_table(ceiling=True))
    (panel,) = figure["panels"]
    assert panel["title"] == "B = 50"
    assert [c["pool"] for c in panel["curves"]] == ["targeted", "random", "real", "recon"]
    assert all(list(c["x"]) == [0.0, 1.0] for c in panel["curves"])
    refs = {r["label"]: r for r in panel["references"]}
    assert set(refs) == {"B = 200 alone (R = 0)", "ceiling (all train shapes)"}
    assert np.isclose(refs["B = 200 alone (R = 0)"]["ap"], 0.7) and np.isclose(
        refs["B = 200 alone (R = 0)"]["low"], 0.65
    )
    # no augmented base size at all: one panel whose x axis is the base size
    (alone,) = ratio_panels(_table(augmented=False))["panels"]
    assert alone["xlabel"].startswith("base set size") and list(alone["curves"][0]["x"]) == [50.0, 200.0]


def test_the_ap_figure_is_drawn(tmp_path):
    for name, table in (("ap.png", _table(ceiling=True)), ("alone.png", _table(augmented=False))):
        path = tmp_path / name
        draw_ap_vs_ratio(table, [0, 1], path)
        assert path.stat().st_size > 10_000
        assert blank_below_title(path) < 0.3 * DPI
