"""Chamfer distance, coverage, MMD and 1-NN accuracy on hand-made point clouds."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from graspaug.experiments.fidelity import (
    chamfer_matrix,
    coverage_mmd,
    distribution_distances,
    one_nn_accuracy,
    surface_cloud,
)


def test_chamfer_of_a_cloud_and_its_shift():
    a = np.zeros((1, 3))
    b = np.array([[0.003, 0.004, 0.0]])
    assert np.isclose(chamfer_matrix([a], [b])[0, 0], 0.005)
    square = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    assert chamfer_matrix([square], [square])[0, 0] == 0.0
    assert np.isclose(chamfer_matrix([square], [square[:1]])[0, 0], 0.5 * (np.mean([0, 1, 1, np.sqrt(2)]) + 0))


def test_coverage_and_mmd_by_hand():
    d = np.array([[0.1, 0.5, 0.9], [0.2, 0.4, 0.8]])  # both pool shapes are nearest to reference 0
    coverage, mmd = coverage_mmd(d)
    assert coverage == pytest.approx(1 / 3) and mmd == pytest.approx((0.1 + 0.4 + 0.8) / 3)


def test_one_nn_accuracy_is_one_for_separate_sets_and_half_for_interleaved_ones():
    near = np.array([[0, 1], [1, 0]], float)
    far = np.full((2, 2), 10.0)
    assert one_nn_accuracy(near, near, far) == 1.0  # every shape's nearest is in its own set
    close = np.full((2, 2), 0.1)
    assert one_nn_accuracy(near, near, close) == 0.0  # every shape's nearest is in the other set
    with pytest.raises(ValueError, match="square"):
        one_nn_accuracy(near, near, np.ones((2, 3)))


def test_a_pool_of_the_reference_shapes_is_indistinguishable_and_boxes_are_not():
    rng = np.random.default_rng(0)
    spheres = [trimesh.creation.icosphere(radius=r) for r in (0.02, 0.025, 0.03, 0.035)]
    reference = [surface_cloud(m, 256, rng) for m in spheres]
    again = [surface_cloud(m, 256, rng) for m in spheres]  # the same shapes, other points
    same = distribution_distances(again, reference)
    # each shape's nearest is its twin in the other set; MMD is the sampling noise of 256 points (a few mm)
    assert same["coverage"] == 1.0 and same["one_nna"] == 0.0 and same["mmd"] < 0.005
    boxes = [surface_cloud(trimesh.creation.box((0.1, 0.01, 0.01 * k)), 256, rng) for k in (1, 2, 3, 4)]
    other = distribution_distances(boxes, reference)
    assert other["one_nna"] == 1.0 and other["coverage"] < 0.5 and other["mmd"] > 3 * same["mmd"]
