"""A depth sensor like an Intel RealSense D435 looking down from 0.65 m: correlated axial noise
that grows with the square of the distance, pixels lost at depth edges and on steep surfaces,
and depths rounded to the camera's depth unit (the model and its numbers: :class:`DepthNoise`).

Missing pixels read 0, as the camera reports them; the planner fills them from the nearest
valid pixel (:func:`graspaug.planning.check_depth` with ``fill_missing``).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from graspaug.render.settings import Intrinsics
from graspaug.sim.settings import DepthNoise


def edge_band(depth: np.ndarray, settings: DepthNoise) -> np.ndarray:
    """(H, W) bool: pixels within ``settings.edge_band_px`` of a depth jump above
    ``settings.edge_jump`` (m) between 4-neighbours of ``depth`` (H, W) m (both sides of it)."""
    jumps = np.zeros(depth.shape, dtype=bool)
    across_u = np.abs(np.diff(depth, axis=1)) > settings.edge_jump
    across_v = np.abs(np.diff(depth, axis=0)) > settings.edge_jump
    jumps[:, 1:] |= across_u
    jumps[:, :-1] |= across_u
    jumps[1:] |= across_v
    jumps[:-1] |= across_v
    if settings.edge_band_px == 0 or not jumps.any():
        return jumps
    return ndimage.binary_dilation(jumps, iterations=settings.edge_band_px)


def surface_tilt(depth: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """(H, W) angle (degrees) between each pixel's surface and the image plane: 0 for a surface
    facing the camera, 90 for one seen edge-on (from the depth gradient, m per pixel, over
    the pixel's footprint z / f)."""
    grad_v, grad_u = np.gradient(depth)
    footprint = depth / (0.5 * (intrinsics.fx + intrinsics.fy))
    return np.degrees(np.arctan(np.hypot(grad_u, grad_v) / np.maximum(footprint, 1e-9)))


def noise_sd(depth: np.ndarray, settings: DepthNoise) -> np.ndarray:
    """Axial noise SD (m) at ``depth`` (m): ``sd_coefficient`` × z²."""
    return settings.sd_coefficient * np.square(depth)


def sense_depth(
    depth: np.ndarray, intrinsics: Intrinsics, settings: DepthNoise, rng: np.random.Generator
) -> np.ndarray:
    """What the sensor reads for the exact depth image ``depth`` (H, W) m: a new (H, W) float64
    array in m, 0 where the pixel is lost. ``depth`` is left unchanged; with
    ``settings.enabled`` false it is returned as a copy."""
    depth = np.asarray(depth, dtype=np.float64)
    if not settings.enabled:
        return depth.copy()
    field = rng.standard_normal(depth.shape)
    if settings.correlation_px > 0:
        field = ndimage.gaussian_filter(field, settings.correlation_px, mode="reflect")
        field /= field.std()  # unit SD per pixel after smoothing
    noisy = depth + noise_sd(depth, settings) * field
    if settings.quantization > 0:
        noisy = np.round(noisy / settings.quantization) * settings.quantization
    band = edge_band(depth, settings)
    steep = (surface_tilt(depth, intrinsics) > settings.steep_angle) & ~band
    draw = rng.random(depth.shape)
    lost = (band & (draw < settings.edge_dropout)) | (steep & (draw < settings.steep_dropout))
    noisy[lost] = 0.0
    return noisy
