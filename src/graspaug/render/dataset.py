"""One shape's Dex-Net 2.0 datapoints: stable poses × camera views × table-parallel grasps."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import trimesh

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.io.meshes import read_mesh
from graspaug.render.camera import CameraPose, sample_viewpoint
from graspaug.render.collision import CollisionChecker, approach_directions
from graspaug.render.crops import CropGeometry, crops_by_ray_casting
from graspaug.render.settings import Intrinsics, RenderSettings
from graspaug.render.stable_poses import stable_poses
from graspaug.rng import shape_rng

log = logging.getLogger(__name__)

COLUMNS = (
    "grasp_index",
    "pose_id",
    "pose_probability",
    "image_id",
    "camera_height",
    "camera_tilt",
    "center_u",
    "center_v",
    "angle",
    "z",
    "width_px",
    "collision_free",
)


@dataclass(frozen=True)
class ShapeDatapoints:
    """``images`` (D, out, out) float32 depth crops (m); ``columns``: name → (D,) array, per
    :data:`COLUMNS` (``grasp_index`` indexes the grasps passed in; ``angle`` in radians is the
    jaw axis's direction in the full image; ``z`` (m) the grasp center's camera depth;
    ``camera_tilt`` in degrees); ``n_poses`` stable poses used; ``n_rays`` rays cast."""

    images: np.ndarray
    columns: dict[str, np.ndarray]
    n_poses: int
    n_rays: int

    def __len__(self) -> int:
        return len(self.images)


def grasp_image_geometry(
    camera: CameraPose, intrinsics: Intrinsics, centers: np.ndarray, axes: np.ndarray, opening: float
) -> dict[str, np.ndarray]:
    """Image center (u, v), jaw direction angle (rad), depth z (m) and jaw opening in pixels of
    grasps with table-frame ``centers`` and unit ``axes`` (G, 3)."""
    center_cam = camera.to_camera(centers)
    uv = intrinsics.project(center_cam)
    ends = [intrinsics.project(camera.to_camera(centers + sign * axes * opening / 2)) for sign in (-1.0, 1.0)]
    jaw = ends[1] - ends[0]
    return {
        "center_u": uv[:, 0],
        "center_v": uv[:, 1],
        "angle": np.arctan2(jaw[:, 1], jaw[:, 0]),
        "z": center_cam[:, 2],
        "width_px": np.linalg.norm(jaw, axis=1),
    }


@dataclass(frozen=True)
class Scene:
    """One camera view of the object in one stable pose, with the grasps it shows.

    ``pose`` (4, 4) places the object (its own frame) on the table; ``grasp_index`` (G,) indexes
    the grasps passed to :func:`plan_scenes`; ``centers`` / ``axes`` (G, 3) are those grasps in
    the table frame; ``image`` holds their image geometry (:func:`grasp_image_geometry`)."""

    pose_id: int
    pose: np.ndarray
    probability: float
    image_id: int
    camera: CameraPose
    grasp_index: np.ndarray
    centers: np.ndarray
    axes: np.ndarray
    image: dict[str, np.ndarray]


def crop_inside_image(
    u: np.ndarray, v: np.ndarray, angle: np.ndarray, crop: CropGeometry, intrinsics: Intrinsics
) -> np.ndarray:
    """(G,) bool: the crop around each grasp center (u, v) turned by ``angle`` reads only pixels
    of the image (so it is the crop a real camera image gives, without border padding)."""
    reach = (crop.crop_size - 1) / 2 * (np.abs(np.cos(angle)) + np.abs(np.sin(angle))) + 1
    return (
        (u - reach >= 0) & (u + reach <= intrinsics.width - 1) & (v - reach >= 0) & (v + reach <= intrinsics.height - 1)
    )


def plan_scenes(
    mesh: trimesh.Trimesh,
    centers: np.ndarray,
    axes: np.ndarray,
    opening: float,
    settings: RenderSettings,
    rng: np.random.Generator,
) -> tuple[list[Scene], int]:
    """The scenes of one object (``mesh`` in meters, its own frame) for grasps with ``centers``
    and unit jaw ``axes`` (N, 3) in that frame, and the number of stable poses used. A grasp
    appears in a pose's views if its jaw axis is within the tolerance of parallel to the table
    and its whole (rotated) crop lies inside the image; views without such grasps are left out."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    poses = stable_poses(mesh)
    keep = np.flatnonzero(poses.probabilities >= settings.min_pose_probability)[: settings.max_poses]
    limit = np.sin(np.radians(settings.axis_tolerance_deg))
    intrinsics = settings.intrinsics
    scenes = []
    for pose_id in keep:
        pose = poses.transforms[pose_id]
        rotation, translation = pose[:3, :3], pose[:3, 3]
        pose_axes = axes @ rotation.T
        aligned = np.flatnonzero(np.abs(pose_axes[:, 2]) <= limit)
        if len(aligned) == 0:
            continue
        pose_centers = centers[aligned] @ rotation.T + translation
        pose_axes = pose_axes[aligned]
        for image_id in range(settings.images_per_pose):
            camera = sample_viewpoint(settings.viewpoints, rng)
            image = grasp_image_geometry(camera, intrinsics, pose_centers, pose_axes, opening)
            chosen = np.flatnonzero(
                crop_inside_image(image["center_u"], image["center_v"], image["angle"], settings.crop, intrinsics)
            )
            if 0 < settings.max_grasps_per_image < len(chosen):
                chosen = np.sort(rng.choice(chosen, settings.max_grasps_per_image, replace=False))
            if len(chosen) == 0:
                continue
            scenes.append(
                Scene(
                    pose_id=int(pose_id),
                    pose=pose,
                    probability=float(poses.probabilities[pose_id]),
                    image_id=int(pose_id) * settings.images_per_pose + image_id,
                    camera=camera,
                    grasp_index=aligned[chosen],
                    centers=pose_centers[chosen],
                    axes=pose_axes[chosen],
                    image={k: v[chosen] for k, v in image.items()},
                )
            )
    return scenes, len(keep)


def render_shape(
    mesh: trimesh.Trimesh,
    centers: np.ndarray,
    axes: np.ndarray,
    gripper: ParallelJawGripper,
    settings: RenderSettings,
    rng: np.random.Generator,
) -> ShapeDatapoints:
    """Datapoints of one object (``mesh`` in meters, its own frame) for grasps with ``centers``
    and unit jaw ``axes`` (N, 3) in that frame: a crop, image geometry and approach collision
    check for every grasp of every scene of :func:`plan_scenes`."""
    scenes, n_poses = plan_scenes(mesh, centers, axes, gripper.max_width, settings, rng)
    checker = CollisionChecker(mesh, gripper, settings.approach_distance, settings.palm_clearance) if scenes else None
    images, rows, n_rays = [], {name: [] for name in COLUMNS}, 0
    for scene in scenes:
        crops, rays = crops_by_ray_casting(
            mesh,
            scene.camera,
            settings.intrinsics,
            np.stack([scene.image["center_u"], scene.image["center_v"]], axis=1),
            scene.image["angle"],
            settings.crop,
            pose=scene.pose,
        )
        n_rays += rays
        images.append(crops)
        count = len(scene.grasp_index)
        rows["grasp_index"].append(scene.grasp_index)
        rows["pose_id"].append(np.full(count, scene.pose_id))
        rows["pose_probability"].append(np.full(count, scene.probability))
        rows["image_id"].append(np.full(count, scene.image_id))
        rows["camera_height"].append(np.full(count, scene.camera.height))
        rows["camera_tilt"].append(np.full(count, np.degrees(scene.camera.tilt)))
        for name, values in scene.image.items():
            rows[name].append(values)
        rows["collision_free"].append(
            checker.collision_free(scene.centers, scene.axes, approach_directions(scene.axes), pose=scene.pose)
        )
    if not images:
        out = settings.crop.out_size
        empty = {
            name: np.zeros(
                0,
                dtype=bool
                if name == "collision_free"
                else int
                if name in ("grasp_index", "pose_id", "image_id")
                else float,
            )
            for name in COLUMNS
        }
        return ShapeDatapoints(np.zeros((0, out, out), np.float32), empty, n_poses, n_rays)
    return ShapeDatapoints(
        np.concatenate(images), {name: np.concatenate(parts) for name, parts in rows.items()}, n_poses, n_rays
    )


#: Copied from the corpus table onto each datapoint; ``split`` is empty for the original objects (the ``split``
#: stage's shape table holds it, so a new split renders nothing again) and ``train`` for generated shapes.
SHAPE_COLUMNS = ("shape_id", "origin", "split", "base_size", "pool", "order")


def datapoints_index(shapes, by_shape: dict, results: list, threshold: float) -> tuple[list, list, list, int, list]:
    """Gather every shape's datapoints: (image arrays, index parts, skipped shapes with reasons,
    rays cast, stable poses per shape). ``shapes``: the corpus table; ``by_shape``: shape id →
    its grasp rows; ``results``: (ShapeDatapoints or None, reason) per shape; ``threshold``:
    robust ε above which a grasp succeeds (label = collision free and success)."""
    images, parts, skipped, n_rays, n_poses = [], [], [], 0, []
    for shape, (data, reason) in zip(shapes.itertuples(index=False), results):
        if data is None:
            skipped.append({"shape_id": shape.shape_id, "reason": reason})
            log.warning("render: %s has no datapoints: %s", shape.shape_id, reason)
            continue
        rows = by_shape[shape.shape_id].iloc[data.columns["grasp_index"]]
        part = pd.DataFrame({name: [getattr(shape, name, None)] * len(data) for name in SHAPE_COLUMNS})
        part["grasp_id"] = rows["grasp_id"].to_numpy()
        for name, values in data.columns.items():
            if name != "grasp_index":
                part[name] = values
        part["eps"] = rows["eps_mean"].to_numpy()
        part["success"] = part["eps"] > threshold
        part["label"] = part["collision_free"] & part["success"]
        parts.append(part)
        images.append(data.images)
        n_rays += data.n_rays
        n_poses.append(data.n_poses)
    return images, parts, skipped, n_rays, n_poses


def render_file(
    path: Path,
    shape_id: str,
    centers: np.ndarray,
    axes: np.ndarray,
    settings: RenderSettings,
    hand,
    seed: int,
    stream: str = "render",
) -> tuple[ShapeDatapoints | None, str | None]:
    """One shape's datapoints, or None and why there are none; its random choices (camera views, grasp subsets) from
    the shape's stream ``stream`` of ``seed`` (:func:`graspaug.rng.shape_rng`)."""
    if len(centers) == 0:
        return None, "the shape has no grasps"
    try:
        mesh = read_mesh(path)
    except Exception as exc:  # a broken file is skipped with its reason, not fatal
        return None, f"mesh could not be read: {exc}"
    try:
        data = render_shape(mesh, centers, axes, hand, settings, shape_rng(seed, shape_id, stream))
    except Exception as exc:  # a degenerate mesh (no hull, no volume) is skipped with its reason
        return None, f"rendering failed: {type(exc).__name__}: {exc}"
    if len(data) == 0:
        return None, (
            f"none of its {len(centers)} grasps has its jaw axis within {settings.axis_tolerance_deg} deg of the table "
            f"in its {data.n_poses} stable poses"
        )
    return data, None
