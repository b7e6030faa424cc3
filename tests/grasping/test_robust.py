"""Robust Ferrari-Canny: perturbations, determinism, and the plain reference."""

import numpy as np
import trimesh

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.quality import ferrari_canny_qhull
from graspaug.grasping.robust import (
    Perturbations,
    QualitySettings,
    grasp_epsilon,
    perturbed_grasps,
    robust_ferrari_canny,
)

QUALITY = QualitySettings(friction_coef=0.5, cone_faces=8, torque_scaling=1000.0)
NOISE = Perturbations(
    n_samples=25,
    center_sigma=0.005,
    axis_sigma=0.001,
    object_translation_sigma=0.01,
    object_rotation_sigma=0.01,
    friction_sigma=0.1,
)
PANDA = ParallelJawGripper()


def grasps_across(mesh, n, seed):
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(n, 3)) * 0.2 + [0, 1.0, 0]
    return rng.normal(0, 0.003, (n, 3)), axes / np.linalg.norm(axes, axis=1, keepdims=True)


def test_without_noise_robust_equals_nominal():
    mesh = trimesh.creation.box((0.05, 0.04, 0.06))
    centers, axes = grasps_across(mesh, 20, 0)
    still = Perturbations(5, 0.0, 0.0, 0.0, 0.0, 0.0)
    mean, std = robust_ferrari_canny(mesh, centers, axes, PANDA, QUALITY, still, np.random.default_rng(0))
    np.testing.assert_allclose(mean, grasp_epsilon(mesh, centers, axes, 0.5, PANDA, QUALITY), atol=1e-15)
    np.testing.assert_allclose(std, 0.0, atol=1e-15)


def test_noise_lowers_quality_and_is_seeded():
    mesh = trimesh.creation.icosphere(subdivisions=4, radius=0.03)
    centers, axes = np.zeros((10, 3)), np.tile([0.0, 1.0, 0.0], (10, 1))
    nominal = grasp_epsilon(mesh, centers, axes, 0.5, PANDA, QUALITY)
    mean, std = robust_ferrari_canny(mesh, centers, axes, PANDA, QUALITY, NOISE, np.random.default_rng(1))
    again, _ = robust_ferrari_canny(mesh, centers, axes, PANDA, QUALITY, NOISE, np.random.default_rng(1))
    np.testing.assert_array_equal(mean, again)
    # a centered grasp on a sphere is the best one there is: perturbing it only loses quality
    assert np.all(mean < nominal) and np.all(mean > 0) and np.all(std > 0)


def test_perturbations_have_the_requested_spread():
    rng = np.random.default_rng(2)
    noise = Perturbations(4000, 0.005, 0.001, 0.0, 0.0, 0.1)
    centers, axes = np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]])
    c, a, mu = perturbed_grasps(centers, axes, 0.5, noise, rng)
    assert abs(c.std() - 0.005) < 3e-4
    tilt = np.arccos(np.clip(a[..., 2], -1, 1))  # angle of a rotation vector of std σ per axis
    assert abs(np.sqrt(np.mean(tilt**2)) - np.sqrt(2) * 0.001) < 1e-4
    assert mu.min() >= 0 and mu.max() <= 1 and abs(mu.mean() - 0.5) < 0.01 and abs(mu.std() - 0.1) < 0.01


def test_plain_reference_gives_the_same_robust_quality():
    mesh = trimesh.creation.box((0.05, 0.04, 0.06))
    centers, axes = grasps_across(mesh, 8, 3)
    ours = robust_ferrari_canny(mesh, centers, axes, PANDA, QUALITY, NOISE, np.random.default_rng(4))
    plain = robust_ferrari_canny(
        mesh,
        centers,
        axes,
        PANDA,
        QUALITY,
        NOISE,
        np.random.default_rng(4),
        epsilon=lambda w, inside: np.array([ferrari_canny_qhull(x) for x in w]),
    )
    np.testing.assert_allclose(ours, plain, atol=1e-9)
    assert ours[0].max() > 0.002


def test_object_pose_noise_moves_the_object_rigidly():
    """With only object-pose noise, a sample equals the grasp on the explicitly moved object.

    ``perturbed_grasps`` draws center, grasp rotation, object rotation, object shift in that
    order; redrawing them from the same seed gives the object's pose."""
    from scipy.spatial.transform import Rotation

    mesh = trimesh.creation.box((0.05, 0.04, 0.06))
    centers, axes = grasps_across(mesh, 6, 5)
    noise = Perturbations(1, 0.0, 0.0, 0.01, 0.05, 0.0)
    mean, _ = robust_ferrari_canny(mesh, centers, axes, PANDA, QUALITY, noise, np.random.default_rng(9))
    rng = np.random.default_rng(9)
    rng.standard_normal((6, 1, 3)), rng.standard_normal((6, 1, 3))
    rotations = Rotation.from_rotvec(0.05 * rng.standard_normal((6, 1, 3)).reshape(-1, 3))
    shifts = 0.01 * rng.standard_normal((6, 1, 3)).reshape(-1, 3)
    expected = []
    for i in range(6):
        moved = mesh.copy()
        moved.apply_transform(np.vstack([np.c_[rotations[i].as_matrix(), shifts[i]], [0, 0, 0, 1]]))
        expected.append(
            grasp_epsilon(
                moved, centers[i : i + 1], axes[i : i + 1], 0.5, PANDA, QUALITY, x_axis=rotations[i].apply([1.0, 0, 0])
            )[0]
        )
    np.testing.assert_allclose(mean, expected, rtol=5e-3, atol=1e-12)
    assert not np.allclose(
        mean, grasp_epsilon(mesh, centers, axes, 0.5, PANDA, QUALITY), rtol=1e-3
    )  # the noise did something
