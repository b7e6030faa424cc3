"""``graspaug``: one command per pipeline stage, and the user's commands.

A stage command runs what the stage's own entry point runs (``python -m graspaug.pipeline.stages.<stage>``, the
``cmd`` of its ``dvc.yaml`` stage, through :mod:`graspaug.pipeline.entry`), importing its stage module when it runs;
this module is no stage's code, so editing it re-runs nothing. The params tables in ``--help`` are filled in when
help is shown.

A table: one command per stage, and ``profile``, ``results``, ``schema``, each a few lines of options with
the help text a user reads; the work is elsewhere (``pipeline/stages/``) and errors go through one handler
(:mod:`graspaug.pipeline.command`). The commands on a trained project's networks and data (``plan``, ``evaluate``,
``from-failures``, ``export-model``, ``export-dexnet``) are mounted from :mod:`graspaug.pipeline.planner_cli`,
``graspaug study …`` from :mod:`graspaug.pipeline.study_cli`.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

import typer
from typer.core import TyperCommand

from graspaug.pipeline.command import EXIT_CODES, Command, ParamsOption, debug_mode
from graspaug.pipeline.entry import load_stage_params, round_number, run_stage

app = typer.Typer(
    help="graspaug: augment a grasp planner's training objects with generated shapes.\n\n"
    "The stage commands (ingest … report) each run one stage of the DVC pipeline with the settings in params.yaml; "
    "`dvc repro` runs them in order. The others are tools around it: `evaluate` (trained networks on your meshes), "
    "`plan` (a grasp on your depth image), `study` (experiments over several draws), `results`, `profile`, ..."
    "\n\n" + EXIT_CODES,
    rich_markup_mode="markdown",
    no_args_is_help=True,
    add_completion=False,
)


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


def stage_command(name: str, help: str, *sections: str) -> None:
    """Register ``graspaug <name>``: load params, run ``graspaug.pipeline.stages.<module>.run``; ``{params}`` in
    ``help`` becomes the keys of ``sections``."""
    module = name.replace("-", "_")

    def command(params: Path = ParamsOption) -> None:
        stage = _stage(module)
        run_stage(stage.run, load_stage_params(params, stage))

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
    "scale it; `graspaug split` then splits train/test.\n\nWrites `data/shapes/<shape_id>.ply`, "
    "`data/objects.parquet` (no split), `data/rejects.parquet`.\n\n{params}\n\nAlso `n_jobs`.",
    "data",
    "ingest",
)
stage_command(
    "split",
    "Split the ingested objects into train and test (`ingest.test_fraction` of them test; a duplicate goes where its "
    "original goes), seeded by `seed`, or with `independent_draws: true` by `seed` and `data_seed` (a split of its "
    "own for every draw). Ingest, voxels and the originals' grasps and renders read no split, so a new split reruns "
    "none of them.\n\nWrites `data/shapes.parquet` (the objects table with a `split` column).\n\nReads `seed`, "
    "`data_seed`, `independent_draws` and `ingest.test_fraction`.",
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


@app.command(
    name="train-ae-own",
    help="The own pool's generator for one augmented base set of B shapes: the AutoEncoder and AE-Critic of "
    "`train-ae` (ae.net, ae.train) trained on that base set's voxel grids alone, for as many SGD steps as the main "
    "AE-Critic took on the train split unless `generate.own` names the epochs; nothing when `own` is not in "
    "gqcnn.pools.\n\nWrites `models/ae_own/<B>/` (`ae_critic.pt` with the ids it trained on, `latents.parquet`, "
    "`summary.json`: reconstruction IoU on the base set and the test split beside the main AE-Critic's, DVCLive logs "
    "in `live/`) and `metrics/train_ae_own/<B>.json`.\n\n{params}\n\nAlso `generate.base_sizes`, `data_seed` (the "
    "base set), `gqcnn.pools`, `gqcnn.augment_base_sizes`, `seed`, `device`.",
    cls=_with_params("train_ae_own", "ae"),
)
def train_ae_own_command(
    base_size: int = typer.Option(
        ..., "--base-size", "-b", help="The base set size B (one of gqcnn.augment_base_sizes)."
    ),
    params: Path = ParamsOption,
) -> None:
    stage = _stage("train_ae_own")
    run_stage(lambda p: stage.run(p, base_size), load_stage_params(params, stage))


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
    run_stage(lambda p: stage.run(p, corpus), load_stage_params(params, stage))


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
    run_stage(lambda p: stage.run(p, base_size), load_stage_params(params, stage))


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
    run_stage(lambda p: stage.run(p, base_size), load_stage_params(params, stage))


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
    run_stage(lambda p: stage.run(p, round_), load_stage_params(params, stage))


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
    run_stage(stage.run, load_stage_params(params, stage))


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
    run_stage(lambda p: stage.run(p, corpus), load_stage_params(params, stage))


stage_command(
    "render-views",
    "Render the original shapes again from `gqcnn.extra_views` more camera views per stable pose, with new view seeds "
    "(each shape's `render-views` stream): the same grasps, poses, crops and labels as `graspaug render`, other "
    "views. The `views` networks (gqcnn.networks) add as many of their base shapes' extra-view datapoints as "
    "targeted adds generated ones. Per object, with no split: every draw shares it; `gqcnn.extra_views` 0 writes an "
    "empty corpus.\n\nWrites `data/gqcnn/views/` (as `graspaug render` writes a corpus) and "
    "`reports/timing/render/views.json`.\n\n{params}\n\nAlso `gqcnn.extra_views`, `grasps.gripper`, "
    "`grasps.threshold`, `seed` and `n_jobs`.",
    "render",
)


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
    run_stage(lambda p: stage.run(p, seed), load_stage_params(params, stage))


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
    "`results/<study>/` (written by `graspaug study attribution`, `lifelong`, `heldout-fidelity` and `precision` with "
    "`--results`): writes `<out>/<study>/summary.json`, "
    "`decomposition.md` and `figures.json` (key → the quoted text) and prints each figure. `--check`: a figure the "
    "markdown marks (`<!-- results:KEY -->` before it) that differs in any character from the recomputed one, or that "
    "no study recomputes, a malformed marker, or a document without a marker, is an error naming it (exit 2); so is a "
    "confirmatory study's plan (`results/<name>/plan.yaml`) that git shows committed after any other file of its "
    "folder or edited since, or a draw once committed and now gone.",
)
def results_command(
    root: Path = typer.Option(Path("."), "--root", help="The repository (its results/, README.md, docs/)."),
    out: Path = typer.Option(Path("reports/results"), "--out", "-o", help="Folder for the recomputed tables."),
    check: bool = typer.Option(False, "--check", help="Compare the marked figures of README.md, docs/results.md."),
) -> None:
    from graspaug.experiments.results import DOCUMENTS, check_markdown, history_problems, recompute, write_recomputed

    figures, results = recompute(root / "results")
    write_recomputed(results, figures, root / out)
    for key, text in figures.items():
        typer.echo(f"{key}: {text}")
    if check:
        problems = [p for doc in DOCUMENTS for p in check_markdown((root / doc).read_text(), figures, doc)]
        problems += history_problems(root / "results")  # a confirmatory plan: committed first, never edited
        if problems:
            from graspaug.errors import DataError

            raise DataError(f"{len(problems)} problem(s) with the marked figures: {'; '.join(problems)}")
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


from graspaug.pipeline.planner_cli import planner_app  # noqa: E402 - the user's commands, after the stages'
from graspaug.pipeline.study_cli import study_app  # noqa: E402

app.add_typer(planner_app)
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
    """The ``graspaug`` command: a usage error (an unknown option, a bad value, a missing argument) is one line
    naming it and exit 2, as every other bad input (:data:`~graspaug.pipeline.command.EXIT_CODES`)."""
    try:
        code = app(standalone_mode=False)
    except Exception as exc:  # typer's own copy of click's errors: told apart by their class names
        kinds = {c.__name__ for c in type(exc).__mro__}
        if "NoArgsIsHelpError" in kinds:  # `graspaug` or a group alone: its help
            exc.show()
            sys.exit(exc.exit_code)
        if "UsageError" in kinds:
            where = exc.ctx.command_path if exc.ctx is not None else "graspaug"
            typer.echo(f"error: {where}: {' '.join(exc.format_message().split())} (see `{where} --help`)", err=True)
            sys.exit(2)
        if "Abort" in kinds:
            typer.echo("aborted", err=True)
            sys.exit(1)
        raise
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    main()
