"""Robust Ferrari-Canny: the mean (and spread) of ε over perturbed grasp poses, object poses
and friction coefficients (Dex-Net's ``RobustPointGraspMetrics3D``), in SI units."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation
from scipy.stats import truncnorm

from graspaug.grasping.contacts import close_fingers
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.quality import X_AXIS, ferrari_canny, grasp_wrenches
from graspaug.grasping.settings import Perturbations, QualitySettings

Epsilon = Callable[[np.ndarray, np.ndarray], np.ndarray]  # (wrench sets, origin known inside) -> ε


def grasp_epsilon(
    mesh: trimesh.Trimesh,
    centers: np.ndarray,
    axes: np.ndarray,
    friction_coef: np.ndarray | float,
    gripper: ParallelJawGripper,
    quality: QualitySettings,
    epsilon: Epsilon = ferrari_canny,
    x_axis: np.ndarray = X_AXIS,
) -> np.ndarray:
    """ε (N,) of grasps ``centers`` (N, 3) m / unit ``axes`` (N, 3) on ``mesh`` (center of mass
    at ``mesh.center_mass``; contact tangent frames turned toward ``x_axis``, the object's x
    axis, which is the frame's x axis for a mesh in its own frame).

    0 where a jaw misses or starts inside the object, or a contact slips (Dex-Net)."""
    contacts = close_fingers(mesh, centers, axes, gripper.max_width)
    out = np.zeros(len(centers))
    ok = contacts.found
    if not ok.any():
        return out
    mu = np.broadcast_to(np.asarray(friction_coef, dtype=float), (len(centers),))[ok]
    wrenches, slips, inside = grasp_wrenches(
        contacts.p1[ok],
        contacts.n1[ok],
        contacts.p2[ok],
        contacts.n2[ok],
        np.asarray(axes, dtype=float)[ok],
        np.asarray(mesh.center_mass),
        mu,
        quality.torque_scaling,
        gripper.finger_radius,
        quality.cone_faces,
        x_axis,
    )
    eps = np.zeros(len(wrenches))
    eps[~slips] = epsilon(wrenches[~slips], inside[~slips])
    out[ok] = eps
    return out


def perturbed_grasps(
    centers: np.ndarray, axes: np.ndarray, friction_coef: float, noise: Perturbations, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n_samples`` perturbed copies of each grasp, expressed in the object's frame.

    Returns centers (N, S, 3), unit axes (N, S, 3) and friction coefficients (N, S). The grasp
    moves by ``center + δ``, ``axis ← exp([ξ]×) axis``; the object by ``x ← R x + t``; the
    grasp seen from the moved object is ``Rᵀ(center - t)``, ``Rᵀ axis``."""
    n, s = len(centers), noise.n_samples
    shape = (n, s, 3)
    center = centers[:, None, :] + noise.center_sigma * rng.standard_normal(shape)
    grasp_rot = Rotation.from_rotvec(noise.axis_sigma * rng.standard_normal(shape).reshape(-1, 3))
    axis = grasp_rot.apply(np.repeat(axes, s, axis=0)).reshape(shape)
    object_rot = Rotation.from_rotvec(noise.object_rotation_sigma * rng.standard_normal(shape).reshape(-1, 3))
    shift = noise.object_translation_sigma * rng.standard_normal(shape)
    center = object_rot.inv().apply((center - shift).reshape(-1, 3)).reshape(shape)
    axis = object_rot.inv().apply(axis.reshape(-1, 3)).reshape(shape)
    axis /= np.linalg.norm(axis, axis=2, keepdims=True)
    if noise.friction_sigma > 0:
        lo, hi = (0.0 - friction_coef) / noise.friction_sigma, (1.0 - friction_coef) / noise.friction_sigma
        mu = truncnorm.rvs(lo, hi, loc=friction_coef, scale=noise.friction_sigma, size=(n, s), random_state=rng)
    else:
        mu = np.full((n, s), friction_coef)
    return center, axis, mu


def robust_ferrari_canny(
    mesh: trimesh.Trimesh,
    centers: np.ndarray,
    axes: np.ndarray,
    gripper: ParallelJawGripper,
    quality: QualitySettings,
    noise: Perturbations,
    rng: np.random.Generator,
    epsilon: Epsilon = ferrari_canny,
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (N,) of ε over ``noise.n_samples`` perturbations of each
    grasp (``centers``, ``axes`` (N, 3)); ``epsilon`` computes ε of wrench sets."""
    if len(centers) == 0:
        return np.zeros(0), np.zeros(0)
    center, axis, mu = perturbed_grasps(
        np.asarray(centers, float), np.asarray(axes, float), quality.friction_coef, noise, rng
    )
    eps = grasp_epsilon(mesh, center.reshape(-1, 3), axis.reshape(-1, 3), mu.reshape(-1), gripper, quality, epsilon)
    eps = eps.reshape(len(centers), noise.n_samples)
    return eps.mean(axis=1), eps.std(axis=1)
