"""``graspaug plan``'s work on files: read a depth image, plan on it, write ``grasp.json`` and draw ``grasp.png``.

:func:`plan_files` checks its inputs one at a time, so that a refusal (:class:`PlanningError` and the errors the
readers raise, one line each) names what is at fault: the image, the camera, the model or the output folder;
it returns a :class:`PlanReport` whose ``lines`` are what the command prints and ``exit_code`` 0 (a grasp that
clears the quality floor) or 1 (no grasp, or the best below the floor; the files are written either way).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from graspaug.io.atomic import atomic_paths
from graspaug.io.outputs import check_output_files
from graspaug.planning.camera import check_depth, intrinsics_for
from graspaug.planning.errors import PlanningError
from graspaug.planning.inputs import read_depth_image, read_intrinsics
from graspaug.planning.limits import quality_floor, range_warnings, rejected_line
from graspaug.planning.picture import planned_grasps
from graspaug.planning.planner import load_planner

PLAN_MARK = "graspaug plan"  # grasp.json's "written_by": plan replaces only its own grasp.json and grasp.png


@dataclass(frozen=True)
class PlanReport:
    """What a plan wrote and says: ``lines`` (``warning: ...`` lines first, for stderr; then the grasps and the
    verdict), ``exit_code`` (0 accepted, 1 no grasp or rejected) and the files written."""

    warnings: list[str]
    lines: list[str]
    exit_code: int
    files: tuple[Path, Path]


def plan_files(
    depth: Path,
    model: Path,
    intrinsics: Path | None,
    focal_and_center: tuple[float | None, float | None, float | None, float | None],
    top: int = 1,
    seed: int = 0,
    camera_distance: float | None = None,
    fill_missing: bool = False,
    min_quality: float | None = None,
    out: Path = Path("."),
    force: bool = False,
) -> PlanReport:
    """Plan the ``top`` best grasps on the depth image file ``depth`` with the GQ-CNN ``model`` (``model.pt``) and
    write ``out/grasp.json`` and ``out/grasp.png``.

    ``intrinsics`` is a JSON file of fx, fy, cx, cy (px) or None for ``focal_and_center`` (fx, fy, cx, cy; fy
    defaults to fx, the principal point to the image center); ``min_quality`` in [0, 1] the quality floor (None:
    the model card's operating point); ``force`` replaces a grasp.json / grasp.png that plan did not write.
    """
    if min_quality is not None and not 0.0 <= min_quality <= 1.0:
        raise PlanningError(f"--min-quality must lie in [0, 1] (a P(success)), got {min_quality:g}")
    check_output_files(out, ["grasp.json", "grasp.png"], "plan", PLAN_MARK, force)
    # one step per input, so that an error names what is at fault: the image, the camera, the model
    image = read_depth_image(depth)
    try:
        checked = check_depth(image, fill_missing)  # missing pixels filled once, here
    except PlanningError as exc:
        raise PlanningError(f"{depth}: {exc}") from None
    image = np.asarray(image).reshape(checked.shape)  # (H, W, 1) → (H, W), as check_depth took it
    camera = intrinsics_for(checked.shape, read_intrinsics(intrinsics, *focal_and_center, checked.shape))
    planner = load_planner(model)
    grasps = planner.plan(checked, camera, seed, top, camera_distance)
    warnings = range_warnings(planner.card, checked, camera, grasps, camera_distance)
    floor = quality_floor(planner.card, min_quality)
    accepted = [floor.accepts(g.quality) for g in grasps]
    json_path, png_path = out / "grasp.json", out / "grasp.png"
    labels = [
        f"#{i + 1}  Q = {g.quality:.3f}, {1000 * g.width:.0f} mm" + ("" if ok else f"  rejected (< {floor.value:.3f})")
        for i, (g, ok) in enumerate(zip(grasps, accepted, strict=True))
    ]
    verdict = f"; rejected: Q < floor {floor.value:.3f}" if grasps and not accepted[0] else ""
    shown = np.where(np.isfinite(image) & (image > 0), image, np.nan) if image.dtype.kind == "f" else image
    finger = float(planner.card.gripper.get("finger_width", 0.0))
    made = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    try:  # both files drawn and written into temporaries first: a failure leaves neither, nor a folder it made
        with atomic_paths([json_path, png_path]) as (json_tmp, png_tmp):
            crops, openings = planner.network_crops(image, camera, grasps, camera_distance, fill_missing)
            planned_grasps(
                np.nan_to_num(shown, nan=float(np.nanmax(shown))),
                [g.jaw_pixels for g in grasps],
                labels,
                png_tmp,
                f"{depth.name}: {len(grasps)} grasp(s), model {model.resolve().parent.name}/{model.name}{verdict}",
                rejected=[not ok for ok in accepted],
                finger_px=[finger * camera.fx / g.depth for g in grasps] if finger > 0 else None,
                crops=crops,
                crop_openings=openings,
                px_per_cm=0.01 * camera.fx / grasps[0].depth if grasps else None,
            )
            json_tmp.write_text(
                json.dumps(
                    {
                        "written_by": PLAN_MARK,
                        "depth": str(depth),
                        "model": str(model),
                        "accepted": bool(grasps) and accepted[0],  # the best grasp clears the quality floor
                        "quality_floor": floor.to_dict(),
                        "warnings": warnings,
                        "grasps": [{**g.to_dict(), "accepted": ok} for g, ok in zip(grasps, accepted, strict=True)],
                        "model_card": planner.card.to_dict(),
                    },
                    indent=1,
                )
                + "\n"
            )
    except BaseException:
        if made and not any(out.iterdir()):
            out.rmdir()
        raise
    said = [f"warning: {w}" for w in warnings]
    if not grasps:
        line = f"no grasp: no antipodal pair of depth edges in {depth} fits the gripper (wrote {json_path})"
        return PlanReport(warnings, said + [line], 1, (json_path, png_path))
    lines = [
        f"#{i + 1}: center ({g.u:.1f}, {g.v:.1f}) px, angle {np.degrees(g.angle):.1f} deg, depth {g.depth:.3f} m, "
        f"width {1000 * g.width:.1f} mm, quality {g.quality:.3f}{'' if ok else ' (below the floor)'}"
        for i, (g, ok) in enumerate(zip(grasps, accepted, strict=True))
    ]
    if not accepted[0]:
        lines.append(f"{rejected_line(grasps[0].quality, floor)} (wrote {json_path} and {png_path})")
        return PlanReport(warnings, said + lines, 1, (json_path, png_path))
    lines.append(
        f"wrote {json_path} and {png_path} ({grasps[0].planning_time:.2f} s; quality floor "
        f"{floor.value:.3f}: {floor.source})"
    )
    return PlanReport(warnings, said + lines, 0, (json_path, png_path))
