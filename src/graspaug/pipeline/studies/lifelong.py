"""``graspaug study lifelong``: the lifelong loop over several draws of the data (issue #36).

Runs the ``lifelong`` profile's rounds once per data seed and gives every round's arms and contrasts one interval
over draws, training seeds and test objects. Each draw k is a clone of the project's HEAD in ``workdir``/draw<k>
with params.yaml written from the profile plus ``data_seed: k``. By default it runs ``dvc repro lifelong@r<K>``
there (the whole pipeline up to the last round, sharing the project's DVC cache). With ``reuse`` the stages before
the loop are not run again: their outputs are linked from ``reuse``/draw<k> (an attribution study's draws: the same
profile's data, the same data seed) and the rounds run as ``graspaug lifelong-start`` and ``graspaug lifelong
--round r<k>``, the commands the DVC stages run. A finished round is not run again. Then
:func:`~graspaug.experiments.lifelong.numbers.arm_contrasts` combines the draws per round and ``summary.json``,
``lifelong.md``, ``followed.csv``, ``curve.png`` (test AP) and ``gain.png`` (the gain over round 0) are written
into ``workdir``, and every network's test predictions with the command and commit into the project's
``results/<results>/`` (``graspaug results`` recomputes every figure from them).
"""

from __future__ import annotations

import json
import logging
import os
import time
from pathlib import Path

import pandas as pd

from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.lifelong.figures import curve_series
from graspaug.experiments.lifelong.numbers import ARMS, arm_contrasts, arm_variant, curve_rows, round_networks
from graspaug.experiments.results import write_lifelong
from graspaug.experiments.stats import interval_text, share_text
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv
from graspaug.pipeline.paths import AE_CRITIC_MODEL, LATENTS, SHAPES_TABLE, VOXELS, gqcnn_dir
from graspaug.pipeline.studies.draws import checked, draw_params, prepare_draw, provenance
from graspaug.plots import lines

log = logging.getLogger(__name__)

REUSED = (  # the loop's inputs, made by the stages before it
    str(SHAPES_TABLE),
    str(LATENTS),
    "data/scores.parquet",
    str(VOXELS),
    str(AE_CRITIC_MODEL),
    str(gqcnn_dir("original")),
    "models/gqcnn",
)


def run_draw(project: Path, folder: Path, params, profile: str, reuse: Path | None) -> None:
    """Clone ``project``'s HEAD into ``folder`` (once), write params.yaml and run the rounds (module docstring)."""
    header = (
        f"graspaug params, profile `{profile}` with data_seed {params.data_seed}: written by `graspaug study lifelong`"
    )
    prepare_draw(project, folder, params, header, share_cache=reuse is None)
    rounds = params.lifelong.round_numbers()
    if reuse is None:
        checked(["dvc", "repro", f"lifelong@r{max(rounds)}"], folder, f"draw {params.data_seed}")
        return
    for path in REUSED:
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        if not (folder / path).exists():
            os.symlink((reuse / path).resolve(), folder / path)
    for k in [0, *rounds]:
        if not (folder / f"data/lifelong/r{k}").exists():
            command = ["graspaug", "lifelong-start"] if k == 0 else ["graspaug", "lifelong", "--round", f"r{k}"]
            checked(command, folder, f"draw {params.data_seed}")


def combine(folders: dict[int, Path], params, n_resamples: int, results: Path, meta: dict) -> dict:
    """Every round's arms and contrasts over the draws (``folders``: data seed → draw folder); the networks' test
    predictions, with ``meta`` (command, commit, date), go to ``results`` (``results/lifelong/``: `graspaug results`
    recomputes every figure from them)."""
    cfg, seeds = params.lifelong, params.gqcnn.seeds
    first = next(iter(folders.values()))
    index = read_table(first / gqcnn_dir("original") / "index.parquet")
    labels, objects = test_labels(index, first / "models/gqcnn/s0")
    start = arm_variant("none", cfg.base_size, 0).name
    out, rounds = {}, {}
    for k in [0, *cfg.round_numbers()]:
        variants = [arm_variant(arm, cfg.base_size, k * cfg.shapes_per_round) for arm in ARMS]
        networks = {}
        for d, folder in folders.items():
            starts = {s: folder / f"models/gqcnn/s{s}/{start}" for s in seeds}
            if k == 0:
                networks[d] = {s: {"none": starts[s]} for s in seeds}
            else:
                seed_dirs = {s: folder / f"models/lifelong/r{k}/s{s}" for s in seeds}
                networks[d] = round_networks(starts, seed_dirs, variants)
        out[k] = arm_contrasts(networks, labels, objects, n_resamples, params.seed)
        rounds[k] = networks
    write_lifelong(results, rounds, labels, objects, meta | {"n_resamples": n_resamples, "seed": params.seed})
    return out


def followed(folders: dict[int, Path], rounds: list[int]) -> pd.DataFrame:
    """Per round, the last round's failure objects on validation, before (under the network that chose them) and
    under each arm now: mean AP and mean log loss over the draws' objects (``reports/lifelong/r<k>/followed.csv``).
    The arms are each other's control: a failure chosen for its high loss moves back toward the mean under any arm."""
    rows = []
    for k in rounds:
        frames = [pd.read_csv(f / f"reports/lifelong/r{k}/followed.csv") for f in folders.values()]
        both = pd.concat(frames, ignore_index=True)
        row = {"round": k, "objects": len(both)}
        for who in ("before", *ARMS):
            row[f"{who}_ap"], row[f"{who}_log_loss"] = both[f"{who}_ap"].mean(), both[f"{who}_log_loss"].mean()
        rows.append(row)
    return pd.DataFrame(rows)


def markdown(result: dict, params, command: str, seconds: float, follow: pd.DataFrame) -> str:
    """``lifelong.md``: per round the contrasts and the share of the real gain, the arms' test AP, and the failure
    objects followed (:func:`followed`), with the ``command`` and its ``seconds``."""
    cfg = params.lifelong
    lines_ = [
        "# The lifelong loop over draws of the data",
        "",
        f"B = {cfg.base_size}; {cfg.shapes_per_round} shapes per arm and round; failures: the {cfg.worst} worst "
        f"validation objects, {cfg.per_failure} anchors each; training seeds {list(params.gqcnn.seeds)}; draws "
        f"{result[0]['draws']}. Intervals: 95% nested bootstrap over draws × seeds × test objects.",
        "",
        "| round | contrast | mean [95% interval] |",
        "|---|---|---|",
    ]
    for k, r in result.items():
        for name, c in r["contrasts"].items():
            lines_.append(f"| {k} | `{name}@r{k}` | {interval_text(c)} |")
        if "share" in r:
            real = interval_text(r["contrasts"]["real_data"])
            lines_.append(f"| {k} | share of the real gain (its denominator: {real}) | {share_text(r['share'])} |")
    lines_ += ["", "| round | arm | test AP [95% interval] |", "|---|---|---|"]
    for k, r in result.items():
        lines_ += [f"| {k} | {a} | {interval_text(c, '.4f')} |" for a, c in r["ap"].items()]
    lines_ += [
        "",
        "The last round's failure objects on validation (mean over draws and objects), before and under each arm:",
        "",
        "| round | objects | " + " | ".join(f"{w} AP / log loss" for w in ("before", *ARMS)) + " |",
        "|---|---|" + "---|" * (1 + len(ARMS)),
    ]
    for row in follow.itertuples(index=False):
        cells = [f"{getattr(row, f'{w}_ap'):.3f} / {getattr(row, f'{w}_log_loss'):.3f}" for w in ("before", *ARMS)]
        lines_.append(f"| {row.round} | {row.objects} | " + " | ".join(cells) + " |")
    return "\n".join(lines_ + ["", f"Command: `{command}` ({seconds / 60:.0f} min).", ""])


def run(
    project: Path,
    draws: list[int],
    workdir: Path,
    profile: str,
    reuse: Path | None,
    resamples: int,
    combine_only: bool,
    results: str,
    command: str,
) -> str:
    """Run (unless ``combine_only``) and combine the lifelong loops of the draws ``draws`` (data seeds) of
    ``profile`` in ``workdir``; the text of ``lifelong.md`` (module docstring). ``command``: the line recorded with
    the predictions in ``project``/results/``results``."""
    start = time.perf_counter()
    project, workdir = project.resolve(), workdir.resolve()
    params = {k: draw_params(project, profile, k) for k in draws}
    folders = {k: workdir / f"draw{k}" for k in draws}
    for k in draws:
        if not combine_only:
            run_draw(project, folders[k], params[k], profile, reuse.resolve() / f"draw{k}" if reuse else None)
        log.info("draw %d: done (%.0f s)", k, time.perf_counter() - start)
    p = params[draws[0]]
    meta = provenance(project, command) | {"draws": draws}
    result = combine(folders, p, resamples, project / "results" / results, meta)
    follow = followed(folders, p.lifelong.round_numbers())
    text = markdown(result, p, command, time.perf_counter() - start, follow)
    curve = pd.concat([curve_rows(k, r) for k, r in result.items()])
    design = f"{len(draws)} draws × {len(p.gqcnn.seeds)} seeds × test objects, 95% intervals"
    for figure, label, name in (("ap", "test AP", "curve.png"), ("gain", "test AP − round 0's", "gain.png")):
        rounds, series, bands = curve_series(curve, ARMS, figure)
        what = "Test AP per round" if figure == "ap" else "Gain over round 0, paired"
        lines(rounds, series, workdir / name, "round", label, f"{what} ({design})", bands)  # written atomically
    write_csv(follow, workdir / "followed.csv")
    with atomic_path(workdir / "summary.json") as tmp:
        tmp.write_text(json.dumps({str(k): r for k, r in result.items()}, indent=1) + "\n")
    with atomic_path(workdir / "lifelong.md") as tmp:
        tmp.write_text(text)
    return text
