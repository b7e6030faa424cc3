"""The planner: a GQ-CNN (or none) with its model card, planning grasps on a depth image of any
camera and returning them in the camera frame."""

from __future__ import annotations

import logging
import math
import os
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from graspaug.planning.camera import CameraAdapter, camera_adapter, check_depth, intrinsics_for
from graspaug.planning.card import ModelCard
from graspaug.planning.errors import NoGraspFound, PlanningError
from graspaug.planning.grasps import ImageGrasps, jaw_endpoints, opening_widths
from graspaug.planning.policies import CrossEntropyGraspPolicy, GraspPolicy, RandomAntipodalPolicy
from graspaug.planning.sampler import antipodal_in_image
from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.render.settings import Intrinsics

log = logging.getLogger(__name__)


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
        """The image grasp as one row of :class:`~graspaug.planning.grasps.ImageGrasps`."""
        return ImageGrasps(
            np.array([[self.u, self.v]]), np.array([self.angle]), np.array([self.depth]), np.array([self.width_px])
        )

    @property
    def jaw_pixels(self) -> np.ndarray:
        """(2, 2) the two jaw positions (u, v) px in the image (:func:`~graspaug.planning.grasps.jaw_endpoints`)."""
        return jaw_endpoints(np.array([[self.u, self.v]]), np.array([self.angle]), np.array([self.width_px]))[0]

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers for JSON."""
        return {
            "u": self.u,
            "v": self.v,
            "angle": self.angle,
            "depth": self.depth,
            "width_px": self.width_px,
            "position": self.position.tolist(),
            "rotation": self.rotation.tolist(),
            "pose": self.pose.tolist(),
            "width": self.width,
            "quality": None if math.isnan(self.quality) else self.quality,
            "planning_time": self.planning_time,
            "candidates": self.candidates,
        }


class Planner:
    """A GQ-CNN (or none: a random antipodal grasp) with its model card and sampler settings.

    ``sampler`` and ``cem`` default to the simulator's (Dex-Net 2.0's) with the jaw opening of
    the card's gripper. With ``check_image`` (the default) a grasp is returned only if it fits the
    gripper (its opening in meters at its gripper depth, :attr:`PlannedGrasp.width`, at most the
    card's ``max_width``: the sampler bounds the opening at the depth of one jaw's edge, and a grasp
    deeper than that edge opens wider) and the image shows it antipodal and reachable
    (:func:`~graspaug.planning.sampler.antipodal_in_image`: jaws on depth edges inside the friction
    cone, free space beside them down to the grasp depth); the candidates, filtered so before they
    are ranked, are then the last cross-entropy iteration's and the seeds. Dex-Net's policy,
    which the simulated robot runs (``check_image=False``), trusts the network instead.
    ``threads``: torch threads while planning (1 suits the network's small batches; 0 leaves
    torch's setting).
    """

    def __init__(
        self,
        net=None,
        card: ModelCard | None = None,
        sampler: SamplerSettings | None = None,
        cem: CEMSettings = CEMSettings(),
        check_image: bool = True,
        threads: int = 1,
    ) -> None:
        self.net, self.check_image, self.threads = (None if net is None else net.eval()), check_image, threads
        image_input = getattr(getattr(net, "config", None), "image_input", "depth")
        self.card = card if card is not None else ModelCard(image_input=image_input, assumed=True)
        if sampler is None:
            sampler = SamplerSettings(max_width=float(self.card.gripper.get("max_width", SamplerSettings().max_width)))
        self.sampler, self.cem = sampler, cem

    @property
    def max_width(self) -> float:
        """The widest jaw opening (m) of the card's gripper (the sampler's when the card names none)."""
        return float(self.card.gripper.get("max_width", self.sampler.max_width))

    def policy(self, intrinsics: Intrinsics) -> GraspPolicy:
        """The grasp policy for images of a camera with ``intrinsics`` (the network's, or random antipodal)."""
        if self.net is None:
            return RandomAntipodalPolicy(intrinsics, self.sampler)
        return CrossEntropyGraspPolicy(self.net, intrinsics, self.sampler, self.cem, self.card.geometry)

    def plan(
        self,
        depth: np.ndarray,
        intrinsics: Intrinsics | dict,
        rng: np.random.Generator | int = 0,
        top: int = 1,
        camera_distance: float | None = None,
        fill_missing: bool = False,
    ) -> list[PlannedGrasp]:
        """Up to ``top`` distinct grasps on ``depth`` (H, W) m, best first (near-duplicates of a
        better grasp dropped: :func:`~graspaug.planning.grasps.distinct_grasps`; the best is the same
        for every ``top``); [] when the image holds no antipodal pair. ``camera_distance`` (m, the
        table's distance along the optical axis) defaults to the image's median depth. Raises
        :class:`PlanningError` for bad input."""
        start = time.perf_counter()
        depth, intrinsics, adapter = self._view(depth, intrinsics, camera_distance, fill_missing)
        if top < 1:
            raise PlanningError(f"top must be >= 1, got {top}")
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        if not adapter.identity:
            log.info(
                "planning on a virtual camera: image scaled %.3f × %.3f, depths shifted %+.3f m",
                *adapter.scale,
                adapter.shift,
            )
        image = adapter.image(depth)
        reach = float(self.card.gripper.get("fingertip_offset", 0.0))
        accept = None
        if self.check_image:
            widest = self.max_width * (1 + 1e-9)

            def accept(g: ImageGrasps) -> np.ndarray:  # virtual-image grasps → (N,) bool
                fits = opening_widths(adapter.to_original(g), intrinsics.fx, intrinsics.fy) <= widest
                return fits & antipodal_in_image(image, g, self.sampler, reach)

        with self._torch_threads():
            ranked = self.policy(adapter.virtual).plan_ranked(image, rng, top, accept)
        if ranked is None:
            return []
        grasps, quality, candidates = ranked
        grasps = adapter.to_original(grasps)
        elapsed = time.perf_counter() - start
        return [
            self._planned(grasps.take([i]), float(quality[i]), elapsed, candidates, intrinsics)
            for i in range(len(grasps))
        ]

    def network_crops(
        self,
        depth: np.ndarray,
        intrinsics: Intrinsics | dict,
        grasps: list[PlannedGrasp],
        camera_distance: float | None = None,
        fill_missing: bool = False,
    ) -> tuple[np.ndarray, np.ndarray]:
        """What the network saw of each planned grasp: its depth crops (n, out, out) m, jaw axis
        horizontal (:func:`~graspaug.render.crops.crops_from_depth_image` with the card's
        geometry, on the image resampled to the training camera as :meth:`plan` does), and each
        grasp's jaw opening (n,) in crop pixels. Same arguments as :meth:`plan`."""
        from graspaug.render.crops import crops_from_depth_image

        depth, intrinsics, adapter = self._view(depth, intrinsics, camera_distance, fill_missing)
        geometry = self.card.geometry
        if not grasps:
            return np.zeros((0, geometry.out_size, geometry.out_size), np.float32), np.zeros(0)
        image = ImageGrasps(
            *(np.concatenate([getattr(g.grasp, k) for g in grasps]) for k in ("centers", "angles", "depths", "widths"))
        )
        virtual = adapter.to_virtual(image)
        crops = crops_from_depth_image(adapter.image(depth), virtual.centers, virtual.angles, geometry)
        return crops, virtual.widths / geometry.factor

    def score(
        self,
        depth: np.ndarray,
        intrinsics: Intrinsics | dict,
        grasps: ImageGrasps,
        camera_distance: float | None = None,
        fill_missing: bool = False,
    ) -> np.ndarray:
        """The network's success probability (N,) of each of ``grasps`` (image grasps on ``depth`` (H, W) m, as
        :meth:`plan` returns them, e.g. another planner's), seen as :meth:`plan` sees them (the image resampled
        to the training camera). Same arguments as :meth:`plan`; the random antipodal planner has no scores."""
        if self.net is None:
            raise PlanningError("the random antipodal planner has no network to score grasps with")
        depth, intrinsics, adapter = self._view(depth, intrinsics, camera_distance, fill_missing)
        with self._torch_threads():
            return self.policy(adapter.virtual).quality(adapter.image(depth), adapter.to_virtual(grasps))

    def _view(
        self, depth: np.ndarray, intrinsics: Intrinsics | dict, camera_distance: float | None, fill_missing: bool
    ) -> tuple[np.ndarray, Intrinsics, CameraAdapter]:
        """The checked depth image (H, W) m, its camera, and the adapter to the card's training camera
        (the table at ``camera_distance`` m, or the image's median depth) that :meth:`plan`,
        :meth:`network_crops` and :meth:`score` all see it through."""
        depth = check_depth(depth, fill_missing)
        intrinsics = intrinsics_for(depth.shape, intrinsics)
        distance = float(np.median(depth)) if camera_distance is None else float(camera_distance)
        return depth, intrinsics, camera_adapter(self.card, intrinsics, distance)

    @contextmanager
    def _torch_threads(self):
        """Torch runs on :attr:`threads` threads inside (its setting unchanged with 0), restored after."""
        before = torch.get_num_threads()
        if self.threads:
            torch.set_num_threads(self.threads)
        try:
            yield
        finally:
            torch.set_num_threads(before)

    @staticmethod
    def _planned(
        g: ImageGrasps, quality: float, elapsed: float, candidates: int, intrinsics: Intrinsics
    ) -> PlannedGrasp:
        (u, v), angle, depth, width_px = g.centers[0], float(g.angles[0]), float(g.depths[0]), float(g.widths[0])
        position = intrinsics.rays([u], [v])[0] * depth
        jaw = np.array([math.cos(angle) / intrinsics.fx, math.sin(angle) / intrinsics.fy, 0.0])
        width = float(opening_widths(g, intrinsics.fx, intrinsics.fy)[0])
        x = jaw / np.linalg.norm(jaw)
        z = np.array([0.0, 0.0, 1.0])
        rotation = np.stack([x, np.cross(z, x), z], axis=1)
        return PlannedGrasp(
            float(u), float(v), angle, depth, width_px, position, rotation, width, quality, elapsed, candidates
        )


def load_planner(
    path: str | os.PathLike,
    sampler: SamplerSettings | None = None,
    cem: CEMSettings = CEMSettings(),
    check_image: bool = True,
    threads: int = 1,
) -> Planner:
    """The planner of a trained GQ-CNN checkpoint (``model.pt``), with its model card; a
    checkpoint without a card is assumed to be trained for the default camera (a warning).
    ``threads``: see :class:`Planner`."""
    from graspaug.io.checkpoints import read_gqcnn

    path = Path(path)
    if path.is_dir():
        inside = sorted(p.relative_to(path).as_posix() for p in path.rglob("model.pt"))
        shown = ", ".join(inside[:6]) + (f" and {len(inside) - 6} more" if len(inside) > 6 else "")
        held = f": it holds {f'{len(inside)} networks, ' if len(inside) > 1 else ''}{shown}" if inside else ""
        raise PlanningError(f"model {path}: a folder, not a model.pt file{held}")
    if path.is_file():
        with open(path, "rb") as f:
            if f.read(6) == b"\x93NUMPY":
                raise PlanningError(
                    f"model {path}: a NumPy array (.npy), not a trained GQ-CNN (a model.pt file); the depth image "
                    "is the first argument, the network --model"
                )
    net, card = read_gqcnn(path)
    if card is None:
        log.warning(
            "%s has no model card: assuming the default training camera (f = 525 px, 0.65-0.75 m) and 96 → 32 px crops",
            path,
        )
    return Planner(net, ModelCard.from_dict(card, net.config.image_input), sampler, cem, check_image, threads)


def _planner(model) -> Planner:
    if isinstance(model, Planner):
        return model
    if model is None or hasattr(model, "success_probability"):
        return Planner(model)
    return load_planner(model)


def plan_grasps(
    depth_m: np.ndarray,
    intrinsics: Intrinsics | dict,
    model,
    top: int = 5,
    seed: int = 0,
    camera_distance: float | None = None,
    fill_missing: bool = False,
) -> list[PlannedGrasp]:
    """The ``top`` best distinct grasps (best first) on ``depth_m`` (H, W) m seen with ``intrinsics``;
    ``model`` is a :class:`Planner`, a ``model.pt`` path, a GQ-CNN or None (random antipodal)."""
    return _planner(model).plan(depth_m, intrinsics, np.random.default_rng(seed), top, camera_distance, fill_missing)


def plan_grasp(
    depth_m: np.ndarray,
    intrinsics: Intrinsics | dict,
    model,
    seed: int = 0,
    camera_distance: float | None = None,
    fill_missing: bool = False,
) -> PlannedGrasp:
    """The best grasp on ``depth_m`` (H, W) m seen with ``intrinsics`` (px; an
    :class:`~graspaug.render.settings.Intrinsics` or a dict of fx, fy, cx, cy). ``model``: a
    :class:`Planner`, a ``model.pt`` path, a GQ-CNN or None (a random antipodal grasp).
    Raises :class:`NoGraspFound` when the image holds no antipodal pair, :class:`PlanningError`
    for bad input."""
    planned = plan_grasps(depth_m, intrinsics, model, 1, seed, camera_distance, fill_missing)
    if not planned:
        raise NoGraspFound("no antipodal pair of depth edges fits the gripper in this image")
    return planned[0]
