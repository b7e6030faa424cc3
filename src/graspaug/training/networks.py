"""Training every GQ-CNN of one seed as a paired set: the same initial weights, the same noise
stream and the same validation shapes for every variant, so differences between variants
of a seed are paired (common random numbers); seeds are the replicates.

A seed's folder holds one folder per network, ``<pool>/<B>-<R>/`` (``ceiling/`` for the
ceiling; :attr:`~graspaug.training.variants.Variant.name`): ``model.pt`` (config, weights,
summary), ``summary.json``, ``history.csv`` (validation AP per evaluation),
``test_predictions.npy`` and ``val_predictions.npy``
(P(success) per datapoint, rows in ``test_rows.npy`` / ``val_rows.npy`` of the seed folder).
With ``gqcnn.members`` = K > 1 every network is an ensemble of K members (member m of every
variant starts from the same weights and noise stream) whose mean P(success) is validated and
tested; ``*_predictions_members.npy`` (K, N) keep each member's.

Where the networks train (:func:`train_jobs`): here, one after another with torch's threads, or one network per
task on :class:`~graspaug.parallel.Workers` (local processes or a Dask cluster), each task with
:data:`TASK_THREADS` torch threads. Every network starts from its own initial weights and noise seeds, so it
comes out the same wherever it trains, byte for byte at the same thread count; at another thread count
float sums round differently (docs/cluster.md).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from tqdm import tqdm

from graspaug.device import GQCNN_GPU_BFLOAT16, resolve_precision
from graspaug.errors import DataError
from graspaug.io.checkpoints import finish_gqcnn_card, gqcnn_card, operating_point, save_gqcnn, training_range
from graspaug.nets.gqcnn import GQCNN, GQCNNEnsemble, GQCNNStack
from graspaug.nets.settings import GQCNNConfig
from graspaug.parallel import Workers, parallel_map
from graspaug.training.gqcnn import GraspArrays, classification_metrics, predict_members, train_members
from graspaug.training.gqcnn_data import (
    Corpora,
    ExperimentSplit,
    shapes_datapoints,
    split_ids,
    split_test_set,
    training_set,
)
from graspaug.training.settings import TrainSettings
from graspaug.training.variants import Variant

log = logging.getLogger(__name__)


def network_seed(seed: int, data_seed: int, independent_draws: bool) -> int:
    """The global seed of the networks' initial weights and noise streams (:func:`stream_seeds`): ``seed``, or with
    ``independent_draws`` one drawn from (``seed``, ``data_seed``), so that training seed s starts from other
    weights in every draw (seeds nested in draws)."""
    if not independent_draws:
        return seed
    return int(np.random.SeedSequence([seed, data_seed]).generate_state(1)[0])


def stream_seeds(global_seed: int, seed: int, member: int = 0) -> tuple[int, int]:
    """(initial-weights seed, noise-and-batch-order seed) of member ``member`` (< 3959) of
    training seed ``seed``; member 0's are the seed's own."""
    base = global_seed * 1_000_003 + 7919 * seed + 2 * member
    return base, base + 1


def initial_weights(config: GQCNNConfig, weight_seed: int) -> dict[str, torch.Tensor]:
    """The weights every network of a seed starts from."""
    torch.manual_seed(weight_seed)
    return GQCNN(config).state_dict()


def seed_members(
    config: GQCNNConfig, global_seed: int, seed: int, members: int
) -> tuple[tuple[dict, ...], tuple[int, ...]]:
    """Initial weights and noise seeds of the ``members`` members of every network of a seed:
    member m starts from the same weights and noise stream in every variant (paired)."""
    streams = [stream_seeds(global_seed, seed, m) for m in range(members)]
    return tuple(initial_weights(config, w) for w, _ in streams), tuple(n for _, n in streams)


def weights_digest(state: dict[str, torch.Tensor]) -> str:
    """SHA-256 (first 16 hex digits) of a state dict's tensors, in key order."""
    digest = hashlib.sha256()
    for name in sorted(state):
        digest.update(name.encode())
        digest.update(state[name].detach().cpu().contiguous().numpy().tobytes())
    return digest.hexdigest()[:16]


def members_digest(inits: tuple[dict, ...]) -> str:
    """``init_digest`` of a network: :func:`weights_digest` of its one member's initial
    weights, or of all members' as one ensemble state dict."""
    if len(inits) == 1:
        return weights_digest(inits[0])
    return weights_digest({f"members.{m}.{k}": v for m, init in enumerate(inits) for k, v in init.items()})


@dataclass(frozen=True)
class NetworkJob:
    """One network of a seed (a worker's unit of work): one member per initial weights and
    noise seed (:func:`seed_members`), their P(success) averaged; trained on datapoints of
    ``corpora``, written into its folder in the seed's folder ``out_dir``."""

    variant: Variant
    split: ExperimentSplit
    net: GQCNNConfig
    train: TrainSettings
    inits: tuple[dict, ...]
    noise_seeds: tuple[int, ...]
    seed: int
    device: str
    out_dir: Path
    corpora: Corpora
    card: dict | None = None  # the model card's data part (graspaug.io.checkpoints.gqcnn_card)


def network_dir(seed_dir: Path, variant: Variant) -> Path:
    return seed_dir / variant.name


def train_network(job: NetworkJob, val: GraspArrays | None = None, test: GraspArrays | None = None) -> dict:
    """Train one network (each of its members from its initial weights); write its folder;
    return its summary. ``val`` / ``test``: the seed's validation and test datapoints (read
    here when not given). With several members the network is their
    :class:`~graspaug.nets.gqcnn.GQCNNEnsemble` and every member's predictions are kept too
    (``*_predictions_members.npy``, (K, N))."""
    device = torch.device(job.device)
    train, info = training_set(job.variant, job.split, job.corpora)
    val = val if val is not None else shapes_datapoints(job.corpora.original, job.split.validation)[0]
    test = test if test is not None else split_test_set(job.corpora.original, job.split)[0]
    members = [GQCNN(job.net) for _ in job.inits]
    for net, init in zip(members, job.inits, strict=True):
        net.load_state_dict(init)
    gens = [torch.Generator().manual_seed(noise_seed) for noise_seed in job.noise_seeds]
    history = []

    def log(m: int, step: int, metrics: dict) -> None:  # history.csv names members only in an ensemble
        history.append({**({"member": m} if len(members) > 1 else {}), "step": step, **metrics})

    share = info.get("target_positive_share")  # a balanced network's batches are drawn at targeted's share
    fits = train_members(members, train, val, job.train, device, gens, on_log=log, progress=False, positive_share=share)
    kept = GQCNNStack(members).to(device, memory_format=torch.channels_last)  # the kept weights, one pass
    val_ps = [f["val_predictions"] for f in fits]
    if any(p is None for p in val_ps):
        val_ps = list(predict_members(kept, val, device, job.train.eval_batch))
    test_ps = list(predict_members(kept, test, device, job.train.eval_batch))
    single = len(members) == 1
    net = members[0] if single else GQCNNEnsemble(members)
    val_p, test_p = np.mean(val_ps, axis=0, dtype=np.float32), np.mean(test_ps, axis=0, dtype=np.float32)
    init_digest = members_digest(job.inits)
    rounded = lambda d: {k: (round(v, 5) if isinstance(v, float) else v) for k, v in d.items()}  # noqa: E731
    summary = {
        "pool": job.variant.pool,
        "base_size": job.variant.base_size,
        "ratio": job.variant.ratio,
        "seed": job.seed,
        "validation": rounded(classification_metrics(val.labels, val_p)),
        "test": rounded(classification_metrics(test.labels, test_p)),
        "train": {
            **info,
            "steps": fits[0]["steps"],
            "best_step": fits[0]["best_step"] if single else [f["best_step"] for f in fits],
            "batch_size": job.train.batch_size,
            "drawn_positive_share": _by_member_list([round(f["drawn_positive_share"], 6) for f in fits]),
            "precision": resolve_precision(
                job.train.precision, device, GQCNN_GPU_BFLOAT16
            ).label,  # as resolved where it trained
            **({} if single else {"members": len(members)}),
        },
        "parameters": net.describe()["parameters"],
        "init_digest": init_digest,
        "noise_seed": job.noise_seeds[0] if single else list(job.noise_seeds),
    }
    folder = network_dir(job.out_dir, job.variant)
    folder.mkdir(parents=True, exist_ok=True)
    # the card's quality floor comes from the validation predictions alone, its data range from the training crops
    card = finish_gqcnn_card(
        job.card, summary, operating_point(val.labels, val_p), training_range(train.images, train.z)
    )
    save_gqcnn(folder / "model.pt", net, summary, card)
    np.save(folder / "test_predictions.npy", test_p)
    np.save(folder / "val_predictions.npy", val_p)
    if not single:
        np.save(folder / "test_predictions_members.npy", np.stack(test_ps))
        np.save(folder / "val_predictions_members.npy", np.stack(val_ps))
    pd.DataFrame(history).to_csv(folder / "history.csv", index=False)
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    seconds = fits[0]["train_seconds"]  # the members trained together
    return {
        **summary,
        "train_seconds": seconds,
        "samples_per_second": fits[0]["samples_per_second"],  # every member's samples
        "threads": torch.get_num_threads(),  # torch threads it trained with
    }


def _by_member_list(values: list):
    """One value for a network of one member, else the list by member."""
    return values[0] if len(values) == 1 else values


def seed_card(render, grasps, global_seed: int, ingest=None, data_seed: int | None = None, train=None) -> dict:
    """The model card's data part of every network (:func:`graspaug.io.checkpoints.gqcnn_card`) from the
    ``render`` params (crop, intrinsics, viewpoints: the camera distance range the planner warns outside of),
    the ``grasps`` params (gripper, label threshold) and the global seed; with the ``ingest`` params also
    ``test_set_rules``: the ingest, grasps and render settings its data were made by, so that a test set made for it
    is made alike (`graspaug evaluate` uses them); with ``data_seed`` the draw of the data it was trained in, with the
    ``gqcnn.train`` settings ``train`` its ``training_rule`` (steps, schedule, checkpoint choice): what tells replicates
    of one arm apart from other arms (`graspaug evaluate --seeds`). :func:`train_network` adds each
    network's training set, AP, validation operating point and training data range."""
    card = gqcnn_card(render.crop, render.intrinsics, render.viewpoints, grasps.gripper, grasps.threshold, global_seed)
    if ingest is not None:
        card["test_set_rules"] = test_set_rules(ingest, grasps, render)
    if data_seed is not None:
        card["data_seed"] = int(data_seed)
    if train is not None:
        card["training_rule"] = json.loads(json.dumps(dataclasses.asdict(train)))
    return card


def test_set_rules(ingest, grasps, render) -> dict:
    """The ``ingest`` (checks and surface: the size rule and its limits), ``grasps`` and ``render`` settings (views
    per pose, poses, camera) a network's data were made by, as plain data (a model card's ``test_set_rules``)."""
    surface = {"max_faces": ingest.max_faces, "max_file_mb": ingest.max_file_mb, "min_voxels": ingest.min_voxels}
    ingest_rules = surface | {"surface": dataclasses.asdict(ingest.surface)}
    rules = {"ingest": ingest_rules, "grasps": dataclasses.asdict(grasps), "render": dataclasses.asdict(render)}
    return json.loads(json.dumps(rules))  # tuples as lists: what the card's JSON holds


TASK_THREADS = 1  # torch threads of a network trained beside others: a small network's layers scale poorly over
# threads, so a core per network trains more networks per hour than cores shared by one (docs/cluster.md)


def _train_task(job: NetworkJob, threads: int) -> dict:
    """:func:`train_network` of ``job`` with ``threads`` torch threads (restored after), reading the seed's
    validation and test datapoints itself: a worker reads them from the project folder it shares rather than
    receiving them with every network."""
    before = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        return train_network(job)
    finally:
        torch.set_num_threads(before)


def _in_process(workers: Workers | int) -> bool:
    """Whether :func:`train_jobs` trains on ``workers`` here, in this process (one local job)."""
    local = workers if isinstance(workers, int) else workers.n_jobs if workers.executor == "joblib" else 0
    return local == 1


def _where(workers: Workers | int) -> str:
    """Where :func:`train_jobs` trains on ``workers``, in words."""
    if _in_process(workers):
        return "in this process, one after another"
    if isinstance(workers, Workers) and workers.executor == "dask":
        return "one per task on the Dask cluster at %s, %d torch thread(s) each" % (workers.scheduler, TASK_THREADS)
    n_jobs = workers.n_jobs if isinstance(workers, Workers) else workers
    return "one per task on %d local processes, %d torch thread(s) each" % (n_jobs, TASK_THREADS)


def network_workers(workers: Workers) -> Workers | int:
    """Where a seed's networks train, given where the per-shape loops run: the Dask cluster of ``workers``
    (executor dask), else this process, one network at a time with every thread (two 1-thread processes
    were no faster on 2 cores: docs/results.md#one-network-at-a-time)."""
    return workers if workers.executor == "dask" else 1


def train_jobs(
    jobs: list[NetworkJob], val: GraspArrays, test: GraspArrays, desc: str, workers: Workers | int = 1
) -> list[dict]:
    """Train the networks of ``jobs`` (:func:`train_network`, progress bar ``desc``) on the seed's validation
    and test datapoints; their summaries, in the order of ``jobs``. ``workers`` 1: here, one after another;
    otherwise one network per task on ``workers`` with :data:`TASK_THREADS` torch threads (each task reads the
    validation and test datapoints itself, the same rows). A network that cannot be trained (a ValueError) is
    a :class:`~graspaug.errors.DataError` (one line)."""
    log.info("%s: %d networks %s", desc, len(jobs), _where(workers))
    try:
        if _in_process(workers):
            return [train_network(job, val, test) for job in tqdm(jobs, desc=desc, unit="network")]
        task = functools.partial(_train_task, threads=TASK_THREADS)
        return parallel_map(task, jobs, workers, desc, unit="network", batch_size=1)
    except ValueError as exc:
        raise DataError(str(exc)) from None


def _by_member(value):
    """A per-member list as {"m0": …, "m1": …} (``dvc metrics`` shows dicts and numbers, not lists); a number
    as it is."""
    return {f"m{m}": v for m, v in enumerate(value)} if isinstance(value, list) else value


SEED_TABLE_EXTRAS = ("target_positive_share", "drawn_positive_share", "views_datapoints")
"""What a ``balanced`` or ``views`` network adds to its row of the seed's report (:func:`seed_table`)."""


def seed_table(summaries: list[dict]) -> dict:
    """The seed's networks (its report): pool → base size → ratio → validation / test AP and ROC AUC,
    datapoints, steps, the kept step (per member of an ensemble: ``{"m0": …}``)."""
    out: dict = {}
    for s in summaries:
        key = ("ceiling", "all", "-") if s["pool"] == "ceiling" else (s["pool"], str(s["base_size"]), f"{s['ratio']:g}")
        out.setdefault(key[0], {}).setdefault(key[1], {})[key[2]] = {
            "val_ap": s["validation"]["ap"],
            "test_ap": s["test"]["ap"],
            "test_roc_auc": s["test"]["roc_auc"],
            "datapoints": s["train"]["datapoints"],
            "steps": s["train"]["steps"],
            "best_step": _by_member(s["train"]["best_step"]),
            **{k: _by_member(s["train"][k]) for k in SEED_TABLE_EXTRAS if k in s["train"]},
        }
    return out


def seed_headline(table: dict) -> dict[str, float | None]:
    """The seed's metrics from its :func:`seed_table`: ``test_ap`` and ``val_ap``, each the mean over the
    seed's networks (those with a value), rounded to 5 decimals; None without any."""
    rows = [row for by_base in table.values() for by_ratio in by_base.values() for row in by_ratio.values()]

    def mean(key: str) -> float | None:
        values = [row[key] for row in rows if row[key] is not None]
        return round(float(np.mean(values)), 5) if values else None

    return {"test_ap": mean("test_ap"), "val_ap": mean("val_ap")}


def read_history(seed_dir: Path, variants: list[Variant]) -> pd.DataFrame:
    """Validation AP per evaluation of every network of a seed: network (``<name> #<m>`` for
    member m > 0 of an ensemble), step, val_ap, loss, lr."""

    def named(frame: pd.DataFrame, name: str) -> pd.DataFrame:
        member = frame["member"] if "member" in frame else pd.Series(0, index=frame.index)
        return frame.assign(network=[name if m == 0 else f"{name} #{m}" for m in member])

    frames = [named(pd.read_csv(network_dir(seed_dir, v) / "history.csv"), v.name) for v in variants]
    return (
        pd.concat(frames, ignore_index=True)[["network", "step", "val_ap", "loss", "lr"]] if frames else pd.DataFrame()
    )


def seed_plan(variants: list[Variant], members: int, n_validation: int, val_rows, test_rows, device) -> str:
    """One line on a seed's training: the networks and members, the validation shapes
    (``n_validation``) and datapoints (``val_rows`` (N,)), the test datapoints (``test_rows`` (M,))
    and the torch ``device``; :func:`train_jobs` says where the networks train."""
    return (
        "%d networks of %d member(s) (a network's members at once); "
        "validation %d shapes (%d datapoints), test %d datapoints; on %s"
        % (len(variants), members, n_validation, len(val_rows), len(test_rows), device)
    )


def save_seed_split(seed_dir: Path, split: ExperimentSplit, test_rows: np.ndarray, val_rows: np.ndarray) -> None:
    """Write the seed's ``test_rows.npy`` / ``val_rows.npy`` ((N,) rows of the original corpus's
    index) and ``split.json`` (shape ids by role, :func:`graspaug.training.gqcnn_data.split_ids`)
    into its folder ``seed_dir``."""
    seed_dir = Path(seed_dir)
    np.save(seed_dir / "test_rows.npy", test_rows)
    np.save(seed_dir / "val_rows.npy", val_rows)
    (seed_dir / "split.json").write_text(json.dumps(split_ids(split), indent=1) + "\n")


def seed_timing(results: list[dict], seconds: float) -> dict:
    """A seed's timing file: ``seconds`` (s, rounded to 0.1), the network count, the torch threads a
    network trained with (the most over ``results``, :func:`train_network`'s summaries), their median
    training samples per second and each network's training seconds by ``<pool>/<B>-<R>``."""
    speed = [r["samples_per_second"] for r in results]
    return {
        "seconds": round(seconds, 1),
        "networks": len(results),
        "threads": max((r["threads"] for r in results), default=torch.get_num_threads()),
        "samples_per_second_median": round(float(np.median(speed)), 1),
        "train_seconds": {
            f"{r['pool']}/{r['base_size']}-{r['ratio']:g}": round(r["train_seconds"], 1) for r in results
        },
    }


def result_lines(results: list[dict]) -> list[str]:
    """One line per network of ``results`` (:func:`train_network`'s summaries), sorted by pool, base
    size and ratio: ``<pool> <B>-<R>``, its datapoints, steps, kept step, validation and test AP."""
    return [
        "%s %d-%g: %d datapoints, %d steps (kept %s); validation AP %.4f, test AP %.4f"
        % (
            r["pool"],
            r["base_size"],
            r["ratio"],
            r["train"]["datapoints"],
            r["train"]["steps"],
            r["train"]["best_step"],
            r["validation"]["ap"] or float("nan"),
            r["test"]["ap"] or float("nan"),
        )
        for r in sorted(results, key=lambda r: (r["pool"], r["base_size"], r["ratio"]))
    ]


def train_paired(
    variants: list[Variant],
    split: ExperimentSplit,
    gqcnn,
    global_seed: int,
    device: torch.device,
    out_dir: Path,
    corpora: Corpora,
    card: dict,
    label: str,
    workers: Workers | int = 1,
) -> dict[int, list[dict]]:
    """Train ``variants`` for every training seed of the ``gqcnn`` params as :mod:`train_gqcnn
    <graspaug.pipeline.stages.train_gqcnn>` does (the seed's initial weights and noise streams, validated on
    ``split.validation``, tested on the test split of ``corpora.original``), each seed into
    ``out_dir``/s<seed>/ with its ``test_rows.npy``, ``val_rows.npy`` and ``split.json``; every seed's networks
    on ``workers`` at once (:func:`train_jobs`), tested on :func:`~graspaug.training.gqcnn_data.split_test_set`.
    Returns training seed → the networks' summaries
    (:func:`train_network`)."""
    val, val_rows = shapes_datapoints(corpora.original, split.validation)
    test, test_rows = split_test_set(corpora.original, split)
    jobs = []
    for seed in gqcnn.seeds:
        inits, noise_seeds = seed_members(gqcnn.net, global_seed, seed, gqcnn.members)
        folder = Path(out_dir) / f"s{seed}"
        folder.mkdir(parents=True, exist_ok=True)
        jobs += [
            NetworkJob(v, split, gqcnn.net, gqcnn.train, inits, noise_seeds, seed, str(device), folder, corpora, card)
            for v in variants
        ]
    results = train_jobs(jobs, val, test, f"{label} (seeds {', '.join(map(str, gqcnn.seeds))})", workers)
    out = {}
    for i, seed in enumerate(gqcnn.seeds):
        out[seed] = results[i * len(variants) : (i + 1) * len(variants)]
        save_seed_split(Path(out_dir) / f"s{seed}", split, test_rows, val_rows)
    return out
