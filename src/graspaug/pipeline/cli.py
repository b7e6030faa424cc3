"""``graspaug``: one command per pipeline stage, and the user's commands.

A stage command runs what the stage's own entry point runs (``python -m graspaug.pipeline.stages.<stage>``, the
``cmd`` of its ``dvc.yaml`` stage, through :mod:`graspaug.pipeline.entry`), importing its stage module when it runs;
this module is no stage's code, so editing it re-runs nothing. The params tables in ``--help`` are filled in when
help is shown.

Over 400 lines because it is a table: 26 commands (one per stage, and ``plan``, ``from-failures``, ``evaluate``,
``export-model``, ``profile``, ``schema``; ``graspaug study …`` is mounted from :mod:`graspaug.pipeline.study_cli`),
each a few lines of options with the help text a user reads; the work
is elsewhere (``pipeline/stages/``, ``planning/report.py``) and errors go through one handler
(:mod:`graspaug.pipeline.command`).
"""

from __future__ import annotations

import importlib
import os
from pathlib import Path

import typer
from typer.core import TyperCommand

from graspaug.pipeline.command import EXIT_CODES, Command, debug_mode
from graspaug.pipeline.entry import load_params, round_number, run_stage

app = typer.Typer(
    help="graspaug: augment a grasp planner's training objects with generated shapes.\n\n"
    "Each command runs one stage of the DVC pipeline with the settings in params.yaml; `dvc repro` runs them in order."
    "\n\n" + EXIT_CODES,
    rich_markup_mode="markdown",
    no_args_is_help=True,
    add_completion=False,
)

ParamsOption = typer.Option(Path("params.yaml"), "--params", "-p", help="The params file to read.")
ForceOption = typer.Option(
    False,
    "--force",
    help="Write into an output folder that holds files this command did not write: those of the names it writes are "
    "replaced, the others kept.",
)


def _load(path: Path, stage):
    """The params ``stage`` (a stage module) reads from the file at ``path`` (a bad one: ParamsError, exit 2)."""
    return load_params(path, stage.Params)


def _stage(module: str):
    return importlib.import_module(f"graspaug.pipeline.stages.{module}")


def _with_params(module: str, *sections: str) -> type[TyperCommand]:
    """A command class whose help fills ``{params}`` with the keys of ``sections`` of stage ``module``'s params."""

    class StageCommand(Command):
        def format_help(self, ctx, formatter) -> None:
            if "{params}" in (self.help or ""):
                from graspaug.settings import describe

                fields = _stage(module).Params.model_fields
                tables = [f"Params `{s}`:\n\n{describe(fields[s].annotation, s + '.')}" for s in sections]
                self.help = self.help.replace("{params}", "\n\n".join(tables))
            super().format_help(ctx, formatter)

    return StageCommand


def _run(stage_run, params) -> None:
    run_stage(stage_run, params)


def stage_command(name: str, help: str, *sections: str) -> None:
    """Register ``graspaug <name>``: load params, run ``graspaug.pipeline.stages.<module>.run``; ``{params}`` in
    ``help`` becomes the keys of ``sections``."""
    module = name.replace("-", "_")

    def command(params: Path = ParamsOption) -> None:
        stage = _stage(module)
        _run(stage.run, _load(params, stage))

    app.command(name=name, help=help, cls=_with_params(module, *sections))(command)


stage_command(
    "check-params",
    "Check the whole params.yaml: every key known, every value valid, the cross-section rules kept. The first stage "
    "of `dvc repro`, so that a mistyped key or a bad value stops the run, with one line naming the key, before any "
    "stage deletes its outputs. Writes nothing.",
)
stage_command(
    "ingest",
    "Load the shape corpus, reject broken meshes with a reason, rebuild one closed outer surface per shape, center and "
    "scale it, and split train/test.\n\nWrites `data/shapes/<shape_id>.ply`, `data/shapes.parquet`, "
    "`data/rejects.parquet`.\n\n{params}\n\nAlso `seed` (split) and `n_jobs`.",
    "data",
    "ingest",
)
stage_command(
    "voxelize",
    "Voxelize every shape's closed surface into a solid R×R×R occupancy grid (voxel centers inside the surface), "
    "scaled to fit with a margin; pitch and origin are kept to go back to meters.\n\nWrites "
    "`data/voxels.npz`.\n\n{params}\n\nAlso `n_jobs`.",
    "voxelize",
)
stage_command(
    "train-ae",
    "Train the AutoEncoder (phase 1, binary cross-entropy), then from it the AE-Critic (phase 2, eqs. (1)-(2) of the "
    "paper) and its control (phase 2 with λ = 0) on the train split's voxel grids; test shapes stay unseen.\n\nWrites "
    "`models/ae.pt`, `models/ae_extra.pt` (control), `models/ae_critic.pt`, DVCLive logs in `metrics/train_ae/`, and "
    "`metrics/train_ae.json` (test IoU per model, the critic's AUC on held-out shapes; every figure in "
    "`reports/train_ae/summary.json`).\n\n{params}\n\nAlso "
    "`seed`, `device`.",
    "ae",
)
stage_command(
    "embed",
    "Encode every shape with the AE-Critic: `data/latents.parquet` (shape_id, split, z) and a 2-D t-SNE map "
    "(`reports/embed/tsne.csv`, `.png`).\n\n{params}",
    "embed",
)
stage_command(
    "critic-eval",
    "The paper's critic study: decode interpolations of random train pairs with the AE, its λ = 0 control and the "
    "AE-Critic, cluster each with DBSCAN, report the mean outlier percentage per α with bootstrap intervals, the "
    "paired difference AE-Critic − control and the critic's AUC (`reports/critic_eval/study.json`; the headline, "
    "AE-Critic − control over the interpolants, in `metrics/critic_eval.json`) with plots in `reports/critic_eval/`."
    "\n\n{params}",
    "critic_eval",
)


@app.command(
    name="grasps",
    help="Sample antipodal grasps on every shape of a corpus (Dex-Net's sampler, Franka Panda opening) and label "
    "each with robust Ferrari-Canny: the mean ε over perturbed grasp poses, object poses and friction.\n\nWrites "
    "`data/grasps/<corpus>.parquet` (one row per grasp), `metrics/grasps/<corpus>.json` and "
    "`reports/grasps/<corpus>.json`; corpus `original` is the "
    "ingested shapes, `gen_<B>` the shapes generated for base size B. A shape without any grasp gets no rows and a "
    "warning with the reason.\n\n{params}\n\nAlso `seed` and `n_jobs`.",
    cls=_with_params("grasps", "grasps"),
)
def grasps_command(
    corpus: str = typer.Option(
        "original",
        "--corpus",
        "-c",
        help="Which shapes: `original` (ingested corpus) or `gen_<B>` (generated for base size B).",
    ),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("grasps")
    _run(lambda p: stage.run(p, corpus), _load(params, stage))


stage_command(
    "score",
    "Score every original shape: rarity (eq. (3)-(4) of the paper on the AE-Critic latents, relative to the train "
    "split) and graspness (share of its grasps with robust ε above the threshold).\n\nWrites `data/scores.parquet`, "
    "`metrics/score.json`, and a summary, histograms and a grasp picture in `reports/score/`.\n\n{params}\n\nAlso "
    "`grasps.threshold` (for labels).",
    "score",
)


@app.command(
    name="generate",
    help="Generate new shapes for one base set of B train shapes (paper Section III-C): pair its rare shapes, and "
    "separately its graspable ones, with their N-th to (N+K)-th nearest neighbours in latent space, decode the "
    "interpolated latents with the AE-Critic and mesh them (fill, opening, marching cubes, Humphrey smoothing); also a "
    "random-pair pool of the same size as the baseline, and the recon pool: the real pool's shapes (as the GQ-CNN "
    "experiment orders them, from the rendered corpus) decoded from their own latents, the same way (gqcnn.pools says "
    "which pools). Each pool holds max(ratios) × B shapes in order: the first "
    "round(R × B) are the set for ratio R.\n\nWrites `data/generated/<B>/` (`meshes/*.obj`, `index.parquet`, "
    "`rejects.parquet`, `base.parquet`), `metrics/generate/<B>.json` and "
    "`reports/generate/<B>/{summary.json,pairs.png,tsne.png}`.\n\n{params}\n\nAlso `score.k` (rarity on the base "
    "set), `gqcnn.pools`, `gqcnn.val_shapes` (the real pool), `data_seed` (base sets, real pool, random pairs), "
    "`seed`, `device`, `n_jobs`.",
    cls=_with_params("generate", "generate"),
)
def generate_command(
    base_size: int = typer.Option(..., "--base-size", "-b", help="The base set size B (one of generate.base_sizes)."),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("generate")
    _run(lambda p: stage.run(p, base_size), _load(params, stage))


@app.command(
    cls=Command,
    name="fidelity",
    help="How close each pool of one base size B is to real shapes, before any network trains on it: per pool of "
    "`gqcnn.pools` (the shapes of its 1:1 augmentation set), graspness and the share of the parents' graspness a "
    "child keeps, the share of positive rendered datapoints, datapoints per shape, median extents, and coverage / MMD "
    "/ 1-NN accuracy on the Chamfer distance against B held-out real shapes of the test split, each with a 95% "
    "bootstrap interval over shapes.\n\nWrites `metrics/fidelity/<B>/<pool>_<figure>.json` (mean, lo, hi) and "
    "`reports/fidelity/<B>/{fidelity.csv,fidelity.md}`.\n\nParams: `gqcnn.pools`, `gqcnn.augment_base_sizes`; "
    "`generate.base_sizes`, `gqcnn.val_shapes` and `data_seed` (the real pool, drawn as the GQ-CNN experiment draws "
    "it); `seed` (the reference shapes, the surface points, the resamples).",
)
def fidelity_command(
    base_size: int = typer.Option(
        ..., "--base-size", "-b", help="The base set size B (one of gqcnn.augment_base_sizes)."
    ),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("fidelity")
    _run(lambda p: stage.run(p, base_size), _load(params, stage))


@app.command(
    cls=Command,
    name="lifelong",
    help="One round of the lifelong loop: generate from the objects the planner fails on, round after round. "
    "Round 0 (`graspaug lifelong-start`, `dvc repro lifelong_start`) scores every validation object by "
    "the 1:0 networks of base size `lifelong.base_size` (mean log loss, predictions averaged over the "
    "seeds; the test split never chooses) and marks the `lifelong.worst` as failures. Round k >= 1 (`dvc "
    "repro lifelong@r<k>`, after `lifelong.rounds` names it) anchors generation at the "
    "`lifelong.per_failure` base shapes nearest each failure in latent space; three arms each add "
    "`lifelong.shapes_per_round` shapes: `failure` (those), `random` (random base pairs, the same "
    "weights) and `real` (as many more real train shapes, the positive control); grasps and crops are "
    "made as `grasps` and `render` make them; each arm trains, paired within every seed of "
    "`gqcnn.seeds`, on the base set plus its shapes of every round so far; the failure arm's worst "
    "validation objects are round k + 1's failures. Round k reads round k - 1's outputs only (with the "
    "corpus, the AE and the round-0 networks).\n\nWrites `data/lifelong/r<k>/` (this round's `meshes/`, "
    "every round's `shapes.parquet`, `dataset/` and `real.csv`, `failures.csv`, `history.csv`, "
    "`curve.csv`), `models/lifelong/r<k>/s<seed>/<arm>/<B>-<R>/`, `metrics/lifelong/r<k>/` (each arm's "
    "test AP `ap_<arm>` and the contrasts `failure_vs_random`, `failure_vs_real`, `real_data`, ...: "
    "mean, lo, hi) and `reports/lifelong/r<k>/` (`report.md`, `curve.png`, `failures.png`, "
    "`followed.csv`).\n\nFor a planner trained elsewhere, `graspaug from-failures FOLDER` is the same "
    "generation step from a folder of its failure meshes.",
)
def lifelong_command(
    round_: int = typer.Option(
        ..., "--round", "-r", parser=round_number, help="The round: r<k> (or k), one of lifelong.rounds."
    ),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("lifelong")
    _run(lambda p: stage.run(p, round_), _load(params, stage))


@app.command(
    cls=Command,
    name="lifelong-start",
    help="Round 0 of the lifelong loop (see `graspaug lifelong --help`): score every validation object by the 1:0 "
    "networks of base size `lifelong.base_size` (mean log loss, predictions averaged over the seeds) and mark the "
    "`lifelong.worst` as the failures round 1 generates from.\n\nWrites `data/lifelong/r0/` (`failures.csv`, "
    "`history.csv`, `curve.csv`), `metrics/lifelong/r0/` (the round-0 networks' test AP) and `reports/lifelong/r0/`.",
)
def lifelong_start_command(params: Path = ParamsOption) -> None:
    stage = _stage("lifelong_start")
    _run(stage.run, _load(params, stage))


@app.command(
    name="render",
    help="Render a Dex-Net 2.0 style grasp image dataset for a corpus: each shape in its most probable stable poses "
    "on a table, random depth-camera views from above, and for every grasp whose jaw axis is near parallel to the "
    "table a 96×96 crop centered on it, turned so the jaws are horizontal, averaged down to 32×32, with the gripper "
    "depth, an approach collision check of the Panda and the label (collision free and robust ε above the grasps "
    "threshold). Crops come from rays cast only where they are needed; they equal crops cut from full 640×480 renders "
    "(tests/render).\n\nWrites `data/gqcnn/<corpus>/` (.npy shards of images, z, labels, ε; `index.parquet`; "
    "`skipped.parquet`), `metrics/render/<corpus>.json` and "
    "`reports/render/<corpus>/{summary.json,examples.png}`.\n\n{params}\n\nAlso `grasps.gripper` (the hand), "
    "`grasps.threshold` (labels), `seed` and `n_jobs`.",
    cls=_with_params("render", "render"),
)
def render_command(
    corpus: str = typer.Option(
        "original",
        "--corpus",
        "-c",
        help="Which shapes: `original` (train and test) or `gen_<B>` (generated for base size B).",
    ),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("render")
    _run(lambda p: stage.run(p, corpus), _load(params, stage))


@app.command(
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


@app.command(
    name="train-gqcnn",
    help="Train every GQ-CNN (Dex-Net 2.0) of one training seed as a paired set (paper Section IV-C): `targeted` at "
    "every base size B × ratio R of `generate` (the B base shapes' rendered grasps + those of the first round(R × B) "
    "shapes of B's targeted pool), the other `gqcnn.pools` (`random`: random-pair interpolants, `real`: round(R × B) "
    "more real train shapes, `recon`: the real pool decoded by the AutoEncoder, `blend`: the targeted pairs with no "
    "network) at every nonzero ratio of `gqcnn.augment_base_sizes`, and the `ceiling` (every train shape outside "
    "validation). Every network of the seed starts from the same weights and noise stream and is validated on the same "
    "`gqcnn.val_shapes` train shapes; it trains `gqcnn.train.epochs` passes over its own set (within min/max steps), "
    "the learning rate annealed along a cosine, and keeps the weights with the best validation AP. With "
    "`gqcnn.members` K > 1 each network is an ensemble of K such GQ-CNNs (member m starts from the same weights in "
    "every network of the seed) whose mean P(success) is validated, tested and planned with. Test = every test-split "
    "grasp of the original corpus.\n\nWrites `models/gqcnn/s<seed>/<pool>/<B>-<R>/` (model.pt, predictions, "
    "history.csv), `metrics/gqcnn/s<seed>.json` (mean test and validation AP), `reports/gqcnn/networks/s<seed>.json` "
    "(AP per network) and "
    "`reports/gqcnn/validation/s<seed>.png` (validation AP vs step).\n\n{params}\n\nAlso `data_seed` (base sets, "
    "validation shapes, real pool), `seed`, `device`, `n_jobs`.",
    cls=_with_params("train_gqcnn", "gqcnn"),
)
def train_gqcnn_command(
    seed: int = typer.Option(0, "--seed", "-s", help="Training seed (one of gqcnn.seeds)."),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("train_gqcnn")
    _run(lambda p: stage.run(p, seed), _load(params, stage))


stage_command(
    "report",
    "The paper's GQ-CNN experiment in one place: test AP of every network of every seed (pooled and per test object, "
    "with validation AP), contrasts declared before any network is read (real_data: the positive control; "
    "targeted_vs_none, at the mean over ratios and at the ratio chosen on validation; targeted_vs_random; "
    "targeted_vs_real; recon_vs_real: what decoding costs a real shape; targeted_vs_recon: what interpolation and "
    "selection add to a decoded shape; each pool contrast only when both pools are in gqcnn.pools), each with a "
    "95% t-interval over seeds and a 95% bootstrap interval over test objects, AP vs "
    "ratio (Fig. 7), the per-object AP change of the validation-chosen ratio by rarity and graspness (Fig. 8), a t-SNE "
    "of original and generated latents by graspness (Fig. 1), and the verdicts in words.\n\nWrites "
    "`metrics/ap/<contrast>.json` (mean, lo, hi), `reports/gqcnn/{ap.json,report.md,ap_table.csv,ap_vs_ratio.png,"
    "improvement_by_score.png,tsne_graspness.png}`.\n\nReads "
    "params `generate.base_sizes`, `generate.ratios`, `gqcnn.seeds`, `gqcnn.augment_base_sizes`, `gqcnn.pools`, "
    "`gqcnn.ceiling`, "
    "`gqcnn.val_shapes`, `score.k`, `embed.perplexity`, `seed`.",
)

stage_command(
    "sim",
    "Simulated robot trials (paper Section IV-E): a pybullet Franka Panda picks each object (everyday objects of "
    "pybullet_data, `sim.n_test_objects` held-out test shapes and the meshes of `sim.objects_path`, with mass and "
    "friction drawn per object, dropped from seeded poses) from the table into a bin, with grasps planned on a "
    "D435-like noisy overhead depth image: antipodal seeds on depth edges, cross-entropy refinement by the GQ-CNN. "
    "Arms: `before` (B-0), `after` (B at the ratio chosen on validation AP), `real` (the real pool there), "
    "`more_real` (the largest base size at ratio 0: the positive control; each when trained) and `antipodal` "
    "(a random antipodal grasp, no network), the same drops for all.\n\nWrites `metrics/sim/<contrast>.json` "
    "(real_data, after_vs_before, network_vs_antipodal, after_vs_real: mean, lo, hi, bootstrap "
    "over objects) and `reports/sim/` (`summary.json`: success per arm and object with 95% Wilson intervals, the "
    "contrasts in full, calibration; `report.md`, `trials.csv`, `success.csv/.png`, `objects.csv`, "
    "`calibration.csv`, `timing.json`, `trials/<arm>-<object>.png`).\n\n{params}",
    "sim",
)

stage_command(
    "grasp-calibration",
    "Do the robot cell's outcomes follow the grasp labels? `sim.calibration_grasps` labelled datapoints of the "
    "rendered test split (half positive, spread over the test shapes) are executed in the `sim` stage's cell: each "
    "shape rests on the table in its datapoint's stable pose and the Panda executes that grasp from above, lifts and "
    "carries the object to the bin.\n\nWrites `metrics/grasp_calibration/<figure>.json` (success_positive, "
    "success_negative, auc_eps, auc_eps_collision_free, auc_quality, auc_label: mean, lo, hi, bootstrap over "
    "shapes) and "
    "`reports/grasp_calibration/` (`summary.json` with outcome counts per label, `grasps.csv` one row per executed "
    "grasp, `by_eps.csv` and `calibration.png`: success per robust-ε bin, ROC curves).\n\n{params}",
    "sim",
)


@app.command(
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


@app.command(
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

    _run(lambda p: command.run(p, folder, network, worst, count, per_failure, out, force), _load(params, command))


@app.command(
    cls=Command,
    name="evaluate",
    help="Test trained GQ-CNNs on your own objects: every mesh under --corpus (.obj .stl .ply .off .glb, metres "
    "unless --unit-scale) is ingested at real size, its grasps sampled and labelled, its datapoints rendered for the "
    "models' camera (their card), as the pipeline makes its test set; prints each model's test AP with a 95% interval "
    "over objects and the paired difference of each model against the first. The test set is cached by the files' "
    "content and those settings (--cache), so another model costs seconds. Writes report.md, evaluate.json and "
    "rejects.csv into --out.",
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
    params: Path = ParamsOption,
) -> None:
    import graspaug.pipeline.stages.evaluate as command

    for line in command.run(_load(params, command), models, corpus, out, cache, unit_scale, limit, resamples, force):
        typer.echo(line)


@app.command(
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


@app.command(
    cls=Command,
    name="profile",
    help="Write params.yaml for a profile: the defaults plus the few keys `profiles/<name>.yaml` changes "
    "(`default`: the defaults alone). Profiles: `tiny` (every stage in minutes, for trying changes), `study` (the "
    "GQ-CNN experiment over several seeds), `paper` (the paper's sizes, for a GPU). Every key is written, commented, "
    "so DVC tracks each value; `graspaug profile default` restores the defaults. A params.yaml with hand edits "
    "(values no profile writes) is kept, and the edited keys named, unless `--force`.",
)
def profile_command(
    name: str = typer.Argument(..., help="Profile name: `default` or a file stem in profiles/."),
    out: Path = typer.Option(Path("params.yaml"), "--out", "-o", help="File to write."),
    profiles: Path = typer.Option(Path("profiles"), "--profiles", help="Folder of profile overlays."),
    force: bool = typer.Option(False, "--force", help="Overwrite a params.yaml with values no profile writes."),
) -> None:
    from graspaug.io.atomic import atomic_path
    from graspaug.pipeline.params.base import ParamsError
    from graspaug.pipeline.params.profiles import hand_edits, profile_yaml

    text = profile_yaml(name, profiles)
    edits = hand_edits(out.read_text(), profiles) if out.is_file() and not force else []
    if edits:
        shown = ", ".join(edits[:3]) + (f" and {len(edits) - 3} more" if len(edits) > 3 else "")
        raise ParamsError(
            f"{out} holds values no profile writes ({shown}); copy it to keep them, then `graspaug profile {name} "
            "--force` overwrites it"
        )
    with atomic_path(out) as tmp:
        tmp.write_text(text)
    typer.echo(f"wrote {out} (profile {name})")


@app.command(
    cls=Command,
    name="results",
    help="Recompute every figure the README and docs/results.md quote from the studies' per-network tables in "
    "`results/<study>/` (written by `graspaug study attribution`): writes `<out>/<study>/summary.json`, "
    "`decomposition.md` and `figures.json` (key → the quoted text) and prints each figure. `--check`: a figure the "
    "markdown marks (`<!-- results:KEY -->` before it) that differs from the recomputed one, or that no study "
    "recomputes, is an error naming it (exit 2).",
)
def results_command(
    root: Path = typer.Option(Path("."), "--root", help="The repository (its results/, README.md, docs/)."),
    out: Path = typer.Option(Path("reports/results"), "--out", "-o", help="Folder for the recomputed tables."),
    check: bool = typer.Option(False, "--check", help="Compare the marked figures of README.md, docs/results.md."),
) -> None:
    from graspaug.experiments.results import DOCUMENTS, check_markdown, recompute, write_recomputed

    figures, results = recompute(root / "results")
    write_recomputed(results, figures, root / out)
    for key, text in figures.items():
        typer.echo(f"{key}: {text}")
    if check:
        problems = [p for doc in DOCUMENTS for p in check_markdown((root / doc).read_text(), figures, doc)]
        if problems:
            from graspaug.errors import DataError

            raise DataError(f"{len(problems)} quoted figure(s) differ from results/: {'; '.join(problems)}")
        typer.echo(f"every marked figure of {', '.join(DOCUMENTS)} equals the recomputed one")


@app.command(
    cls=Command,
    name="schema",
    help="Write the JSON Schema of params.yaml (every key's type, range, default and meaning), for editors: "
    "params.yaml's first line `# yaml-language-server: $schema=params.schema.json` makes VS Code's YAML extension "
    "check and complete it.",
)
def schema_command(out: Path = typer.Option(Path("params.schema.json"), "--out", "-o", help="File to write.")) -> None:
    from graspaug.pipeline.params.model import json_schema

    out.write_text(json_schema())
    typer.echo(f"wrote {out}")


from graspaug.pipeline.study_cli import study_app  # noqa: E402 - the studies' commands, after the stages'

app.add_typer(study_app, name="study")


def _version(value: bool) -> None:
    if value:
        from importlib.metadata import version

        typer.echo(f"graspaug {version('graspaug')}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
    debug: bool = typer.Option(
        False,
        "--debug",
        help="On an error, show its traceback instead of one line, and show the warnings other packages raise "
        "(also GRASPAUG_DEBUG=1).",
    ),
) -> None:
    """graspaug: augment a grasp planner's training objects with generated shapes."""
    debug_mode(debug or os.environ.get("GRASPAUG_DEBUG", "") not in ("", "0"))


def main() -> None:
    app()


if __name__ == "__main__":
    main()
