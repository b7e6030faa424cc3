"""Planning a grasp on a depth image with a trained GQ-CNN: the public API.

    import numpy as np
    from graspaug.planning import load_planner, plan_grasp

    planner = load_planner("models/gqcnn/s0/targeted/50-1/model.pt")
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

The card also holds the network's validation operating point (a threshold on P(success)) and the
range of its training data: :mod:`graspaug.planning.limits` gives the floor below which a planned
grasp is rejected (``quality_floor``) and the lines that say where an image lies outside the training
data (``range_warnings``: camera distance, object height above the table, gripper depth). It is not
re-exported here, so the simulated robot, which imports this package, does not depend on it.

Modules: :mod:`~graspaug.planning.settings` (sampler and cross-entropy settings, plain data),
:mod:`~graspaug.planning.grasps` (image grasps, jaw endpoints, Dex-Net's feature vector),
:mod:`~graspaug.planning.sampler` (antipodal pairs on depth edges), :mod:`~graspaug.planning.policies`
(the cross-entropy and random policies), :mod:`~graspaug.planning.card` (the model card),
:mod:`~graspaug.planning.camera` (intrinsics, depth checks, resampling to the training camera),
:mod:`~graspaug.planning.inputs` (depth images and intrinsics from files),
:mod:`~graspaug.planning.limits` (the quality floor and the out-of-range warnings),
:mod:`~graspaug.planning.planner` (the planner) and :mod:`~graspaug.planning.export` (TorchScript
export). The names below load their module (and torch) on first use, so that importing the
settings stays light.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from graspaug.planning.camera import (
        DISTANCE_TOLERANCE,
        MAX_DISTANCE_RATIO,
        MAX_DOWNSAMPLING,
        MAX_UPSAMPLING,
        CameraAdapter,
        camera_adapter,
        check_depth,
        intrinsics_for,
    )
    from graspaug.planning.card import ModelCard
    from graspaug.planning.errors import NoGraspFound, PlanningError
    from graspaug.planning.export import SuccessProbability, export_model
    from graspaug.planning.inputs import read_depth_image, read_intrinsics
    from graspaug.planning.planner import PlannedGrasp, Planner, load_planner, plan_grasp, plan_grasps

__all__ = [
    "ModelCard",
    "PlannedGrasp",
    "Planner",
    "PlanningError",
    "NoGraspFound",
    "load_planner",
    "plan_grasp",
    "plan_grasps",
    "intrinsics_for",
    "read_depth_image",
    "read_intrinsics",
    "export_model",
    "check_depth",
    "CameraAdapter",
    "camera_adapter",
    "SuccessProbability",
    "MAX_UPSAMPLING",
    "MAX_DOWNSAMPLING",
    "MAX_DISTANCE_RATIO",
    "DISTANCE_TOLERANCE",
]

#: Public name → the module of this package that defines it.
_EXPORTS = {
    "ModelCard": "card",
    "PlanningError": "errors",
    "NoGraspFound": "errors",
    "PlannedGrasp": "planner",
    "Planner": "planner",
    "load_planner": "planner",
    "plan_grasp": "planner",
    "plan_grasps": "planner",
    "intrinsics_for": "camera",
    "check_depth": "camera",
    "CameraAdapter": "camera",
    "camera_adapter": "camera",
    "MAX_UPSAMPLING": "camera",
    "MAX_DOWNSAMPLING": "camera",
    "MAX_DISTANCE_RATIO": "camera",
    "DISTANCE_TOLERANCE": "camera",
    "read_depth_image": "inputs",
    "read_intrinsics": "inputs",
    "export_model": "export",
    "SuccessProbability": "export",
}


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
