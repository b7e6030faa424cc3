"""The planner's inputs from files: a depth image and the camera intrinsics."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from graspaug.planning.errors import PlanningError

#: A 16-bit depth PNG whose median reading is below this (mm) holds some other unit (no camera sees
#: a scene 2 cm away).
MIN_PNG_MEDIAN_MM = 20
#: ... and one whose median reading is below this (mm, a table 10 cm from the camera, nearer than a grasping
#: camera stands: the gripper alone is longer) likely holds centimeters.
MIN_PNG_TABLE_MM = 100


def read_depth_image(path: str | os.PathLike) -> np.ndarray:
    """A depth image (H, W) float64 m from a ``.npy`` file (meters) or a 16-bit PNG
    (millimeters; 0 = no reading, returned as NaN)."""
    path = Path(path)
    if not path.is_file():
        raise PlanningError(f"depth image {path}: no such file")
    if path.stat().st_size == 0:
        raise PlanningError(f"depth image {path}: the file is empty")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            return np.load(path, allow_pickle=False)
        except (ValueError, EOFError, OSError) as exc:
            why = "it holds Python objects" if "pickle" in str(exc) else f"{type(exc).__name__}: {exc}".splitlines()[0]
            raise PlanningError(
                f"depth image {path}: not a numeric .npy array ({why}); "
                "write one with numpy.save(path, depth_in_meters)"
            ) from None
    if suffix == ".png":
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(path) as image:
                pixels, mode = np.asarray(image), image.mode
        except (UnidentifiedImageError, OSError) as exc:
            raise PlanningError(f"depth image {path}: not a readable PNG ({str(exc).splitlines()[0]})") from None
        if pixels.dtype != np.uint16 and not (pixels.dtype == np.int32 and pixels.max() < 2**16):
            raise PlanningError(
                f"depth image {path}: a depth PNG must be 16-bit grayscale in millimeters, got mode {mode}"
            )
        valid = pixels[pixels > 0]
        if valid.size and np.median(valid) < MIN_PNG_MEDIAN_MM:
            raise PlanningError(
                f"depth image {path}: its median reading is {np.median(valid):g}, but a 16-bit depth PNG holds "
                f"millimeters (a camera 0.7 m away reads 700): it looks like meters; save meters as .npy instead"
            )
        if valid.size and np.median(valid) < MIN_PNG_TABLE_MM:
            raise PlanningError(
                f"depth image {path}: its median reading is {np.median(valid):g}, a table {np.median(valid) / 10:g} "
                "cm from the camera in millimeters: it looks like centimeters; a 16-bit depth PNG holds millimeters"
            )
        depth = pixels.astype(np.float64) / 1000.0
        depth[pixels == 0] = np.nan
        return depth
    raise PlanningError(
        f"{path}: depth images are .npy (meters) or 16-bit .png (millimeters), got {suffix or 'no suffix'}"
    )


def read_intrinsics(
    path: str | os.PathLike | None,
    fx: float | None,
    fy: float | None,
    cx: float | None,
    cy: float | None,
    shape: tuple[int, ...],
) -> dict:
    """Intrinsics (px) from a JSON file (fx, fy, cx, cy; width and height optional) or from
    values: fy defaults to fx, the principal point to the image center of ``shape`` (H, W)."""
    if path is not None:
        if any(v is not None for v in (fx, fy, cx, cy)):
            raise PlanningError("give the intrinsics as a JSON file or as --fx/--fy/--cx/--cy, not both")
        try:
            values = json.loads(Path(path).read_text())
        except (OSError, ValueError) as exc:
            raise PlanningError(
                f"{path}: not a readable JSON file of fx, fy, cx, cy ({str(exc).splitlines()[0]})"
            ) from None
        if not isinstance(values, dict):
            raise PlanningError(f"{path}: must hold a JSON object with fx, fy, cx, cy (px)")
        return values
    if fx is None:
        raise PlanningError("intrinsics missing: give --fx (and --fy, --cx, --cy) or --intrinsics camera.json")
    h, w = (shape[0], shape[1]) if len(shape) >= 2 else (1, 1)
    return {
        "fx": fx,
        "fy": fx if fy is None else fy,
        "cx": (w - 1) / 2 if cx is None else cx,
        "cy": (h - 1) / 2 if cy is None else cy,
    }
