"""Depth images from pybullet's renderer for the same cameras: the full-image reference.

Our pinhole convention (OpenCV axes, pixel centers at integer coordinates) is turned into
OpenGL view and projection matrices; the z-buffer is turned back into metric depth with
``depth = far * near / (far - (far - near) * zbuffer)``. Used by the render benchmark and the
tests as an independent check of the ray-cast crops, and by simulated robot trials.
"""

from __future__ import annotations

import numpy as np
import pybullet
import trimesh

from graspaug.render.camera import CameraPose
from graspaug.render.settings import Intrinsics


def view_matrix(camera: CameraPose) -> list[float]:
    """pybullet's (column-major) view matrix of ``camera``: table frame → OpenGL camera frame
    (x right, y up, looking along -z)."""
    rotation = camera.rotation * np.array([1.0, -1.0, -1.0])  # OpenCV → OpenGL camera axes
    view = np.eye(4)
    view[:3, :3] = rotation.T
    view[:3, 3] = -rotation.T @ camera.position
    return view.T.ravel().tolist()


def projection_matrix(intrinsics: Intrinsics, near: float, far: float) -> list[float]:
    """pybullet's (column-major) projection matrix for pinhole ``intrinsics``: pixel (u, v)
    covers [u - 0.5, u + 0.5] × [v - 0.5, v + 0.5], row 0 at the top."""
    w, h = intrinsics.width, intrinsics.height
    proj = np.zeros((4, 4))
    proj[0, 0] = 2 * intrinsics.fx / w
    proj[0, 2] = 1 - 2 * (intrinsics.cx + 0.5) / w
    proj[1, 1] = 2 * intrinsics.fy / h
    proj[1, 2] = 2 * (intrinsics.cy + 0.5) / h - 1
    proj[2, 2] = -(far + near) / (far - near)
    proj[2, 3] = -2 * far * near / (far - near)
    proj[3, 2] = -1.0
    return proj.T.ravel().tolist()


def depth_from_zbuffer(zbuffer: np.ndarray, near: float, far: float) -> np.ndarray:
    """Metric depth (m) from pybullet's nonlinear depth buffer in [0, 1]."""
    return far * near / (far - (far - near) * np.asarray(zbuffer, dtype=float))


def render_depth(client: int, camera: CameraPose, intrinsics: Intrinsics, near: float, far: float) -> np.ndarray:
    """The depth image (height, width) float64 (m) that ``camera`` sees in pybullet ``client``
    (TinyRenderer, clipping planes ``near`` and ``far`` m)."""
    _, _, _, zbuffer, _ = pybullet.getCameraImage(
        intrinsics.width,
        intrinsics.height,
        view_matrix(camera),
        projection_matrix(intrinsics, near, far),
        renderer=pybullet.ER_TINY_RENDERER,
        flags=pybullet.ER_NO_SEGMENTATION_MASK,
        physicsClientId=client,
    )
    return depth_from_zbuffer(np.reshape(zbuffer, (intrinsics.height, intrinsics.width)), near, far)


class PybulletDepthScene:
    """One object on a table in a pybullet DIRECT client, rendered by its software TinyRenderer.

    The table is a 4 m × 4 m box whose top is the plane z = 0.
    """

    def __init__(self, near: float = 0.1, far: float = 2.0) -> None:
        self.near, self.far = near, far
        self.client = pybullet.connect(pybullet.DIRECT)
        table = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[2.0, 2.0, 0.05], physicsClientId=self.client)
        pybullet.createMultiBody(baseVisualShapeIndex=table, basePosition=[0, 0, -0.05], physicsClientId=self.client)
        self.body: int | None = None

    def place(self, mesh: trimesh.Trimesh, pose: np.ndarray | None = None) -> None:
        """Put ``mesh`` (m, its own frame) on the table at ``pose`` (4, 4), replacing any other."""
        if self.body is not None:
            pybullet.removeBody(self.body, physicsClientId=self.client)
        pose = np.eye(4) if pose is None else np.asarray(pose, dtype=float)
        shape = pybullet.createVisualShape(
            pybullet.GEOM_MESH,
            vertices=mesh.vertices.tolist(),
            indices=mesh.faces.ravel().tolist(),
            physicsClientId=self.client,
        )
        quaternion = trimesh.transformations.quaternion_from_matrix(pose)  # w, x, y, z
        self.body = pybullet.createMultiBody(
            baseVisualShapeIndex=shape,
            basePosition=pose[:3, 3].tolist(),
            baseOrientation=[*quaternion[1:], quaternion[0]],
            physicsClientId=self.client,
        )

    def depth(self, camera: CameraPose, intrinsics: Intrinsics) -> np.ndarray:
        """The depth image (height, width) float64 (m) that ``camera`` sees."""
        return render_depth(self.client, camera, intrinsics, self.near, self.far)

    def close(self) -> None:
        pybullet.disconnect(physicsClientId=self.client)

    def __enter__(self) -> PybulletDepthScene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
