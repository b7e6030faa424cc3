"""Where a network's grasps stop counting: the quality floor below which a planned grasp is rejected,
and the warnings for an image outside the range of the training data.

The floor (:func:`quality_floor`) is, in order: the caller's (``--min-quality``), the model card's
validation operating point (:func:`graspaug.io.checkpoints.operating_point`: the threshold on P(success)
that maximises F1 on the network's validation predictions), or :data:`DEFAULT_MIN_QUALITY` for a card
without one. The warnings (:func:`range_warnings`) check the intrinsics against the image and the card
(:func:`intrinsics_warnings`: a principal point far from the image center, an image size other than the
training camera's), and compare the image with the card: the camera distance
with the rendered viewpoints' range, the height above the table of the object under the best grasp with
the training crops' object heights, the best grasp's gripper depth with the training gripper depths.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy import ndimage

from graspaug.planning.camera import DISTANCE_TOLERANCE, PRINCIPAL_POINT_OFFSET, camera_adapter, intrinsics_for
from graspaug.planning.card import ModelCard
from graspaug.render.settings import Intrinsics

if TYPE_CHECKING:
    from graspaug.planning.planner import PlannedGrasp

#: The floor for a card without a validation operating point (a checkpoint from before it was recorded):
#: about the share of successful grasps in the default data (0.094 of the test grasps, docs/results.md), so a
#: grasp below it is one the network rates worse than a random table-parallel grasp on a training object.
DEFAULT_MIN_QUALITY = 0.1
TABLE_BAND = 0.005  # m: while fitting the table plane, points more than 5 mm above it are left out
OBJECT_BAND = 0.003  # m: a pixel 3 mm or more above the table plane belongs to an object
HEIGHT_TOLERANCE = 0.005  # m: an object up to 5 mm taller than the tallest training crop (noise, blur) is in range
HEIGHT_FILTER_PX = 5  # px: median filter on the heights, against flying pixels at depth edges


@dataclass(frozen=True)
class QualityFloor:
    """The lowest P(success) ``value`` (in [0, 1]) at which a planned grasp is accepted, and its
    ``source`` in words (the flag, the model card's operating point or the default)."""

    value: float
    source: str

    def accepts(self, quality: float) -> bool:
        """Whether a grasp of P(success) ``quality`` clears the floor (a grasp without a network, NaN,
        clears only a floor of 0)."""
        return self.value <= 0 or (not math.isnan(quality) and quality >= self.value)

    def to_dict(self) -> dict[str, Any]:
        return {"value": self.value, "source": self.source}


def quality_floor(card: ModelCard, min_quality: float | None = None) -> QualityFloor:
    """The quality floor for a network with model ``card``: ``min_quality`` when given (0 disables the
    floor), else the card's validation operating point, else :data:`DEFAULT_MIN_QUALITY` (said so in
    ``source``). Raises ValueError for a ``min_quality`` outside [0, 1]."""
    if min_quality is not None:
        if not (0.0 <= float(min_quality) <= 1.0):
            raise ValueError(f"min_quality must lie in [0, 1] (a P(success)), got {min_quality:g}")
        return QualityFloor(float(min_quality), "--min-quality")
    point = card.operating_point
    if point and point.get("threshold") is not None:
        detail = (
            f"max F1 {point['f1']:.2f} on {point['datapoints']} validation grasps"
            if point.get("rule") == "max_f1" and "f1" in point and "datapoints" in point
            else f"rule {point.get('rule')}"
        )
        return QualityFloor(float(point["threshold"]), f"the model card's validation operating point, {detail}")
    return QualityFloor(
        DEFAULT_MIN_QUALITY,
        f"the default {DEFAULT_MIN_QUALITY:g}: the model card records no validation operating point "
        "(a network trained before it was recorded)",
    )


def table_heights(depth: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Height above the table (H, W) m of every pixel of ``depth`` (H, W) m: its camera-frame point's
    distance to the table plane, positive toward the camera. The plane is fitted by least squares to a
    grid of at most about 20,000 points, five times, each time to the points not more than
    :data:`TABLE_BAND` above the last plane (the first fit takes them all)."""
    depth = np.asarray(depth, dtype=float)
    h, w = depth.shape
    vv, uu = np.mgrid[0:h, 0:w]
    points = intrinsics.rays(uu, vv) * depth.reshape(-1, 1)  # (H·W, 3) camera frame, m
    step = max(1, int(np.sqrt(h * w / 20000)))
    sample = points.reshape(h, w, 3)[::step, ::step].reshape(-1, 3)
    basis = np.column_stack([sample[:, 0], sample[:, 1], np.ones(len(sample))])
    keep = np.ones(len(sample), dtype=bool)
    coef = np.array([0.0, 0.0, float(np.median(depth))])
    for _ in range(5):
        if keep.sum() < 3:
            break
        coef = np.linalg.lstsq(basis[keep], sample[keep, 2], rcond=None)[0]  # z = a x + b y + c
        keep = (basis @ coef - sample[:, 2]) / math.hypot(1.0, coef[0], coef[1]) <= TABLE_BAND
    plane = points[:, 0] * coef[0] + points[:, 1] * coef[1] + coef[2]
    return ((plane - points[:, 2]) / math.hypot(1.0, coef[0], coef[1])).reshape(h, w)


def object_height(depth: np.ndarray, intrinsics: Intrinsics, jaws: np.ndarray | None = None) -> float:
    """Height (m) above the table plane (:func:`table_heights`, median-filtered over
    :data:`HEIGHT_FILTER_PX` px) of the highest point of the object that a grasp with jaw positions
    ``jaws`` (2, 2) (u, v) px touches: the connected pixels :data:`OBJECT_BAND` or more above the table
    that the line between the jaws crosses. Without ``jaws``, or when the line crosses no object, the
    highest point of the image; 0 for an empty table."""
    heights = ndimage.median_filter(table_heights(depth, intrinsics), size=HEIGHT_FILTER_PX, mode="nearest")
    if jaws is not None:
        blobs, _ = ndimage.label(heights >= OBJECT_BAND)
        line = np.linspace(*np.asarray(jaws, dtype=float).reshape(2, 2), 17)
        u = np.clip(np.rint(line[:, 0]).astype(int), 0, depth.shape[1] - 1)
        v = np.clip(np.rint(line[:, 1]).astype(int), 0, depth.shape[0] - 1)
        touched = np.setdiff1d(blobs[v, u], [0])
        if len(touched):
            return float(heights[np.isin(blobs, touched)].max())
    return max(float(heights.max()), 0.0)


def intrinsics_warnings(card: ModelCard, intrinsics: Intrinsics) -> list[str]:
    """One line per way ``intrinsics`` (checked against the image by :func:`intrinsics_for`) look like another
    camera's than the image's, each saying what planning assumed; [] when they look right.

    - the principal point more than :data:`~graspaug.planning.camera.PRINCIPAL_POINT_OFFSET` of the image side
      from the image center (real cameras put it within a few percent of it; intrinsics of a 640×480 camera
      given for a 1280×720 image put it 320 px off and every grasp position with it);
    - an image size other than the training camera's (the card's ``intrinsics``): the image is planned on with the
      intrinsics given, resampled to the training focal length where needed.
    """
    w, h = intrinsics.width, intrinsics.height
    off_u, off_v = intrinsics.cx - (w - 1) / 2, intrinsics.cy - (h - 1) / 2
    warnings = []
    if abs(off_u) > PRINCIPAL_POINT_OFFSET * w or abs(off_v) > PRINCIPAL_POINT_OFFSET * h:
        warnings.append(
            f"the principal point (cx, cy) = ({intrinsics.cx:g}, {intrinsics.cy:g}) px lies ({off_u:+.0f}, "
            f"{off_v:+.0f}) px from the center ({(w - 1) / 2:g}, {(h - 1) / 2:g}) of this {w}×{h} image, more than "
            f"{PRINCIPAL_POINT_OFFSET:.0%} of its sides: are the intrinsics another image size's? They are used as "
            "given, and grasp positions in meters shift with the principal point (without --cx/--cy it is the "
            "image center)"
        )
    trained = (int(card.intrinsics["width"]), int(card.intrinsics["height"]))
    if (w, h) != trained:
        warnings.append(
            f"the image is {w}×{h} px and the network's training camera {trained[0]}×{trained[1]} px: planning "
            f"assumes the intrinsics given (fx = {intrinsics.fx:g}, fy = {intrinsics.fy:g}, cx = {intrinsics.cx:g}, "
            f"cy = {intrinsics.cy:g} px) are this image's"
        )
    return warnings


def range_warnings(
    card: ModelCard,
    depth: np.ndarray,
    intrinsics: Intrinsics | dict,
    grasps: list[PlannedGrasp],
    camera_distance: float | None = None,
) -> list[str]:
    """One line per way the image ``depth`` (H, W) m (checked, as :meth:`Planner.plan` got it) lies
    outside the data the network of ``card`` was trained on, each naming the training range and the
    measured value; [] when it lies inside (or the card records no range). First those of
    :func:`intrinsics_warnings`, then:

    - the camera distance (m; ``camera_distance``, default the image's median depth, as the planner
      takes it) outside the card's ``camera_distance`` (the rendered viewpoints, ± :data:`DISTANCE_TOLERANCE`);
    - the object under the best grasp (the first of ``grasps``; without one, the highest point)
      taller above the table (:func:`object_height`) than the central share (95%) of the training crops
      show (``training_range.object_height``, + :data:`HEIGHT_TOLERANCE`);
    - the best grasp's gripper depth, on the training camera the planner resamples to, outside the
      central share of the training gripper depths (``training_range.gripper_depth``).
    """
    intrinsics = intrinsics_for(np.shape(depth), intrinsics)
    warnings = intrinsics_warnings(card, intrinsics)
    distance = float(np.median(depth)) if camera_distance is None else float(camera_distance)
    said = "the image's median depth" if camera_distance is None else "--camera-distance"
    low, high = card.camera_distance
    if not (low - DISTANCE_TOLERANCE <= distance <= high + DISTANCE_TOLERANCE):
        target = min(max(distance, low), high)
        warnings.append(
            f"the camera is {distance:.3f} m from the table ({said}), outside the training camera distances "
            f"{low:g}-{high:g} m; the image is resampled to {target:g} m"
        )
    trained = card.training_range or {}
    share = f"{trained['share']:.0%} of " if trained.get("share") else ""  # cards before the share: the extremes
    heights = trained.get("object_height")
    if heights:
        best = grasps[0].jaw_pixels if grasps else None
        height = object_height(depth, intrinsics, best)
        if height > heights[1] + HEIGHT_TOLERANCE:
            where = "the object under the best grasp" if grasps else "the highest object"
            warnings.append(
                f"{where} stands {100 * height:.1f} cm above the table, taller than the objects of {share}the "
                f"training crops ({100 * heights[0]:.1f}-{100 * heights[1]:.1f} cm above the table): "
                "the network has seen few such scenes or none"
            )
    depths = trained.get("gripper_depth")
    if depths and grasps:
        virtual = grasps[0].depth + camera_adapter(card, intrinsics, distance).shift
        if not (depths[0] <= virtual <= depths[1]):
            warnings.append(
                f"the best grasp's gripper depth is {virtual:.3f} m on the training camera, outside {share}the "
                f"training gripper depths ({depths[0]:.3f}-{depths[1]:.3f} m)"
            )
    return warnings


def rejected_line(quality: float, floor: QualityFloor) -> str:
    """The one-line message for a best grasp of P(success) ``quality`` below ``floor``."""
    return (
        f"rejected: the best grasp's quality {quality:.3f} is below the floor {floor.value:.3f} ({floor.source}); "
        "--min-quality 0 accepts it"
    )
