"""Image grasps: the canonical angle, the jaw endpoints and Dex-Net's feature vector."""

from __future__ import annotations

import numpy as np

from graspaug.planning.grasps import (
    ImageGrasps,
    canonical_angles,
    distinct_grasps,
    grasp_features,
    grasps_from_features,
    jaw_endpoints,
)
from graspaug.planning.planner import PlannedGrasp


def some_grasps() -> ImageGrasps:
    return ImageGrasps(
        centers=np.array([[300.0, 200.0], [100.5, 50.0], [320.25, 240.75]]),
        angles=np.array([0.3, -1.2, np.pi / 2]),
        depths=np.array([0.61, 0.63, 0.64]),
        widths=np.array([40.0, 22.0, 31.5]),
    )


def test_features_round_trip():
    grasps = some_grasps()
    back = grasps_from_features(grasp_features(grasps))
    for name in ("centers", "angles", "depths", "widths"):
        assert np.allclose(getattr(back, name), getattr(grasps, name))


def test_canonical_angles_fold_into_the_half_open_interval():
    angles = np.array([-np.pi / 2, np.pi / 2, np.pi, -3.0, 0.2, 2.0])
    folded = canonical_angles(angles)
    assert np.all((folded > -np.pi / 2) & (folded <= np.pi / 2))
    assert np.allclose(np.cos(2 * folded), np.cos(2 * angles))  # the same jaw line
    assert np.isclose(folded[0], np.pi / 2) and np.isclose(folded[2], 0.0)


def test_jaw_endpoints_straddle_the_center_along_the_jaw_axis():
    grasps = some_grasps()
    jaws = jaw_endpoints(grasps.centers, grasps.angles, grasps.widths)
    assert jaws.shape == (3, 2, 2)
    assert np.allclose(jaws.mean(axis=1), grasps.centers)
    assert np.allclose(np.linalg.norm(jaws[:, 1] - jaws[:, 0], axis=1), grasps.widths)
    axis = jaws[:, 1] - jaws[:, 0]
    assert np.allclose(np.arctan2(axis[:, 1], axis[:, 0]), grasps.angles)  # jaw 1 → jaw 2 along +angle
    assert np.array_equal(jaw_endpoints(np.zeros((0, 2)), np.zeros(0), np.zeros(0)), np.zeros((0, 2, 2)))


def test_jaw_endpoints_are_those_of_the_features_and_of_a_planned_grasp():
    """One computation: Dex-Net's feature vector and PlannedGrasp.jaw_pixels hold exactly these numbers."""
    grasps = some_grasps()
    jaws = jaw_endpoints(grasps.centers, grasps.angles, grasps.widths)
    features = grasp_features(grasps)
    assert np.array_equal(features[:, 0:2], jaws[:, 0]) and np.array_equal(features[:, 2:4], jaws[:, 1])
    for i in range(len(grasps)):
        (u, v), angle, width = grasps.centers[i], float(grasps.angles[i]), float(grasps.widths[i])
        planned = PlannedGrasp(
            float(u), float(v), angle, float(grasps.depths[i]), width, np.zeros(3), np.eye(3), 0.05, 0.5, 0.1, 10
        )
        assert np.array_equal(planned.jaw_pixels, jaws[i])
        row = planned.grasp
        assert np.array_equal(jaw_endpoints(row.centers, row.angles, row.widths)[0], jaws[i])


def test_distinct_grasps_drops_near_duplicates_of_better_grasps():
    """Non-maximum suppression: a grasp goes when its center lies within a quarter of a kept
    better grasp's opening (at least 4 px) and its jaw line within 15° of that grasp's (mod 180°)."""
    ranked = ImageGrasps(
        centers=np.array(
            [[100, 100], [103, 100], [103, 100], [120, 100], [100, 102], [101, 100], [200, 50], [203.5, 50]]
        ),
        angles=np.array([0.0, np.radians(10), np.pi / 2, 0.0, np.pi - np.radians(3), 0.0, 1.0, 1.0]),
        depths=np.full(8, 0.65),
        widths=np.array([40.0, 40.0, 40.0, 40.0, 40.0, 8.0, 8.0, 8.0]),
    )
    # 1: 3 px and 10° from 0; 2: turned 90°; 3: 20 px away (> 40 / 4); 4: 2 px and 3° (mod 180°) from 0;
    # 5: 1 px from 0, whose radius is its opening's quarter (10 px); 6: far; 7: 3.5 px from 6 (radius 4 px, not 2)
    assert distinct_grasps(ranked, 10).tolist() == [0, 2, 3, 6]
    assert distinct_grasps(ranked, 2).tolist() == [0, 2]
    assert distinct_grasps(ranked, 1).tolist() == [0]
    assert distinct_grasps(ranked.take(np.zeros(0, dtype=int)), 3).tolist() == []
    moved = ImageGrasps(ranked.centers + np.array([[0, 0]] * 7 + [[1, 0]]), ranked.angles, ranked.depths, ranked.widths)
    assert distinct_grasps(moved, 10).tolist() == [0, 2, 3, 6, 7]  # 4.5 px from 6: kept
