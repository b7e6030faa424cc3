"""The commands a user runs on a trained project's networks and data: ``plan`` (a grasp on one depth image),
``from-failures`` (new shapes near the objects a planner missed), ``evaluate`` (networks on anyone's objects),
``export-model`` and ``export-dexnet`` (a network or a rendered dataset out for other tools). Mounted on the
``graspaug`` command by :mod:`graspaug.pipeline.cli`; each command is its options and help, the work is elsewhere
(``planning/``, ``pipeline/stages/``), errors go through the one handler (:class:`graspaug.pipeline.command.Command`).
"""

from __future__ import annotations

from pathlib import Path

import typer

from graspaug.pipeline.command import EXIT_CODES, Command, ForceOption, ParamsOption
from graspaug.pipeline.entry import load_stage_params, run_stage

planner_app = typer.Typer()


@planner_app.command(
    cls=Command,
    name="plan",
    help="Plan a grasp on one depth image with a trained GQ-CNN (the planner the simulated robot uses: antipodal pairs "
    "on depth edges, GQ-CNN scores, cross-entropy refinement; a grasp is kept only if the image shows it antipodal and "
    "reachable). DEPTH is a `.npy` array in meters or a 16-bit PNG in millimeters (0 = no reading), from a camera "
    "looking (nearly) straight down. The model card in `model.pt` says which camera the network was trained for; "
    "another focal length or camera distance is resampled to it where that is sound, else refused.\n\nWrites "
    "`<out>/grasp.json` (the grasps, best first: image center, angle, depth, width; camera-frame pose and width in m; "
    "quality; the model card) and `<out>/grasp.png` (the image with the grasps drawn). A best grasp below the quality "
    "floor (`--min-quality`) is written and drawn as rejected, with exit code 1; a warning says where the image lies "
    "outside the training data (camera distance, object height above the table, gripper depth) or the intrinsics look "
    "like another image's (a principal point far from the image center).\n\n" + EXIT_CODES,
)
def plan_command(
    depth: Path = typer.Argument(..., help="Depth image: .npy (meters) or 16-bit .png (millimeters)."),
    model: Path = typer.Option(
        ..., "--model", "-m", help="A trained GQ-CNN, e.g. models/gqcnn/s0/targeted/50-1/model.pt."
    ),
    intrinsics: Path | None = typer.Option(
        None, "--intrinsics", "-i", help="JSON file with fx, fy, cx, cy (px); instead of the flags."
    ),
    fx: float | None = typer.Option(None, "--fx", help="Focal length along u (px)."),
    fy: float | None = typer.Option(None, "--fy", help="Focal length along v (px; default: fx)."),
    cx: float | None = typer.Option(None, "--cx", help="Principal point u (px; default: the image center)."),
    cy: float | None = typer.Option(None, "--cy", help="Principal point v (px; default: the image center)."),
    top: int = typer.Option(1, "--top", "-k", min=1, help="List the K best distinct grasps (near-duplicates dropped)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the sampler."),
    camera_distance: float | None = typer.Option(
        None, "--camera-distance", help="Camera to table along the optical axis (m; default: the image's median depth)."
    ),
    fill_missing: bool = typer.Option(
        False, "--fill-missing", help="Give missing pixels (0, NaN) the nearest valid depth instead of stopping."
    ),
    min_quality: float | None = typer.Option(
        None,
        "--min-quality",
        help="Reject the plan (exit code 1) when the best grasp's P(success) is below this floor, in [0, 1]; 0 accepts "
        "every grasp. Default: the model card's validation operating point (the threshold that maximises F1 on the "
        "network's validation predictions), or 0.1 for a model without one.",
    ),
    out: Path = typer.Option(
        Path("."), "--out", "-o", help="Folder for grasp.json and grasp.png (an earlier plan's are replaced)."
    ),
    force: bool = typer.Option(False, "--force", help="Replace a grasp.json or grasp.png that plan did not write."),
) -> None:
    from graspaug.planning.report import plan_files

    report = plan_files(
        depth, model, intrinsics, (fx, fy, cx, cy), top, seed, camera_distance, fill_missing, min_quality, out, force
    )
    for line in report.lines:
        typer.echo(line, err=line.startswith("warning: "))
    raise typer.Exit(code=report.exit_code)


@planner_app.command(
    cls=Command,
    name="from-failures",
    help="Generate new training shapes near objects a grasp planner fails on. The failure objects are either FOLDER, "
    "meshes (.obj, .stl, .ply) of objects a planner trained anywhere missed (each closed and scaled as the corpus is, "
    "voxelized and encoded by this project's AE-Critic), or with `--network` the `--worst` validation objects of one "
    "of this project's GQ-CNNs (highest mean log loss of its validation predictions, averaged over `gqcnn.seeds`; the "
    "test split never chooses). Each failure object's `--per-failure` nearest train shapes in latent space become "
    "anchors, each interpolated with its nearest train shapes (`generate.first_neighbour`, `extra_neighbours`, "
    "`alphas`), decoded and meshed as `generate` does, until `--count` shapes are kept. A failure object is never a "
    "parent, and with `--network` no validation object is one either. Needs `dvc repro score` (and `train_gqcnn` for "
    "`--network`).\n\nWrites `<out>/meshes/failure_<order>.obj` (m), `<out>/index.csv` (per shape: the failure "
    "object it serves, anchor `parent_a`, neighbour `parent_b`, `alpha`, size), `<out>/failures.csv` (the failure "
    "objects worst first, each with its `anchors`, `shapes` made, decodes `rejected` and, for one that got no shape, "
    "`why_none`; with `--network` every validation object's datapoints, log loss and AP), `<out>/rejects.csv` (each "
    "rejected decode, its reason and the `failure` it served) and `<out>/skipped.csv` (files that could not be used, "
    "and why); the log has a line per failure object, a warning for one that got nothing. An existing `--out` holding "
    "a file from-failures did not write is refused before any work (`--force` writes beside it, keeping it); a "
    "symbolic link, or a folder inside FOLDER, is always refused. Feed the "
    "meshes to your own pipeline, or to this one (`data.source: folder`, `data.path`).\n\n" + EXIT_CODES,
)
def from_failures_command(
    folder: Path | None = typer.Argument(None, help="Folder of meshes of the objects the planner failed on."),
    network: str | None = typer.Option(
        None, "--network", help="Instead of FOLDER: a network of this project, <pool>/<B>-<R>, e.g. targeted/50-0."
    ),
    worst: int = typer.Option(10, "--worst", help="With --network: how many of its worst validation objects."),
    count: int = typer.Option(20, "--count", "-n", help="Shapes to generate."),
    per_failure: int = typer.Option(3, "--per-failure", help="Train shapes anchored near each failure object."),
    out: Path = typer.Option(
        Path("failures_generated"),
        "--out",
        "-o",
        help="Folder to write: a new or empty one, or one from-failures wrote (its files from the last run are "
        "replaced, nothing else). Never inside FOLDER, data/ or models/.",
    ),
    force: bool = ForceOption,
    params: Path = ParamsOption,
) -> None:
    import graspaug.pipeline.stages.from_failures as command

    params_ = load_stage_params(params, command)
    run_stage(lambda p: command.run(p, folder, network, worst, count, per_failure, out, force), params_)


@planner_app.command(
    cls=Command,
    name="evaluate",
    help="Test trained GQ-CNNs on your own objects: every mesh under --corpus (.obj .stl .ply .off .glb, any file "
    "name; metres unless --unit-scale) is ingested at real size, its grasps sampled and labelled, its datapoints "
    "rendered for the models' camera (their card), as the pipeline makes its test set; prints each model's test AP "
    "with a 95% interval over objects (none with one object) and the paired difference of each model against the "
    "first. The test set is made by the built-in default params, wherever the command runs from, unless --params "
    "names a file (e.g. a project's params.yaml: its ingest, grasps and render sections; `ingest.surface.size: fit` "
    "scales objects too wide for the gripper down, refusing one it would shrink by more than half). It is cached by "
    "the files' content, those settings and the code that makes it (--cache; never read as objects, even inside "
    "--corpus; a second run at once waits for the first), so another model costs seconds.\n\nWrites report.md, "
    "evaluate.json (each AP and difference, the counts, and what shaped the test set: params, recipe fingerprint, "
    "label threshold, size rule, objects fitted and by what scale) and rejects.csv into --out. An existing --out "
    "holding a file evaluate did not write (or one changed since) is refused before any work (--force writes beside "
    "it, keeping it); --out is refused when it is or holds the working folder, the --params file's folder, --corpus, "
    "--cache or a model, or lies inside --corpus, or cannot be written.\n\n" + EXIT_CODES,
)
def evaluate_command(
    models: list[Path] = typer.Argument(..., help="Trained GQ-CNNs (model.pt); the first is the reference."),
    corpus: Path = typer.Option(..., "--corpus", "-c", help="Folder of meshes (searched recursively)."),
    out: Path = typer.Option(Path("reports/evaluate"), "--out", "-o", help="Folder to write (or one evaluate wrote)."),
    cache: Path = typer.Option(Path(".graspaug-cache/evaluate"), "--cache", help="Folder of cached test sets."),
    unit_scale: float = typer.Option(1.0, "--unit-scale", min=1e-9, help="Metres per file unit (0.001: mm files)."),
    limit: int | None = typer.Option(None, "--limit", min=1, help="Use only the first N files in sorted order."),
    resamples: int = typer.Option(1000, "--resamples", min=100, help="Bootstrap resamples of the objects."),
    force: bool = ForceOption,
    params: Path | None = typer.Option(
        None,
        "--params",
        "-p",
        help="The params file whose ingest, grasps and render sections make the test set "
        "(default: the built-in defaults, not the params.yaml of the folder it runs from).",
    ),
    seeds: int | None = typer.Option(
        None,
        "--seeds",
        min=2,
        help="The models are arms of this many replicates each (training seeds of one draw, or networks of as many "
        "draws), one arm's after another (e.g. 8 models with --seeds 4: two arms), each arm's replicates in any order: "
        "they are paired by their cards' draw (data_seed) and training seed, and refused when they cannot be. Arms are "
        "named from the cards (none@50, targeted@50, random@50, none@150); also prints each arm's mean AP and each "
        "arm's paired difference to the first, 95% over the replicates (t) and the objects (bootstrap), clipped to "
        "AP's range, and each model's difference to the first arm's model of the same draw and seed.",
    ),
) -> None:
    import graspaug.pipeline.stages.evaluate as command

    settings = load_stage_params(params, command)
    args = (settings, models, corpus, out, cache, unit_scale, limit, resamples, force, params, seeds)
    for line in command.run(*args):
        typer.echo(line)


@planner_app.command(
    cls=Command,
    name="export-model",
    help="Export a trained GQ-CNN for use without graspaug: `<out>/model.ts` (TorchScript: images (N, 1, 32, 32) and "
    "gripper depths (N,) in meters → P(success) (N,)), `<out>/card.json` (the model card: training camera, crop sizes, "
    "gripper, label threshold, training set, AP; and the input contract), and `<out>/model.onnx` when the onnx package "
    "is installed (it is not a dependency).",
)
def export_model_command(
    model: Path = typer.Argument(..., help="A trained GQ-CNN, e.g. models/gqcnn/s0/targeted/50-1/model.pt."),
    out: Path = typer.Argument(..., help="Folder to write (new, empty, or one export-model wrote)."),
    force: bool = ForceOption,
) -> None:
    from graspaug.io.outputs import output_folder
    from graspaug.planning import export_model

    with output_folder(out, "export-model", force=force) as tmp:
        info = export_model(model, tmp)
    typer.echo(f"wrote {', '.join(str(out / f) for f in [*info['files'], 'card.json'])} (ONNX: {info['onnx']})")


@planner_app.command(
    cls=Command,
    name="export-dexnet",
    help="Export a rendered dataset in Dex-Net 2.0's tensor layout for Berkeley's gqcnn tools: "
    "`<out>/tensors/{depth_ims_tf_table,hand_poses,robust_ferrari_canny,collision_free,obj_labels,pose_labels,"
    "image_labels}_%05d.npz` "
    "(key `arr_0`, 1000 rows per file) and `<out>/config.json`. As in Dex-Net, robust_ferrari_canny is 0 for colliding "
    "grasps (so `metric > threshold` is the label); robust_ferrari_canny_raw keeps the robust ε. hand_poses rows are "
    "(center row, center column, depth z, jaw angle, row − cy, column − cx, open jaws in px); obj_labels index "
    "config.json's `obj_ids`, pose_labels its `pose_ids`. Run from the project folder after the render stage.",
)
def export_dexnet_command(
    corpus: str = typer.Argument(..., help="Rendered corpus: `original` or `gen_<B>`."),
    out: Path = typer.Argument(..., help="Folder to write (new, empty, or one export-dexnet wrote)."),
    rows_per_file: int = typer.Option(1000, "--rows-per-file", min=1, help="Datapoints per .npz file (Dex-Net: 1000)."),
    pool: str = typer.Option(
        "all",
        "--pool",
        help="For a generated corpus: the one pool to export (`targeted`, `random`, `real`, ...; config.json names "
        "it); `all`: every pool, each datapoint's in the `pool_labels` field.",
    ),
    force: bool = ForceOption,
) -> None:
    from graspaug.io.dexnet import export_dexnet
    from graspaug.io.outputs import output_folder
    from graspaug.pipeline.paths import gqcnn_dir

    with output_folder(out, "export-dexnet", [gqcnn_dir(corpus)], force) as tmp:
        n = export_dexnet(gqcnn_dir(corpus), tmp, rows_per_file, pool=None if pool == "all" else pool)
    typer.echo(f"wrote {n} datapoints ({corpus}, pool {pool}) to {out}")
