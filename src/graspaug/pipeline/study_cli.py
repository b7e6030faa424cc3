"""``graspaug study <name>``: the studies a researcher reruns outside ``dvc repro``, one command each.

Each command is a few lines of options with the help a user reads (what it runs and what it costs on 2 cores, the
times measured in docs/results.md); the work is in :mod:`graspaug.pipeline.studies`, imported when the command runs.
Errors go through the CLI's one handler (:class:`graspaug.pipeline.command.Command`).
"""

from __future__ import annotations

import logging
import shlex
import sys
from pathlib import Path

import typer

from graspaug.pipeline.command import Command

study_app = typer.Typer(
    help="The studies a researcher reruns outside `dvc repro`: experiments over several draws of the data, the robot "
    "cell with changed settings, what a decoder keeps of a shape. Each command's help says what it runs and its cost "
    "on 2 cores.",
    rich_markup_mode="markdown",
    no_args_is_help=True,
)

ProjectOption = typer.Option(Path("."), "--project", help="The project (a clone of this repository) it reads.")
ForceOption = typer.Option(False, "--force", help="Write into an --out folder that holds files it did not write.")
DRAWS_HELP = "Data seeds, one experiment each (`data_seed`), e.g. `--draws 0 1 2`."
#: The options that take several values after one flag, as `--draws 0 1 2` (argparse's nargs="+").
MANY = frozenset({"--draws", "--projects", "--seeds"})


def spread(args: list[str], names=MANY) -> list[str]:
    """``args`` with each value that follows an option of ``names`` given its own flag: ``--draws 0 1`` becomes
    ``--draws 0 --draws 1`` (click repeats a list option's flag; the studies' users write the values after one)."""
    out, current = [], None
    for arg in args:
        if arg.startswith("-"):
            current = arg if arg in names else None
        elif current is not None and out[-1] != current:
            out.append(current)
        out.append(arg)
    return out


class StudyCommand(Command):
    """A study's command: the CLI's exit-code contract, and several values after one flag (:func:`spread`)."""

    def parse_args(self, ctx, args: list[str]) -> list[str]:
        return super().parse_args(ctx, spread(args))


def _command_line() -> str:
    """The command as the user typed it, recorded with the tables a study writes to `results/`."""
    return shlex.join(["graspaug", *sys.argv[1:]])


def _check_results_name(results: str | None, kind: str) -> None:
    """A ``--results`` folder name that `graspaug results` reads as a ``kind`` study: ``kind`` or ``kind-<label>``."""
    if results is not None and results.split("-")[0] != kind:
        raise typer.BadParameter(f"must be {kind} or {kind}-<label>; got {results}", param_hint="--results")


def _draw_seed(value: str | None) -> tuple[int, int] | None:
    """``--keep-networks DRAW/SEED`` as (draw, seed); anything else is a usage error naming the option (exit 2)."""
    if value is None:
        return None
    draw, _, seed = value.partition("/")
    if not (draw.isdigit() and seed.isdigit()):
        raise typer.BadParameter(f"{value!r}: DRAW/SEED, two numbers, e.g. 0/0")
    return int(draw), int(seed)


SchedulerOption = typer.Option(
    None,
    "--scheduler",
    help="The address of a running Dask scheduler (tcp://host:8786) whose workers see this project and its DVC cache "
    "at the same paths; each draw is one task there (default: a LocalCluster on this machine).",
)
WorkersOption = typer.Option(
    1, "--workers", min=1, help="Draws at once on the LocalCluster (each draw's stages use n_jobs cores)."
)


def _logging() -> None:
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr)


@study_app.command(
    cls=StudyCommand,
    name="attribution",
    help="What each pool of shapes adds to a GQ-CNN's test AP, over several draws of the data (an exploratory "
    "study: for a confirmatory answer, `graspaug study confirm`): for each data seed k, a clone "
    "of the project's HEAD in `<workdir>/draw<k>` (sharing its DVC cache) with the `--profile` params plus "
    "`data_seed: k` and every `--set`, runs `dvc repro report`, each draw one task on a Dask cluster (a LocalCluster "
    "of `--workers` processes, or the one at `--scheduler`; a failed draw is named and the others go on); then one "
    "interval per contrast over draws, training "
    "seeds and test objects (t over the draws' means, with the object bootstrap). Writes `<workdir>/summary.json`, "
    "`decomposition.md` and the per-network tables with this command and the commit to `results/<results>/` "
    "(`graspaug results` recomputes every "
    "quoted figure from them). A finished draw is not run again.\n\nCost on 2 cores: the `attribution` profile, about "
    "40 min per draw (three draws: 121 min); with the distance decoder and seven pools, about 65 s per network (three "
    "draws, 204 networks: about 4 h). `--combine-only`: seconds to minutes.",
)
def attribution_command(
    draws: list[int] = typer.Option([0, 1, 2], "--draws", help=DRAWS_HELP),
    workdir: Path = typer.Option(None, "--workdir", help="Where the draws' clones go (default: ../attribution)."),
    profile: str = typer.Option(
        "attribution", "--profile", help="The profile each draw runs (`profiles/<name>.yaml`)."
    ),
    changes: list[str] = typer.Option([], "--set", help="key.path=value (YAML), e.g. 'gqcnn.augment_base_sizes=[50]'."),
    resamples: int = typer.Option(2000, "--resamples", min=1, help="Bootstrap resamples."),
    combine_only: bool = typer.Option(False, "--combine-only", help="Combine finished draws, run nothing."),
    results: str = typer.Option("attribution", "--results", help="`results/<this>/`: the per-network tables."),
    keep: str = typer.Option(
        None,
        "--keep-networks",
        callback=_draw_seed,
        help="DRAW/SEED, e.g. `0/0`: copy that draw's seed's networks (none, targeted and real at every augmented B: "
        "model.pt and card.json) to `results/<results>/networks/d<DRAW>-s<SEED>/`, for `graspaug evaluate`.",
    ),
    scheduler: str = SchedulerOption,
    workers: int = WorkersOption,
    project: Path = ProjectOption,
) -> None:
    from graspaug.pipeline.studies import attribution

    _logging()
    workdir = workdir or project.resolve().parent / "attribution"
    if keep and keep[0] not in draws:
        raise typer.BadParameter(f"draw {keep[0]} is not among --draws {draws}", param_hint="--keep-networks")
    command = _command_line()
    args = (project, draws, workdir, profile, changes, resamples, combine_only, results, command, keep)
    typer.echo(attribution.run(*args, scheduler=scheduler, workers=workers))


@study_app.command(
    cls=StudyCommand,
    name="confirm",
    help="The draws of a committed confirmatory plan (issue #74): `--plan results/<name>/plan.yaml` names the "
    "profile, the draws (data seeds), the training seeds of each draw, the hypotheses and the words of each outcome. "
    "Refuses a plan git does not hold unchanged, or whose profile now gives other params. Each draw is one task on a "
    "Dask cluster (a LocalCluster of `--workers` processes, or the one at `--scheduler`): a clone of HEAD in "
    "`<workdir>/draw<k>` sharing the DVC cache runs `dvc repro train_gqcnn@<seed>` for each seed; its tables go into "
    "the plan's folder as it finishes (commit them as they come); a failed draw is named and the others go on; a draw "
    "already there is not run again. Prints the progress, or once every planned draw is in, the control, the primary "
    "and secondary tests and the verdict in the plan's words (`graspaug results` recomputes them).\n\nCost on 2 "
    "cores: the pilot draw's wall time is in the plan (`power.pilot_minutes`).",
)
def confirm_command(
    plan: Path = typer.Option(..., "--plan", help="The plan: results/<name>/plan.yaml, committed."),
    draws: list[int] = typer.Option(None, "--draws", help="Only these of the plan's draws (default: all of them)."),
    workdir: Path = typer.Option(None, "--workdir", help="Where the draws' clones go (default: ../confirm)."),
    combine_only: bool = typer.Option(False, "--combine-only", help="Combine the finished draws, run nothing."),
    scheduler: str = SchedulerOption,
    workers: int = WorkersOption,
    project: Path = ProjectOption,
    count_objects: Path = typer.Option(
        None,
        "--count-objects",
        help="Run nothing: write results/<name>/base-objects.parquet, each draw's base sets on actual counts (the "
        "objects holding datapoints, and the train objects its AutoEncoder-Critic learned), from a finished draw's "
        "clone (its objects table and renders); refused unless every 1:0 network's datapoints agree. The worth in "
        "real objects is then also read on these counts. Seconds.",
    ),
) -> None:
    from graspaug.pipeline.studies import confirm

    _logging()
    if count_objects is not None:
        typer.echo(confirm.count_objects(project, plan, count_objects))
        return
    workdir = workdir or project.resolve().parent / "confirm"
    chosen = list(draws) if draws else None
    text = confirm.run(project, plan, workdir, chosen, scheduler, workers, combine_only, _command_line())
    typer.echo(text)


@study_app.command(
    cls=StudyCommand,
    name="external",
    help="A confirmatory study's kept networks on an external test set (issue #82): every network under "
    "`STUDY/networks/d<draw>-s0/` predicts the datapoints of `--corpus` (made into one test set by the networks' "
    "cards, as `graspaug evaluate` makes it, and cached), and the tables (`test.parquet`, a "
    "`predictions-d<draw>.parquet` a draw, `meta.json`) go to `--out` (default `results/<study>-<corpus>/`). "
    "Prints, for the pooled AP and for the mean of per-object AP over the objects holding a positive, each arm's "
    "mean over the draws and each contrast paired by draw (the plan's control first, then its primary and secondary "
    "contrasts, then each augmented arm against its base set) with its interval over draws and objects; `graspaug "
    "results` recomputes them.\n\nCost on 2 cores (AMD EPYC): the 48 networks of results/real-objects-confirm on "
    "ycb78, 8 min 11 s with the test set to make, 4 min 22 s from its cache.",
)
def external_command(
    study: Path = typer.Argument(..., help="A confirmatory study's folder, e.g. results/real-objects-confirm."),
    corpus: Path = typer.Option(..., "--corpus", help="The external meshes, e.g. ../shared/external/ycb78."),
    out: Path = typer.Option(None, "--out", help="Folder to write (default: STUDY-CORPUS, beside the study)."),
    cache: Path = typer.Option(Path(".graspaug-cache/evaluate"), "--cache", help="Folder of cached test sets."),
    unit_scale: float = typer.Option(1.0, "--unit-scale", min=1e-6, help="Metres per file unit (0.001: mm)."),
    resamples: int = typer.Option(1000, "--resamples", min=100, help="The objects' bootstrap resamples."),
) -> None:
    from graspaug.pipeline.studies import external

    _logging()
    out = out or study.parent / f"{study.name}-{corpus.name}"
    typer.echo(external.run(study, corpus, out, cache, unit_scale, resamples, _command_line()))


@study_app.command(
    cls=StudyCommand,
    name="confirm-design",
    help="The power and coverage a confirmatory plan records, from an exploratory study's tables (issue #74): the "
    "variance parts (training seeds, draws, test objects) of the contrast `--a` − `--b` (each POOL/B/R) in "
    "`--exploratory`, the draws needed for 80% power at `--effect` for 1 to 8 seeds a draw with their compute "
    "(`--draw-minutes` a draw's own stages, `--seed-minutes` a seed's networks), the power of `--draws` × `--seeds`, "
    "and the coverage of the draw-level t-interval at that design, simulated on the exploratory networks (each "
    "simulated draw a random measured draw, its seeds and a resample of the test objects). Prints one JSON "
    "object.\n\nCost on 2 cores: about 20 s.",
)
def confirm_design_command(
    exploratory: Path = typer.Option(..., "--exploratory", help="An attribution study's results folder."),
    a: str = typer.Option("targeted/50/1.0", "--a", help="The contrast's arm: POOL/B/R."),
    b: str = typer.Option("targeted/50/0.0", "--b", help="The reference arm: POOL/B/R."),
    effect: float = typer.Option(0.03, "--effect", help="The AP difference the power is for."),
    alpha: float = typer.Option(0.05, "--alpha", help="Two-sided level."),
    draw_minutes: float = typer.Option(..., "--draw-minutes", help="A draw's own stages, minutes (the pilot's)."),
    seed_minutes: float = typer.Option(..., "--seed-minutes", help="One seed's networks, minutes (the pilot's)."),
    draws: int = typer.Option(..., "--draws", min=2, help="The planned draws."),
    seeds: int = typer.Option(..., "--seeds", min=1, help="The planned training seeds a draw."),
    sims: int = typer.Option(2000, "--sims", min=100, help="Simulated studies for the coverage."),
) -> None:
    import json

    from graspaug.experiments.confirm.tables import design

    def arm(text: str, hint: str) -> tuple:
        pool, _, rest = text.partition("/")
        size, _, ratio = rest.partition("/")
        if not (pool and size.isdigit() and ratio.replace(".", "", 1).isdigit()):
            raise typer.BadParameter(f"{text!r}: POOL/B/R, e.g. targeted/50/1.0", param_hint=hint)
        return pool, int(size), float(ratio)

    args = (exploratory, arm(a, "--a"), arm(b, "--b"), effect, alpha, draw_minutes, seed_minutes, draws, seeds)
    typer.echo(json.dumps(design(*args, n_sims=sims), indent=1))


@study_app.command(
    cls=StudyCommand,
    name="real-picks",
    help="The paper's robot experiment on real objects (issue #76): for each draw's kept seed-0 networks "
    "(`--networks DIR` holding `d<k>-s0/`: none@50, targeted@50, none@150) and the random antipodal grasp, every test "
    "object of that draw, loaded from `--corpora` and sized as ingest sized it (the cards' test-set rules, else "
    "`--profile`'s), or every mesh of `--objects DIR`, picked `--attempts` times in the simulated Panda cell (each "
    "attempt a seeded drop that every arm shares). Prints success rates per arm and the paired contrasts (control: "
    "150 vs 50 real objects, first; targeted vs none; each network vs antipodal) with 95% intervals (t over draws, or "
    "the objects' bootstrap with one draw; an object's attempts are one unit), beside the paper's 68% → 86%. Writes "
    "report.md, summary.json and a success and a failure picture of each network arm to `--out`; with `--results` "
    "one row per attempt to `results/<NAME>/attempts.parquet` (`graspaug results` recomputes every figure), each "
    "draw as it finishes; a draw already there is not picked again (the summary covers every draw kept).\n\n"
    "Cost on 2 cores (AMD EPYC, `--workers 2`, 2026-12-07): with `--feasible-only`, a confirm draw's 4-14 feasible "
    "objects × 10 attempts × 5 arms (the networks, oracle, antipodal) took 129-1,492 s beside other studies (median "
    "about 500 s; 12 draws, 5,450 attempts an arm); every object of a draw (about 70) about 7 times that. The first "
    "time an object is loaded its collision shapes are decomposed (V-HACD, about 8 CPU-s an object, then cached).",
)
def real_picks_command(
    networks: Path = typer.Option(
        Path("results/real-objects-confirm/networks"), "--networks", help="Folder of kept networks, d<k>-s0/ each."
    ),
    draws: list[int] = typer.Option(None, "--draws", help="Only these draws (default: every d<k>-s0 there)."),
    corpora: Path = typer.Option(Path("../shared/corpora"), "--corpora", help="Where the test objects' files are."),
    objects: Path = typer.Option(
        None,
        "--objects",
        help="Pick every mesh under this folder instead (.obj .stl .ply .off .glb, any file name, as evaluate reads "
        "--corpus; metres unless --unit-scale).",
    ),
    unit_scale: float = typer.Option(
        1.0, "--unit-scale", min=1e-9, help="Metres per file unit of --objects' meshes (0.001: mm files)."
    ),
    attempts: int = typer.Option(10, "--attempts", min=1, help="Attempts per object and arm (paper: 10)."),
    limit: int = typer.Option(None, "--limit", min=1, help="Only the first N objects of each draw (a timing)."),
    params: Path = typer.Option(None, "--params", help="The params file of the cell (default: built-in defaults)."),
    profile: str = typer.Option("real_objects", "--profile", help="Ingest sizing for cards without test-set rules."),
    workers: int = typer.Option(2, "--workers", min=1, help="Processes."),
    out: Path = typer.Option(Path("reports/study/real_picks"), "--out", help="Folder for the report and pictures."),
    force: bool = ForceOption,
    results: str = typer.Option(None, "--results", help="Also keep the attempts in results/<NAME>/ (real-picks)."),
    paper: int = typer.Option(
        None, "--paper", min=1, help="The paper's protocol: K feasible objects a draw, each in one fixed pose."
    ),
    feasible_only: bool = typer.Option(
        False, "--feasible-only", help="Pick only the objects declared feasible from geometry (fresh drops)."
    ),
) -> None:
    import json

    from graspaug.io.outputs import output_folder
    from graspaug.pipeline.entry import load_stage_params
    from graspaug.pipeline.params.profiles import profile_params
    from graspaug.pipeline.stages import sim as sim_stage
    from graspaug.pipeline.studies import real_picks
    from graspaug.pipeline.studies.draws import provenance

    _logging()
    if objects is None and not corpora.is_dir():
        raise typer.BadParameter(
            f"{corpora}: no such folder. The draws' test objects are Google Scanned Objects meshes (gso300/ and "
            "gso100/, metres: the corpora the networks' project ingested, its data.path; the real_objects profile's is "
            "../shared/corpora), found by file name; point --corpora at your copy, or pick the meshes of any folder "
            "with --objects",
            param_hint="--corpora",
        )
    meta = provenance(Path("."), _command_line())  # the code that runs, before any commit made while it runs
    settings = load_stage_params(params, sim_stage).model_copy(update={"n_jobs": workers})
    surface = lambda: profile_params(profile).ingest.surface  # noqa: E731 (read only for cards without rules)
    chosen = list(draws) if draws else None
    args = (networks, chosen, corpora, objects, attempts, limit, settings, surface)
    kept = None if results is None else Path("results") / results
    done, earlier = real_picks.earlier_attempts(kept, attempts) if kept else (None, {})

    def keep(table, seconds):  # each draw into results/<NAME>/ as it finishes: a long study loses no draw
        runs = {**earlier.get("runs", {}), **{str(d): meta | {"seconds": s} for d, s in seconds.items()}}
        every = {**earlier.get("seconds", {}), **{str(d): s for d, s in seconds.items()}}
        real_picks.write_results(kept, table, meta | {"attempts": attempts, "seconds": every, "runs": runs})

    with output_folder(out, "study real-picks", [networks, corpora, objects], force) as tmp:
        table, summary, text = real_picks.run(
            *args,
            tmp,
            pictures=True,
            done=done,
            on_draw=keep if kept else None,
            paper_k=paper,
            feasible_only=feasible_only,
            unit_scale=unit_scale,
        )
        (tmp / "report.md").write_text(text)
        (tmp / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    typer.echo(text)


@study_app.command(
    cls=StudyCommand,
    name="lifelong",
    help="The lifelong loop over several draws of the data (issue #36): for each data seed k, a clone of the "
    "project's HEAD in `<workdir>/draw<k>` with the `--profile` params plus `data_seed: k` runs `dvc repro "
    "lifelong@r<K>`, or with `--reuse DIR` links the loop's inputs from `DIR/draw<k>` (an attribution study's draws) "
    "and runs the rounds alone; then every round's arms and contrasts over draws, training seeds and test objects. "
    "Writes `<workdir>/summary.json`, `lifelong.md`, `followed.csv`, `curve.png`, `gain.png` and every network's test "
    "predictions with this command and the commit to `results/<results>/`. A finished round is not run again.\n\n"
    "Cost on 2 cores: with `--reuse`, about 6 min per round and draw (rounds 0-2 of three draws: 53 min); without it, "
    "the stages before the loop as well (an attribution draw's). `--combine-only`: seconds to minutes.",
)
def lifelong_command(
    draws: list[int] = typer.Option([0, 1, 2], "--draws", help=DRAWS_HELP),
    workdir: Path = typer.Option(None, "--workdir", help="Where the draws' clones go (default: ../lifelong)."),
    profile: str = typer.Option("lifelong", "--profile", help="The profile each draw runs (`profiles/<name>.yaml`)."),
    reuse: Path = typer.Option(None, "--reuse", help="A study's workdir whose draws hold the loop's inputs."),
    resamples: int = typer.Option(2000, "--resamples", min=1, help="Bootstrap resamples."),
    combine_only: bool = typer.Option(False, "--combine-only", help="Combine finished draws, run nothing."),
    results: str = typer.Option("lifelong", "--results", help="`results/<this>/`: the networks' test predictions."),
    project: Path = ProjectOption,
) -> None:
    from graspaug.pipeline.studies import lifelong

    _logging()
    workdir = workdir or project.resolve().parent / "lifelong"
    text = lifelong.run(project, draws, workdir, profile, reuse, resamples, combine_only, results, _command_line())
    typer.echo(text)


@study_app.command(
    cls=StudyCommand,
    name="cell-ranking",
    help="Do networks trained on more real shapes rank the cell's outcomes better, over draws of the training data? "
    "Scores the `sim` stage's network arms (before, after, real, more_real) of each of `--projects` (one per draw, "
    "sharing the rendered dataset and the cell) on the grasps a `grasp_calibration` run executed (`--grasps`): ROC "
    "AUC against the outcomes per draw, pooled over draws in one interval over draws, seeds and shapes; and each "
    "network's top-scored grasp per shape (exploratory). Prints one JSON line.\n\nCost on 2 cores: seconds (1,000 "
    "grasps, three projects of 4 seeds: 3 s).",
)
def cell_ranking_command(
    grasps: Path = typer.Option(..., "--grasps", help="grasps.csv of a grasp_calibration run."),
    projects: list[Path] = typer.Option(
        ..., "--projects", help="One project folder per draw, e.g. `--projects . ../draw1 ../draw2`."
    ),
    models: Path = typer.Option(Path("models/gqcnn"), "--models", help="The networks' folder in each project."),
    seeds: list[int] = typer.Option(
        None, "--seeds", help="Training seeds, e.g. `--seeds 0 1` (default: each project's `gqcnn.seeds`)."
    ),
    base_size: int = typer.Option(50, "--base-size", help="B of the before, after and real arms."),
    more_real: int = typer.Option(None, "--more-real", help="B of the more_real arm (default: the largest)."),
) -> None:
    import json

    from graspaug.pipeline.studies import cell_ranking

    _logging()
    result = cell_ranking.run(grasps, list(projects), models, list(seeds) if seeds else None, base_size, more_real)
    typer.echo(json.dumps(result))


@study_app.command(
    cls=StudyCommand,
    name="grasp-calibration",
    help="Do the cell's outcomes follow the labels, with changed cell settings? The `grasp_calibration` stage's "
    "work with the project's `sim` params changed by `--set section.key=value` (`hand`, `trial`, `physics`, `cell`): "
    "`--n` datapoints of the rendered test split (half labelled positive; `--split train` to choose settings without "
    "looking at the test split) executed in the cell. Prints one JSON line (success per label, ROC AUCs with "
    "bootstrap intervals over shapes, outcome counts, seconds); `--table` writes the per-grasp table (.csv). Run it "
    "where `render@original` has run.\n\nCost on 2 cores: 1,000 grasps 162 s.",
)
def grasp_calibration_command(
    n: int = typer.Option(1000, "--n", min=1, help="Grasps executed (half labelled positive)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Processes."),
    table: Path = typer.Option(None, "--table", help="Write the per-grasp table here (.csv)."),
    changes: list[str] = typer.Option([], "--set", help="section.key=value (YAML), e.g. hand.grip_force=20."),
    split: str = typer.Option("test", "--split", help="Whose datapoints: test or train (tune the cell on train)."),
    project: Path = ProjectOption,
) -> None:
    import json

    from graspaug.io.tables import write_csv
    from graspaug.pipeline.params.base import ParamsError
    from graspaug.pipeline.studies import grasp_calibration

    if split not in ("test", "train"):
        raise ParamsError(f"--split {split}: test or train")
    _logging()
    summary, executed = grasp_calibration.run(project, n, workers, list(changes), split)
    if table is not None:
        write_csv(executed, table)
    typer.echo(json.dumps(summary))


@study_app.command(
    cls=StudyCommand,
    name="precision",
    help="Does bfloat16 training keep what float32 training gives? Compares two finished runs of one project that "
    "differ only in `gqcnn.train.precision` and `ae.train.precision` (and perhaps `gqcnn.members`: member 0 is "
    "compared) on validation: each GQ-CNN's validation AP paired by seed (the rule: keep bfloat16 if the mean over "
    "the networks whose data the AutoEncoder does not make is above −0.005 AP and its 95% t-interval does not lie "
    "below zero), each AutoEncoder's held-out IoU per test shape and the recon pool's graspness and datapoints kept "
    "(the rule: bfloat16's within float32's intervals). Prints the tables; writes them to `--out`.\n\nCost on 2 "
    "cores: about 30 s, after the two runs (a default `make repro` each).",
)
def precision_command(
    float32: Path = typer.Option(..., "--float32", help="The project trained in float32 (its `dvc repro` done)."),
    bfloat16: Path = typer.Option(..., "--bfloat16", help="The same project trained in bfloat16."),
    out: Path = typer.Option(Path("reports/study/precision"), "--out", help="Folder for the tables."),
    force: bool = ForceOption,
    results: str = typer.Option(
        None,
        "--results",
        help="Also keep the tables in results/<NAME>/ of the current folder (NAME: precision or precision-<label>) "
        "with this command and the commit: `graspaug results` recomputes the figures from them.",
    ),
) -> None:
    from graspaug.experiments.results import write_precision
    from graspaug.io.outputs import output_folder
    from graspaug.pipeline.studies import precision
    from graspaug.pipeline.studies.draws import provenance

    _check_results_name(results, "precision")
    _logging()
    with output_folder(out, "study precision", force=force) as tmp:
        text, tables = precision.run(float32, bfloat16, tmp)
    if results is not None:
        meta = provenance(Path("."), _command_line())
        for name, project in (("float32", float32), ("bfloat16", bfloat16)):
            meta |= {name: str(project.resolve()), f"{name}_commit": provenance(project, "")["commit"] or None}
        write_precision(Path("results") / results, tables, meta)
    typer.echo(text)


@study_app.command(
    cls=StudyCommand,
    name="heldout-fidelity",
    help="What a trained AutoEncoder keeps of real shapes it never trained on: `--shapes` random test-split shapes "
    "decoded from their latents by `models/ae_critic.pt` and meshed as the recon pool is, their grasps labelled and "
    "datapoints rendered as the stages do, originals beside them: graspness and datapoints kept (Fieller 95%), "
    "positive share, how many meshed. Prints a table; writes `summary.json` and `per_shape.csv` to `--out`. Run it "
    "where `embed` and `render@original` have run.\n\nCost on 2 cores: 260 shapes about 70 s.",
)
def heldout_fidelity_command(
    project: Path = ProjectOption,
    shapes: int = typer.Option(100, "--shapes", min=1, help="Random test shapes."),
    seed: int = typer.Option(0, "--seed", help="Which test shapes."),
    workers: int = typer.Option(2, "--workers", min=1, help="Processes."),
    out: Path = typer.Option(Path("reports/study/heldout_fidelity"), "--out", help="Folder for the tables."),
    force: bool = ForceOption,
    results: str = typer.Option(
        None,
        "--results",
        help="Also keep the per-shape table in the project's results/<NAME>/ (NAME: fidelity or fidelity-<label>), "
        "under the AutoEncoder's name `--ae`, with this command and the commit: `graspaug results` recomputes it.",
    ),
    ae: str = typer.Option("ae", "--ae", help="With --results: the name of the AutoEncoder measured."),
) -> None:
    import sys

    import pandas as pd

    from graspaug.experiments.results import write_fidelity
    from graspaug.io.outputs import output_folder
    from graspaug.pipeline.studies import heldout_fidelity
    from graspaug.pipeline.studies.draws import provenance

    _check_results_name(results, "fidelity")
    _logging()
    with output_folder(out, "study heldout-fidelity", force=force) as tmp:
        text = heldout_fidelity.run(project, shapes, seed, workers, tmp)
    if results is not None:
        meta = provenance(project, "graspaug " + " ".join(sys.argv[1:])) | {"project": str(project.resolve())}
        write_fidelity(project / "results" / results, ae, pd.read_csv(out / "per_shape.csv"), meta)
    typer.echo(text)


@study_app.command(
    cls=StudyCommand,
    name="roundtrip-ceiling",
    help="What could a perfect decoder hand over? For `--shapes` random train shapes, graspness kept when each goes "
    "through a grid and back to a mesh: solid occupancy and exact truncated signed distances at 32³ and 64³, meshed "
    "as `generate` meshes a decode, grasps labelled as the `grasps` stage does (Fieller 95%, paired t). Prints a "
    "table; writes `rows.csv`, `per_shape.csv`, `summary.json`, `timing.json` to `--out`. Run it where `ingest` has "
    "run.\n\nCost on 2 cores: 160 shapes 202 s.",
)
def roundtrip_ceiling_command(
    project: Path = ProjectOption,
    shapes: int = typer.Option(80, "--shapes", min=1, help="Train shapes drawn."),
    seed: int = typer.Option(0, "--seed", help="Which shapes are drawn."),
    workers: int = typer.Option(None, "--workers", min=1, help="Processes (default: the project's n_jobs)."),
    truncation: float = typer.Option(3.0, "--truncation", min=0.5, help="TSDF truncation, voxels."),
    out: Path = typer.Option(Path("reports/study/roundtrip_ceiling"), "--out", help="Folder for the tables."),
    force: bool = ForceOption,
) -> None:
    from graspaug.io.outputs import output_folder
    from graspaug.pipeline.studies import roundtrip_ceiling

    _logging()
    with output_folder(out, "study roundtrip-ceiling", force=force) as tmp:
        text = roundtrip_ceiling.run(project, shapes, seed, workers, truncation, tmp)
    typer.echo(text)
