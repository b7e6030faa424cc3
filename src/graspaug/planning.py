"""Planning a grasp on a depth image with a trained GQ-CNN: the public API.

    import numpy as np
    from graspaug.planning import load_planner, plan_grasp

    planner = load_planner("models/gqcnn/s0/targeted/50-0/model.pt")
    depth = np.load("depth.npy")                              # (H, W) meters, camera looking down
    grasp = plan_grasp(depth, {"fx": 525, "fy": 525, "cx": 319.5, "cy": 239.5}, planner)
    grasp.pose                                                # (4, 4) gripper pose in the camera frame, m
    grasp.width, grasp.quality                                # jaw opening (m), predicted P(success)

The planner is the one the simulated robot uses (``graspaug.sim``): antipodal pairs on depth
edges, scored by the GQ-CNN on 96 → 32 px grasp crops, refined by the cross-entropy method
(Dex-Net 2.0's ``CrossEntropyRobustGraspingPolicy``).

A network only knows the camera it was trained for; its model card (in ``model.pt``) records
it: focal length (px), camera distance range (m), crop sizes. For another camera the image is
resampled to a virtual camera with the training focal length at the nearest training distance
(depths shifted by the distance difference) when that is sound: the object must not be
up-sampled by more than :data:`MAX_UPSAMPLING` nor seen from a distance more than
:data:`MAX_DISTANCE_RATIO` times off the training range. Otherwise planning stops with a
one-line :class:`PlanningError`. The camera should look (nearly) straight down, as in training
(tilt 0-5°).
"""
from __future__ import annotations

import logging
import math
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch
from scipy import ndimage

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.render.camera import Intrinsics
from graspaug.render.settings import CropGeometry
from graspaug.sim.policy import CrossEntropyGraspPolicy, ImageGrasps, RandomAntipodalPolicy, _canonical, antipodal_in_image
from graspaug.sim.settings import CEMSettings, SamplerSettings

log = logging.getLogger(__name__)

__all__ = ["ModelCard", "PlannedGrasp", "Planner", "PlanningError", "NoGraspFound", "load_planner", "plan_grasp", "plan_grasps",
           "intrinsics_for", "read_depth_image", "read_intrinsics", "export_model"]

MAX_UPSAMPLING = 1.5  # the camera may see the object with at most 1.5× fewer pixels than in training
MAX_DOWNSAMPLING = 4.0  # ... and with at most 4× more (more only costs time: resample it first)
MAX_DISTANCE_RATIO = 1.5  # camera distance within [lowest / 1.5, highest × 1.5] of the training range
DISTANCE_TOLERANCE = 0.01  # m: a camera this close outside the training range counts as inside


class PlanningError(ValueError):
    """Bad input to the planner; ``str(exc)`` is the one-line reason."""


class NoGraspFound(PlanningError):
    """The image holds no antipodal pair of depth edges that fits the gripper."""


@dataclass(frozen=True)
class ModelCard:
    """What a GQ-CNN was trained for and how well it did (``card`` in ``model.pt``).

    ``intrinsics`` (px) and ``camera_distance`` (m, the camera's distance to the table along
    its axis) are the training camera; ``crop_size`` → ``out_size`` (px) the crops; ``gripper``
    the hand (m); ``label_threshold`` the robust ε above which a training grasp counted as a
    success; ``training_set`` its pool, base size, ratio, seed, size, members and training
    precision (None where not recorded); ``validation_ap`` / ``test_ap`` its Average Precision.
    ``assumed`` is True for a checkpoint without a card (written before cards existed): the
    defaults are then assumed.
    """

    crop_size: int = 96
    out_size: int = 32
    intrinsics: dict = field(default_factory=lambda: {k: getattr(Intrinsics(), k) for k in ("width", "height", "fx", "fy", "cx", "cy")})
    camera_distance: tuple[float, float] = (0.65, 0.75)
    camera_tilt_deg: tuple[float, float] = (0.1, 5.0)
    gripper: dict = field(default_factory=lambda: asdict(ParallelJawGripper()))
    label_threshold: float | None = None
    training_set: dict = field(default_factory=dict)
    validation_ap: float | None = None
    test_ap: float | None = None
    image_input: str = "depth"
    graspaug_version: str | None = None
    global_seed: int | None = None
    format: str = "graspaug.gqcnn-card/1"
    assumed: bool = False

    @classmethod
    def from_dict(cls, card: dict[str, Any] | None, image_input: str = "depth") -> ModelCard:
        """The card stored in a checkpoint (None: the defaults, ``assumed``)."""
        if card is None:
            return cls(image_input=image_input, assumed=True)
        known = {k: v for k, v in card.items() if k in cls.__dataclass_fields__}
        for key in ("camera_distance", "camera_tilt_deg"):
            if key in known:
                known[key] = tuple(float(x) for x in known[key])
        return cls(**{**known, "image_input": image_input})

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["camera_distance"], out["camera_tilt_deg"] = list(self.camera_distance), list(self.camera_tilt_deg)
        return out

    @property
    def geometry(self) -> CropGeometry:
        return CropGeometry(crop_size=self.crop_size, out_size=self.out_size)

    @property
    def focal_length(self) -> float:
        """Training focal length (px), the mean of fx and fy."""
        return 0.5 * (float(self.intrinsics["fx"]) + float(self.intrinsics["fy"]))


@dataclass(frozen=True)
class PlannedGrasp:
    """One planned parallel-jaw grasp.

    In the image: jaw center (``u``, ``v``) px, jaw direction ``angle`` rad (from the u axis
    toward v), jaw opening ``width_px`` px, gripper ``depth`` m (camera frame z of the grasp
    center, below the surface between the jaws). In the camera frame (x right, y down, z along
    the optical axis; m): ``position`` (3,) the grasp center, ``rotation`` (3, 3) the gripper
    axes as columns (x: the jaw axis, z: the approach, along the optical axis), ``width`` m the
    jaw opening at the grasp depth. ``quality`` is the GQ-CNN's P(success) (NaN without a
    network), ``planning_time`` s, ``candidates`` the grasps scored.
    """

    u: float
    v: float
    angle: float
    depth: float
    width_px: float
    position: np.ndarray
    rotation: np.ndarray
    width: float
    quality: float
    planning_time: float
    candidates: int

    @property
    def pose(self) -> np.ndarray:
        """(4, 4) gripper pose in the camera frame (m)."""
        out = np.eye(4)
        out[:3, :3], out[:3, 3] = self.rotation, self.position
        return out

    @property
    def grasp(self) -> ImageGrasps:
        """The image grasp as one row of :class:`~graspaug.sim.policy.ImageGrasps`."""
        return ImageGrasps(np.array([[self.u, self.v]]), np.array([self.angle]), np.array([self.depth]), np.array([self.width_px]))

    @property
    def jaw_pixels(self) -> np.ndarray:
        """(2, 2) the two jaw positions (u, v) px in the image."""
        half = 0.5 * self.width_px * np.array([math.cos(self.angle), math.sin(self.angle)])
        return np.stack([np.array([self.u, self.v]) - half, np.array([self.u, self.v]) + half])

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers for JSON."""
        return {"u": self.u, "v": self.v, "angle": self.angle, "depth": self.depth, "width_px": self.width_px,
                "position": self.position.tolist(), "rotation": self.rotation.tolist(), "pose": self.pose.tolist(), "width": self.width,
                "quality": None if math.isnan(self.quality) else self.quality, "planning_time": self.planning_time,
                "candidates": self.candidates}


def intrinsics_for(depth_shape: tuple[int, int], intrinsics: Intrinsics | dict) -> Intrinsics:
    """``intrinsics`` (an :class:`Intrinsics` or a dict with fx, fy, cx, cy in px; width and
    height default to the image's) checked against an image of ``depth_shape`` (H, W)."""
    h, w = depth_shape
    if isinstance(intrinsics, Intrinsics):
        values = {k: getattr(intrinsics, k) for k in ("width", "height", "fx", "fy", "cx", "cy")}
    elif isinstance(intrinsics, dict):
        missing = [k for k in ("fx", "fy", "cx", "cy") if k not in intrinsics]
        unknown = sorted(set(intrinsics) - {"width", "height", "fx", "fy", "cx", "cy"})
        if missing or unknown:
            raise PlanningError(f"intrinsics need fx, fy, cx, cy (px){'; missing ' + ', '.join(missing) if missing else ''}"
                                f"{'; unknown ' + ', '.join(unknown) if unknown else ''}")
        values = {"width": w, "height": h, **intrinsics}
    else:
        raise PlanningError(f"intrinsics must be an Intrinsics or a dict of fx, fy, cx, cy, got {type(intrinsics).__name__}")
    if (int(values["width"]), int(values["height"])) != (w, h):
        raise PlanningError(f"the depth image is {w}×{h} px but the intrinsics are for {values['width']}×{values['height']}")
    try:
        return Intrinsics(**{k: (int(values[k]) if k in ("width", "height") else float(values[k])) for k in values})
    except (ValueError, TypeError) as exc:
        raise PlanningError(f"bad intrinsics {values}: {str(exc).splitlines()[0]}") from None


def read_depth_image(path: str | os.PathLike) -> np.ndarray:
    """A depth image (H, W) float64 m from a ``.npy`` file (meters) or a 16-bit PNG
    (millimeters; 0 = no reading, returned as NaN)."""
    path = Path(path)
    if not path.is_file():
        raise PlanningError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            return np.load(path, allow_pickle=False)
        except ValueError as exc:
            raise PlanningError(f"{path}: not a numeric .npy array ({str(exc).splitlines()[0]})") from None
    if suffix == ".png":
        from PIL import Image

        with Image.open(path) as image:
            pixels = np.asarray(image)
        if pixels.dtype != np.uint16 and not (pixels.dtype == np.int32 and pixels.max() < 2**16):
            raise PlanningError(f"{path}: a depth PNG must be 16-bit grayscale in millimeters, got mode {image.mode}")
        depth = pixels.astype(np.float64) / 1000.0
        depth[pixels == 0] = np.nan
        return depth
    raise PlanningError(f"{path}: depth images are .npy (meters) or 16-bit .png (millimeters), got {suffix or 'no suffix'}")


def read_intrinsics(path: str | os.PathLike | None, fx: float | None, fy: float | None, cx: float | None, cy: float | None,
                    shape: tuple[int, ...]) -> dict:
    """Intrinsics (px) from a JSON file (fx, fy, cx, cy; width and height optional) or from
    values: fy defaults to fx, the principal point to the image center of ``shape`` (H, W)."""
    if path is not None:
        if any(v is not None for v in (fx, fy, cx, cy)):
            raise PlanningError("give the intrinsics as a JSON file or as --fx/--fy/--cx/--cy, not both")
        import json

        try:
            values = json.loads(Path(path).read_text())
        except (OSError, ValueError) as exc:
            raise PlanningError(f"{path}: not a readable JSON file of fx, fy, cx, cy ({str(exc).splitlines()[0]})") from None
        if not isinstance(values, dict):
            raise PlanningError(f"{path}: must hold a JSON object with fx, fy, cx, cy (px)")
        return values
    if fx is None:
        raise PlanningError("intrinsics missing: give --fx (and --fy, --cx, --cy) or --intrinsics camera.json")
    h, w = (shape[0], shape[1]) if len(shape) >= 2 else (1, 1)
    return {"fx": fx, "fy": fx if fy is None else fy, "cx": (w - 1) / 2 if cx is None else cx, "cy": (h - 1) / 2 if cy is None else cy}


def check_depth(depth: np.ndarray, fill_missing: bool = False) -> np.ndarray:
    """A float64 copy of ``depth`` (H, W) m after checks; pixels that are NaN, inf or <= 0
    (missing) are an error, or with ``fill_missing`` take the value of the nearest valid pixel."""
    depth = np.asarray(depth)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[..., 0]
    if depth.ndim != 2 or min(depth.shape, default=0) < 8:
        raise PlanningError(f"the depth image must be a 2-D array (H, W) in meters, got shape {depth.shape}")
    if not np.issubdtype(depth.dtype, np.number):
        raise PlanningError(f"the depth image must hold numbers (meters), got dtype {depth.dtype}")
    depth = depth.astype(np.float64)
    missing = ~np.isfinite(depth) | (depth <= 0)
    if missing.all():
        raise PlanningError("the depth image has no valid pixel (all NaN, inf or <= 0)")
    if missing.any():
        if not fill_missing:
            raise PlanningError(f"the depth image has {int(missing.sum())} missing pixels (NaN, inf or <= 0); "
                                "fill them (fill_missing=True / --fill-missing takes the nearest valid pixel)")
        index = ndimage.distance_transform_edt(missing, return_distances=False, return_indices=True)
        depth = depth[tuple(index)]
    median = float(np.median(depth))
    if median > 20:
        raise PlanningError(f"the depth image's median is {median:g}: it looks like millimeters, but meters are expected")
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
        v, u = np.mgrid[0:self.virtual.height, 0:self.virtual.width].astype(float)
        source = [(v + 0.5) / sv - 0.5, (u + 0.5) / su - 0.5]
        return ndimage.map_coordinates(depth, source, order=1, mode="nearest") + self.shift

    def to_original(self, grasps: ImageGrasps) -> ImageGrasps:
        """Virtual-image grasps → the original image (centers, angles, widths, depths)."""
        if self.identity:
            return grasps
        su, sv = self.scale
        centers = (grasps.centers + 0.5) / np.array([su, sv]) - 0.5
        axis = np.stack([np.cos(grasps.angles) / su, np.sin(grasps.angles) / sv], axis=1) * grasps.widths[:, None]
        return ImageGrasps(centers, _canonical(np.arctan2(axis[:, 1], axis[:, 0])), grasps.depths - self.shift, np.linalg.norm(axis, axis=1))


def camera_adapter(card: ModelCard, intrinsics: Intrinsics, distance: float) -> CameraAdapter:
    """The resampling that makes a camera with ``intrinsics`` at ``distance`` m from the table
    look like the training camera, or :class:`PlanningError` when that is not sound."""
    low, high = card.camera_distance
    if not (low / MAX_DISTANCE_RATIO <= distance <= high * MAX_DISTANCE_RATIO):
        raise PlanningError(f"the camera is {distance:.3f} m from the scene, far from the network's training range {low:g}-{high:g} m "
                            f"(planning resamples within {low / MAX_DISTANCE_RATIO:.2f}-{high * MAX_DISTANCE_RATIO:.2f} m)")
    target = distance if low - DISTANCE_TOLERANCE <= distance <= high + DISTANCE_TOLERANCE else min(max(distance, low), high)
    train_fx, train_fy = float(card.intrinsics["fx"]), float(card.intrinsics["fy"])
    scale = []
    for f, train_f in ((intrinsics.fx, train_fx), (intrinsics.fy, train_fy)):
        s = (train_f / f) * (distance / target)
        scale.append(1.0 if abs(s - 1.0) < 1e-3 else s)
        if s > MAX_UPSAMPLING:
            raise PlanningError(f"the camera (f = {f:g} px at {distance:.3f} m) sees objects {s:.2f}× smaller than the network's training "
                                f"camera (f = {train_f:g} px at {target:.3f} m); at most {MAX_UPSAMPLING:g}× can be up-sampled")
        if s < 1 / MAX_DOWNSAMPLING:
            raise PlanningError(f"the camera (f = {f:g} px at {distance:.3f} m) sees objects {1 / s:.2f}× larger than the network's training "
                                f"camera; at most {MAX_DOWNSAMPLING:g}× is resampled: down-sample the image first")
    su, sv = scale
    if (su, sv) == (1.0, 1.0) and target == distance:
        return CameraAdapter((1.0, 1.0), 0.0, intrinsics)
    virtual = Intrinsics(width=max(1, int(round(intrinsics.width * su))), height=max(1, int(round(intrinsics.height * sv))),
                         fx=intrinsics.fx * su, fy=intrinsics.fy * sv, cx=(intrinsics.cx + 0.5) * su - 0.5, cy=(intrinsics.cy + 0.5) * sv - 0.5)
    return CameraAdapter((su, sv), target - distance, virtual)


class Planner:
    """A GQ-CNN (or none: a random antipodal grasp) with its model card and sampler settings.

    ``sampler`` and ``cem`` default to the simulator's (Dex-Net 2.0's) with the jaw opening of
    the card's gripper. With ``check_image`` (the default) a grasp is returned only if the image
    shows it antipodal and reachable (:func:`~graspaug.sim.policy.antipodal_in_image`: jaws on
    depth edges inside the friction cone, free space beside them down to the grasp depth);
    the candidates are then the last cross-entropy iteration's and the seeds. Dex-Net's policy,
    which the simulated robot runs (``check_image=False``), trusts the network instead.
    ``threads``: torch threads while planning (1: the network sees small batches, and on a
    2-core CPU one thread plans in 0.47 s where two take 2.4 s; 0 leaves torch's setting).
    """

    def __init__(self, net=None, card: ModelCard | None = None, sampler: SamplerSettings | None = None, cem: CEMSettings = CEMSettings(),
                 check_image: bool = True, threads: int = 1) -> None:
        self.net, self.check_image, self.threads = (None if net is None else net.eval()), check_image, threads
        image_input = getattr(getattr(net, "config", None), "image_input", "depth")
        self.card = card if card is not None else ModelCard(image_input=image_input, assumed=True)
        if sampler is None:
            sampler = SamplerSettings(max_width=float(self.card.gripper.get("max_width", SamplerSettings().max_width)))
        self.sampler, self.cem = sampler, cem

    def policy(self, intrinsics: Intrinsics):
        if self.net is None:
            return RandomAntipodalPolicy(intrinsics, self.sampler)
        return CrossEntropyGraspPolicy(self.net, intrinsics, self.sampler, self.cem, self.card.geometry)

    def plan(self, depth: np.ndarray, intrinsics: Intrinsics | dict, rng: np.random.Generator | int = 0, top: int = 1,
             camera_distance: float | None = None, fill_missing: bool = False) -> list[PlannedGrasp]:
        """Up to ``top`` grasps on ``depth`` (H, W) m, best first; [] when the image holds no
        antipodal pair. ``camera_distance`` (m, the table's distance along the optical axis)
        defaults to the image's median depth. Raises :class:`PlanningError` for bad input."""
        start = time.perf_counter()
        depth = check_depth(depth, fill_missing)
        intrinsics = intrinsics_for(depth.shape, intrinsics)
        if top < 1:
            raise PlanningError(f"top must be >= 1, got {top}")
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        distance = float(np.median(depth)) if camera_distance is None else float(camera_distance)
        adapter = camera_adapter(self.card, intrinsics, distance)
        if not adapter.identity:
            log.info("planning on a virtual camera: image scaled %.3f × %.3f, depths shifted %+.3f m", *adapter.scale, adapter.shift)
        image = adapter.image(depth)
        reach = float(self.card.gripper.get("fingertip_offset", 0.0))
        accept = (lambda g: antipodal_in_image(image, g, self.sampler, reach)) if self.check_image else None  # noqa: E731
        before = torch.get_num_threads()
        if self.threads:
            torch.set_num_threads(self.threads)
        try:
            ranked = self.policy(adapter.virtual).plan_ranked(image, rng, top, accept)
        finally:
            torch.set_num_threads(before)
        if ranked is None:
            return []
        grasps, quality, candidates = ranked
        grasps = adapter.to_original(grasps)
        elapsed = time.perf_counter() - start
        return [self._planned(grasps.take([i]), float(quality[i]), elapsed, candidates, intrinsics) for i in range(len(grasps))]

    @staticmethod
    def _planned(g: ImageGrasps, quality: float, elapsed: float, candidates: int, intrinsics: Intrinsics) -> PlannedGrasp:
        (u, v), angle, depth, width_px = g.centers[0], float(g.angles[0]), float(g.depths[0]), float(g.widths[0])
        position = intrinsics.rays([u], [v])[0] * depth
        jaw = np.array([math.cos(angle) / intrinsics.fx, math.sin(angle) / intrinsics.fy, 0.0])
        width = float(np.linalg.norm(jaw) * width_px * depth)
        x = jaw / np.linalg.norm(jaw)
        z = np.array([0.0, 0.0, 1.0])
        rotation = np.stack([x, np.cross(z, x), z], axis=1)
        return PlannedGrasp(float(u), float(v), angle, depth, width_px, position, rotation, width, quality, elapsed, candidates)


def load_planner(path: str | os.PathLike, sampler: SamplerSettings | None = None, cem: CEMSettings = CEMSettings(),
                 check_image: bool = True, threads: int = 1) -> Planner:
    """The planner of a trained GQ-CNN checkpoint (``model.pt``), with its model card; a
    checkpoint without a card is assumed to be trained for the default camera (a warning).
    ``threads``: see :class:`Planner`."""
    from graspaug.io.checkpoints import read_gqcnn

    net, card = read_gqcnn(Path(path))
    if card is None:
        log.warning("%s has no model card: assuming the default training camera (f = 525 px, 0.65-0.75 m) and 96 → 32 px crops", path)
    return Planner(net, ModelCard.from_dict(card, net.config.image_input), sampler, cem, check_image, threads)


def _planner(model) -> Planner:
    if isinstance(model, Planner):
        return model
    if model is None or hasattr(model, "success_probability"):
        return Planner(model)
    return load_planner(model)


def plan_grasps(depth_m: np.ndarray, intrinsics: Intrinsics | dict, model, top: int = 5, seed: int = 0,
                camera_distance: float | None = None, fill_missing: bool = False) -> list[PlannedGrasp]:
    """The ``top`` best grasps (best first) on ``depth_m`` (H, W) m seen with ``intrinsics``;
    ``model`` is a :class:`Planner`, a ``model.pt`` path, a GQ-CNN or None (random antipodal)."""
    return _planner(model).plan(depth_m, intrinsics, np.random.default_rng(seed), top, camera_distance, fill_missing)


def plan_grasp(depth_m: np.ndarray, intrinsics: Intrinsics | dict, model, seed: int = 0, camera_distance: float | None = None,
               fill_missing: bool = False) -> PlannedGrasp:
    """The best grasp on ``depth_m`` (H, W) m seen with ``intrinsics`` (px; an
    :class:`~graspaug.render.camera.Intrinsics` or a dict of fx, fy, cx, cy). ``model``: a
    :class:`Planner`, a ``model.pt`` path, a GQ-CNN or None (a random antipodal grasp).
    Raises :class:`NoGraspFound` when the image holds no antipodal pair, :class:`PlanningError`
    for bad input."""
    planned = plan_grasps(depth_m, intrinsics, model, 1, seed, camera_distance, fill_missing)
    if not planned:
        raise NoGraspFound("no antipodal pair of depth edges fits the gripper in this image")
    return planned[0]


def export_model(path: str | os.PathLike, out: str | os.PathLike) -> dict[str, Any]:
    """Write a GQ-CNN checkpoint as TorchScript for use without graspaug: ``<out>/model.ts``
    (``forward(images (N, 1, S, S) m, z (N,) m) → P(success) (N,)``, CPU, raw depths as in
    :meth:`~graspaug.nets.gqcnn.GQCNN.success_probability`), ``<out>/card.json`` (the model card
    and the input contract) and, when the ``onnx`` package is installed, ``<out>/model.onnx``.
    Returns the card JSON written."""
    import json

    from graspaug.io.atomic import atomic_path
    from graspaug.io.checkpoints import read_gqcnn

    net, card = read_gqcnn(path)
    model_card = ModelCard.from_dict(card, net.config.image_input)
    size = net.config.image_size
    example = (torch.full((4, 1, size, size), 0.7), torch.full((4,), 0.68))
    wrapped = SuccessProbability(net).eval()
    with torch.no_grad():
        traced = torch.jit.trace(wrapped, example)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_path(out / "model.ts") as tmp, open(tmp, "wb") as f:
        torch.jit.save(traced, f)
    files = ["model.ts"]
    import importlib.util

    if importlib.util.find_spec("onnx") is None:
        onnx_note = "not written: the onnx package is not installed"
    else:  # pragma: no cover - onnx is not a dependency
        torch.onnx.export(wrapped, example, str(out / "model.onnx"), input_names=["images", "z"], output_names=["p_success"],
                          dynamic_axes={"images": {0: "n"}, "z": {0: "n"}, "p_success": {0: "n"}})
        files.append("model.onnx")
        onnx_note = "written"
    info = {"source": str(path), "files": files, "onnx": onnx_note,
            "inputs": {"images": f"(N, 1, {size}, {size}) float32: grasp-centered depth crops in meters, jaw axis along the rows "
                                 f"({model_card.crop_size} px of the image averaged down to {model_card.out_size})",
                       "z": "(N,) float32: gripper depth in meters (camera frame)"},
            "output": "(N,) float32: predicted P(success)", "model_card": model_card.to_dict()}
    with atomic_path(out / "card.json") as tmp:
        tmp.write_text(json.dumps(info, indent=1) + "\n")
    return info


class SuccessProbability(torch.nn.Module):
    """P(success) (N,) of a GQ-CNN for crops (N, 1, S, S) m and gripper depths (N,) m (what is exported)."""

    def __init__(self, net) -> None:
        super().__init__()
        self.net = net

    def forward(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        return torch.softmax(self.net(images, z), dim=1)[:, 1]
