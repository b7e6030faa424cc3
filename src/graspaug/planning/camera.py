"""The camera a depth image comes from: its intrinsics and depths checked, and the resampling that
makes another camera look like the one a network was trained for.

For another camera the image is resampled to a virtual camera with the training focal length at
the nearest training distance (depths shifted by the distance difference) when that is sound:
the object must not be up-sampled by more than :data:`MAX_UPSAMPLING` nor seen from a distance
more than :data:`MAX_DISTANCE_RATIO` times off the training range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from graspaug.planning.card import ModelCard
from graspaug.planning.errors import PlanningError
from graspaug.planning.grasps import ImageGrasps, canonical_angles
from graspaug.render.settings import Intrinsics

MAX_UPSAMPLING = 1.5  # the camera may see the object with at most 1.5× fewer pixels than in training
MAX_DOWNSAMPLING = 4.0  # ... and with at most 4× more (more only costs time: resample it first)
MAX_DISTANCE_RATIO = 1.5  # camera distance within [lowest / 1.5, highest × 1.5] of the training range
DISTANCE_TOLERANCE = 0.01  # m: a camera this close outside the training range counts as inside

MIN_IMAGE_PX = 8  # the smallest image side planning takes (a grasp crop needs neighbours)
PRINCIPAL_POINT_OFFSET = 0.1  # share of the image side beyond which a principal point off the center is warned about

_KEYS = ("width", "height", "fx", "fy", "cx", "cy")


def intrinsics_for(depth_shape: tuple[int, int], intrinsics: Intrinsics | dict) -> Intrinsics:
    """``intrinsics`` (an :class:`Intrinsics` or a dict with fx, fy, cx, cy in px; width and
    height default to the image's) checked against an image of ``depth_shape`` (H, W)."""
    h, w = depth_shape
    if isinstance(intrinsics, Intrinsics):
        values = {k: getattr(intrinsics, k) for k in _KEYS}
    elif isinstance(intrinsics, dict):
        missing = [k for k in ("fx", "fy", "cx", "cy") if k not in intrinsics]
        unknown = sorted(set(intrinsics) - set(_KEYS))
        if missing or unknown:
            raise PlanningError(
                "intrinsics need fx, fy, cx, cy (px)"
                f"{'; missing ' + ', '.join(missing) if missing else ''}"
                f"{'; unknown ' + ', '.join(unknown) if unknown else ''}"
            )
        values = {"width": w, "height": h, **intrinsics}
    else:
        raise PlanningError(
            f"intrinsics must be an Intrinsics or a dict of fx, fy, cx, cy, got {type(intrinsics).__name__}"
        )
    if (int(values["width"]), int(values["height"])) != (w, h):
        raise PlanningError(
            f"the depth image is {w}×{h} px but the intrinsics are for {values['width']}×{values['height']}"
        )
    numbers = {}
    for key, value in values.items():
        try:
            numbers[key] = int(value) if key in ("width", "height") else float(value)
        except (ValueError, TypeError):
            raise PlanningError(f"intrinsics: {key} must be a number (px), got {value!r}") from None
    for key in ("fx", "fy"):
        if not (math.isfinite(numbers[key]) and numbers[key] > 0):
            raise PlanningError(f"intrinsics: {key} must be a positive focal length (px), got {numbers[key]:g}")
    for key, size, side in (("cx", w, "wide"), ("cy", h, "high")):
        if not (math.isfinite(numbers[key]) and -0.5 <= numbers[key] <= size - 0.5):
            raise PlanningError(
                f"intrinsics: {key} = {numbers[key]:g} px lies outside the {size} px {side} image "
                f"(the principal point is near the image center, {(size - 1) / 2:g} px)"
            )
    return Intrinsics(**numbers)


def check_depth(depth: np.ndarray, fill_missing: bool = False) -> np.ndarray:
    """A float64 copy of ``depth`` (H, W) m (or (H, W, 1), a single channel) after checks: real numbers (not
    complex, not bool); pixels that are NaN, inf or <= 0 (missing) are an error, or with ``fill_missing`` take the
    value of the nearest valid pixel."""
    depth = np.asarray(depth)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[..., 0]
    if depth.ndim != 2:
        raise PlanningError(
            f"the depth image must be a 2-D array (H, W) in meters (or (H, W, 1)), got shape {depth.shape}"
        )
    if depth.dtype.kind == "c":
        raise PlanningError(
            f"the depth image holds complex numbers (dtype {depth.dtype}); depths are real meters: save its real "
            "part (depth.real) if that is what the camera measured"
        )
    if min(depth.shape) < MIN_IMAGE_PX:
        raise PlanningError(
            f"the depth image is {depth.shape[1]}×{depth.shape[0]} px; planning needs at least "
            f"{MIN_IMAGE_PX}×{MIN_IMAGE_PX}"
        )
    if depth.dtype.kind not in "uif":
        raise PlanningError(f"the depth image must hold real numbers (meters), got dtype {depth.dtype}")
    depth = depth.astype(np.float64)
    missing = ~np.isfinite(depth) | (depth <= 0)
    if missing.all():
        raise PlanningError("the depth image has no valid pixel (all NaN, inf or <= 0)")
    if missing.any():
        if not fill_missing:
            raise PlanningError(
                f"the depth image has {int(missing.sum())} missing pixels (NaN, inf or <= 0); "
                "fill them (fill_missing=True / --fill-missing takes the nearest valid pixel)"
            )
        index = ndimage.distance_transform_edt(missing, return_distances=False, return_indices=True)
        depth = depth[tuple(index)]
    median = float(np.median(depth))
    if median > 20:
        raise PlanningError(
            f"the depth image's median is {median:g}: it looks like millimeters, but meters are expected"
        )
    return depth


@dataclass(frozen=True)
class CameraAdapter:
    """How an image of another camera becomes one the network was trained for: pixel
    coordinates scale by ``scale`` (su, sv) about the image corner (virtual pixel edge = scaled
    pixel edge), depths shift by ``shift`` m; ``virtual`` are the virtual camera's intrinsics."""

    scale: tuple[float, float]
    shift: float
    virtual: Intrinsics

    @property
    def identity(self) -> bool:
        return self.scale == (1.0, 1.0) and self.shift == 0.0

    def image(self, depth: np.ndarray) -> np.ndarray:
        """The depth image (H', W') m the virtual camera sees (bilinear resampling)."""
        if self.identity:
            return depth
        su, sv = self.scale
        v, u = np.mgrid[0 : self.virtual.height, 0 : self.virtual.width].astype(float)
        source = [(v + 0.5) / sv - 0.5, (u + 0.5) / su - 0.5]
        return ndimage.map_coordinates(depth, source, order=1, mode="nearest") + self.shift

    def to_original(self, grasps: ImageGrasps) -> ImageGrasps:
        """Virtual-image grasps → the original image (centers, angles, widths, depths)."""
        if self.identity:
            return grasps
        su, sv = self.scale
        centers = (grasps.centers + 0.5) / np.array([su, sv]) - 0.5
        axis = np.stack([np.cos(grasps.angles) / su, np.sin(grasps.angles) / sv], axis=1) * grasps.widths[:, None]
        angles = canonical_angles(np.arctan2(axis[:, 1], axis[:, 0]))
        return ImageGrasps(centers, angles, grasps.depths - self.shift, np.linalg.norm(axis, axis=1))

    def to_virtual(self, grasps: ImageGrasps) -> ImageGrasps:
        """Original-image grasps → the virtual image (the inverse of :meth:`to_original`)."""
        if self.identity:
            return grasps
        su, sv = self.scale
        centers = (grasps.centers + 0.5) * np.array([su, sv]) - 0.5
        axis = np.stack([np.cos(grasps.angles) * su, np.sin(grasps.angles) * sv], axis=1) * grasps.widths[:, None]
        angles = canonical_angles(np.arctan2(axis[:, 1], axis[:, 0]))
        return ImageGrasps(centers, angles, grasps.depths + self.shift, np.linalg.norm(axis, axis=1))


def camera_adapter(card: ModelCard, intrinsics: Intrinsics, distance: float) -> CameraAdapter:
    """The resampling that makes a camera with ``intrinsics`` at ``distance`` m from the table
    look like the training camera, or :class:`PlanningError` when that is not sound."""
    low, high = card.camera_distance
    if not (low / MAX_DISTANCE_RATIO <= distance <= high * MAX_DISTANCE_RATIO):
        raise PlanningError(
            f"the camera is {distance:.3f} m from the scene, far from the network's training range "
            f"{low:g}-{high:g} m (planning resamples within {low / MAX_DISTANCE_RATIO:.2f}-"
            f"{high * MAX_DISTANCE_RATIO:.2f} m)"
        )
    inside = low - DISTANCE_TOLERANCE <= distance <= high + DISTANCE_TOLERANCE
    target = distance if inside else min(max(distance, low), high)
    train_fx, train_fy = float(card.intrinsics["fx"]), float(card.intrinsics["fy"])
    scale = []
    for f, train_f in ((intrinsics.fx, train_fx), (intrinsics.fy, train_fy)):
        s = (train_f / f) * (distance / target)
        scale.append(1.0 if abs(s - 1.0) < 1e-3 else s)
        if s > MAX_UPSAMPLING:
            raise PlanningError(
                f"the camera (f = {f:g} px at {distance:.3f} m) sees objects {s:.2f}× smaller "
                f"than the network's training camera (f = {train_f:g} px at {target:.3f} m); "
                f"at most {MAX_UPSAMPLING:g}× can be up-sampled"
            )
        if s < 1 / MAX_DOWNSAMPLING:
            raise PlanningError(
                f"the camera (f = {f:g} px at {distance:.3f} m) sees objects {1 / s:.2f}× larger "
                f"than the network's training camera; at most {MAX_DOWNSAMPLING:g}× is resampled: "
                "down-sample the image first"
            )
    su, sv = scale
    if (su, sv) == (1.0, 1.0) and target == distance:
        return CameraAdapter((1.0, 1.0), 0.0, intrinsics)
    virtual = Intrinsics(
        width=max(1, int(round(intrinsics.width * su))),
        height=max(1, int(round(intrinsics.height * sv))),
        fx=intrinsics.fx * su,
        fy=intrinsics.fy * sv,
        cx=(intrinsics.cx + 0.5) * su - 0.5,
        cy=(intrinsics.cy + 0.5) * sv - 0.5,
    )
    return CameraAdapter((su, sv), target - distance, virtual)
