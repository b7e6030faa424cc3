"""Speed and agreement of our ray-cast grasp crops against full-image rendering, in one run.

Both make the same crops (same shapes, stable poses, cameras and grasps):

- full-image reference: per scene, one 640×480 depth image from pybullet's TinyRenderer
  (`PybulletDepthScene`), then rotate/crop/resize every grasp of that scene
  (`crops_from_depth_image`: scipy bilinear sampling + block average);
- ours: `crops_by_ray_casting` (rays only where the crops read the object, analytic table,
  compiled sampling).

Scenes: the render stage's defaults on the first default shapes as ingest makes them, with
Dex-Net antipodal grasps (grasps stage defaults). Scene set-up (loading a mesh into pybullet,
embree's first build) is left out of both timings. Prints both times, the speed ratio, and
the crops' difference (mean and table pixels) against the TinyRenderer crops and against a
full ray-cast image put through the same rotate/crop/resize. Also times the stable poses of
the same shapes against ``trimesh.poses.compute_stable_poses`` (the reference they equal).

    python bench/render_speed.py --shapes 20
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import trimesh
from _corpus import default_shapes

from graspaug.grasping.antipodal import sample_antipodal_grasps
from graspaug.pipeline.params.model import GraspsParams, RenderParams
from graspaug.render.crops import crops_by_ray_casting, crops_from_depth_image
from graspaug.render.dataset import plan_scenes
from graspaug.render.depth import render_depth
from graspaug.render.pybullet_depth import PybulletDepthScene
from graspaug.render.stable_poses import stable_poses
from graspaug.rng import shape_rng


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--shapes", type=int, default=20, help="first N default shapes")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    grasp_cfg, settings = GraspsParams(), RenderParams()
    hand = grasp_cfg.gripper
    shapes = default_shapes(args.shapes)
    jobs = []
    for shape in shapes:
        grasps = sample_antipodal_grasps(shape.mesh, hand, grasp_cfg.sampler, shape_rng(args.seed, shape.shape_id))
        scenes, _ = plan_scenes(
            shape.mesh,
            grasps.center,
            grasps.axis,
            hand.max_width,
            settings,
            shape_rng(args.seed, shape.shape_id, "render"),
        )
        jobs += [(shape.mesh, scene) for scene in scenes]
    n_grasps = sum(len(scene.grasp_index) for _, scene in jobs)
    print(
        f"{len(shapes)} shapes, {len(jobs)} scenes, {n_grasps} crops "
        f"({settings.intrinsics.width}x{settings.intrinsics.height}, "
        f"{settings.crop.crop_size}->{settings.crop.out_size} px)"
    )

    def grasp_pixels(scene):
        return np.stack([scene.image["center_u"], scene.image["center_v"]], axis=1), scene.image["angle"]

    for shape in shapes:
        shape.mesh.ray.intersects_first(
            np.zeros((1, 3)), np.ones((1, 3))
        )  # embree's build per mesh (set-up), not timed
    crops_by_ray_casting(
        jobs[0][0],
        jobs[0][1].camera,
        settings.intrinsics,
        *grasp_pixels(jobs[0][1]),
        settings.crop,
        pose=jobs[0][1].pose,
    )

    reference, reference_time = [], 0.0
    with PybulletDepthScene() as pybullet_scene:
        placed = None
        for mesh, scene in jobs:
            if placed != (id(mesh), scene.pose_id):
                pybullet_scene.place(mesh, scene.pose)  # set-up, not timed
                placed = (id(mesh), scene.pose_id)
            start = time.perf_counter()
            image = pybullet_scene.depth(scene.camera, settings.intrinsics)
            reference.append(crops_from_depth_image(image, *grasp_pixels(scene), settings.crop))
            reference_time += time.perf_counter() - start

    ours, ours_time, rays = [], 0.0, 0
    for mesh, scene in jobs:
        start = time.perf_counter()
        crops, n_rays = crops_by_ray_casting(
            mesh, scene.camera, settings.intrinsics, *grasp_pixels(scene), settings.crop, pose=scene.pose
        )
        ours_time += time.perf_counter() - start
        ours.append(crops)
        rays += n_rays

    start = time.perf_counter()
    expected = [trimesh.poses.compute_stable_poses(shape.mesh) for shape in shapes]
    trimesh_time = time.perf_counter() - start
    start = time.perf_counter()
    got = [stable_poses(shape.mesh) for shape in shapes]
    poses_time = time.perf_counter() - start
    same = all(
        len(g) == len(p) and np.allclose(np.sort(g.probabilities), np.sort(p), atol=1e-12)
        for g, (_, p) in zip(got, expected)
    )

    raycast_reference, table_only = [], []
    for mesh, scene in jobs:
        moved = mesh.copy()
        moved.apply_transform(scene.pose)
        raycast_reference.append(
            crops_from_depth_image(
                render_depth(moved, scene.camera, settings.intrinsics), *grasp_pixels(scene), settings.crop
            )
        )
        table_only.append(
            crops_from_depth_image(
                render_depth(None, scene.camera, settings.intrinsics), *grasp_pixels(scene), settings.crop
            )
        )
    ours_all, pybullet_all = np.concatenate(ours), np.concatenate(reference)
    raycast_all, table_all = np.concatenate(raycast_reference), np.concatenate(table_only)
    # table pixels: where no object pixel is within one output pixel (in our crops)
    from scipy import ndimage

    object_mask = np.abs(ours_all - table_all) > 1e-9
    table_mask = ~ndimage.binary_dilation(object_mask, structure=np.ones((1, 3, 3), bool))

    print(
        f"full-image reference (TinyRenderer + rotate/crop/resize): {reference_time:.2f} s "
        f"({1e3 * reference_time / len(jobs):.1f} ms per scene)"
    )
    print(
        f"ours (ray-cast crops): {ours_time:.2f} s ({1e3 * ours_time / len(jobs):.2f} ms per scene, "
        f"{rays / n_grasps:.0f} rays per crop "
        f"vs {settings.intrinsics.width * settings.intrinsics.height / (n_grasps / len(jobs)):.0f} pixels per crop "
        "for a full image)"
    )
    print(f"speed ratio: {reference_time / ours_time:.1f}x (target >= 20x)")
    diff = np.abs(ours_all - pybullet_all)
    print(
        f"vs TinyRenderer crops: mean |diff| {1e3 * diff.mean():.3f} mm (target <= 1 mm), table pixels max "
        f"{1e3 * diff[table_mask].max():.4f} mm "
        f"({table_mask.mean():.0%} of pixels; target <= 0.1 mm)"
    )
    diff = np.abs(ours_all - raycast_all)
    print(f"vs full ray-cast crops: mean |diff| {1e3 * diff.mean():.2e} mm, max {1e3 * diff.max():.2e} mm")
    print(
        f"stable poses of the {len(shapes)} shapes: trimesh {trimesh_time:.2f} s, ours {poses_time:.3f} s, "
        f"{trimesh_time / poses_time:.0f}x; "
        f"same poses and probabilities: {same}"
    )


if __name__ == "__main__":
    main()
