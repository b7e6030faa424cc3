"""Does the simulated cell tell a trained GQ-CNN from a random antipodal grasp? (issue 18)

Runs the ``sim`` stage's trials for two arms only, ``before`` (the targeted network of base
size B at 1:0, per training seed) and ``antipodal`` (a random antipodal seed grasp, no network),
on the same drops, sensor noise and planner seeds, and prints one JSON line: both rates, the
paired contrast ``network_vs_antipodal`` (bootstrap over objects), the outcome counts and the
time. ``--set`` changes sim params (``physics``, ``hand``, ``trial``, ``sensor``), to see which
physically plausible setting separates the arms. Run it in a project where
``render@original`` has run with the default params (it reads ``data/shapes.parquet``,
``data/shapes`` and, with ``--train``, ``data/gqcnn/original``):

    python studies/sim_probe.py [--seeds 0 1 2 3] [--n-test 20] [--attempts 2] [--models DIR] [--train]
                                [--more-real 200] [--trials out.csv]
                                [--set hand.grip_force=20 --set physics.friction_range=[0.3,0.5] ...]

``--models`` holds ``s<seed>/targeted/<B>-0/model.pt`` (default ``models/gqcnn``); with ``--train``
the missing networks are trained there first with the default ``gqcnn`` params, as
``train_gqcnn`` trains them. ``--more-real B`` adds the positive control: the targeted B-0
network of each seed as arm ``more_real`` on the same drops, and the paired ``real_data``
(more_real − before).
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

import pandas as pd
from _cell import with_changes

from graspaug.experiments.cell.numbers import rate_summary, trial_contrast
from graspaug.experiments.cell.trials import object_jobs, prepare_objects, run_object, test_shape_ids
from graspaug.io.tables import read_table
from graspaug.parallel import parallel_map
from graspaug.pipeline.params.model import Params
from graspaug.pipeline.paths import SHAPES_DIR, SHAPES_TABLE, gqcnn_dir


def train_before(models: Path, seeds: list[int], base_size: int, params: Params) -> None:
    """Train the targeted B-0 network of every seed that ``models`` lacks."""
    from graspaug.io.checkpoints import gqcnn_card
    from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, test_set
    from graspaug.training.networks import NetworkJob, initial_weights, stream_seeds, train_network
    from graspaug.training.variants import Variant

    missing = [s for s in seeds if not (models / f"s{s}/targeted/{base_size}-0/model.pt").exists()]
    if not missing:
        return
    cfg = params.gqcnn
    corpora = Corpora(gqcnn_dir("original"))
    split = load_split(
        corpora.original, read_table(SHAPES_TABLE), list(params.generate.base_sizes), cfg.val_shapes, params.data_seed
    )
    val, _ = shapes_datapoints(corpora.original, split.validation)
    test, _ = test_set(corpora.original)
    card = gqcnn_card(
        params.render.crop,
        params.render.intrinsics,
        params.render.viewpoints,
        params.grasps.gripper,
        params.grasps.threshold,
        params.seed,
    )
    for seed in missing:
        weight_seed, noise_seed = stream_seeds(params.seed, seed)
        folder = models / f"s{seed}"
        folder.mkdir(parents=True, exist_ok=True)
        job = NetworkJob(
            Variant("targeted", base_size, 0.0),
            split,
            cfg.net,
            cfg.train,
            (initial_weights(cfg.net, weight_seed),),
            (noise_seed,),
            seed,
            "cpu",
            folder,
            corpora,
            card,
        )
        result = train_network(job, val, test)
        print(f"# trained s{seed} targeted {base_size}-0: validation AP {result['validation']['ap']:.4f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    parser.add_argument("--base-size", type=int, default=50)
    parser.add_argument("--n-test", type=int, default=None, help="test shapes (default: sim.n_test_objects)")
    parser.add_argument("--attempts", type=int, default=None, help="drops per object (default: sim.attempts)")
    parser.add_argument("--models", type=Path, default=Path("models/gqcnn"))
    parser.add_argument("--train", action="store_true")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--set", dest="changes", action="append", default=[])
    parser.add_argument(
        "--more-real",
        type=int,
        default=None,
        metavar="B",
        help="add the positive control: the targeted B-0 network (more real shapes) as arm more_real, and real_data",
    )
    parser.add_argument("--trials", type=Path, default=None, help="write the per-trial table here (.csv)")
    args = parser.parse_args()
    params = Params()
    sim = with_changes(params.sim, args.changes)
    if args.train:
        train_before(args.models, args.seeds, args.base_size, params)
    n_test = sim.n_test_objects if args.n_test is None else args.n_test
    attempts = sim.attempts if args.attempts is None else args.attempts
    tests = test_shape_ids(read_table(SHAPES_TABLE), n_test, params.seed)
    objects = prepare_objects(
        sim.objects, tests, SHAPES_DIR, sim.physics, params.seed, sim.vhacd_resolution, workers=args.workers
    )
    arms = {"before": ("targeted", 0.0, args.base_size), "antipodal": (None, None, None)}
    if args.more_real is not None:
        arms["more_real"] = ("targeted", 0.0, args.more_real)
    seed_dirs = {s: args.models / f"s{s}" for s in args.seeds}
    jobs = object_jobs(objects, arms, seed_dirs, attempts, params.seed, 0)
    start = time.perf_counter()
    work = functools.partial(
        run_object,
        layout=sim.cell,
        hand=sim.hand,
        sampler=sim.sampler,
        cem=sim.cem,
        crop_size=params.render.crop.crop_size,
        out_size=params.render.crop.out_size,
        trial_settings=sim.trial,
        sensor=sim.sensor,
    )
    rows = [row for rows in parallel_map(work, jobs, args.workers, "sim probe") for row in rows]
    trials = pd.DataFrame([{k: v for k, v in row.items() if not k.startswith("_")} for row in rows])
    seconds = time.perf_counter() - start
    if args.trials is not None:
        trials.to_csv(args.trials, index=False)
    control = (
        {"real_data": trial_contrast(trials, "more_real", "before", sim.n_bootstrap, params.seed)}
        if args.more_real is not None
        else {}
    )
    print(
        json.dumps(
            {
                "changes": args.changes,
                "seeds": args.seeds,
                "objects": len(objects),
                "attempts": attempts,
                "trials": len(trials),
                "seconds": round(seconds, 1),
                "seconds_per_trial_and_worker": round(seconds * args.workers / len(trials), 2),
                "planning_time_before": round(float(trials.planning_time[trials.arm == "before"].mean()), 3),
                **{arm: rate_summary(trials.success[trials.arm == arm]) for arm in arms},
                "network_vs_antipodal": trial_contrast(trials, "before", "antipodal", sim.n_bootstrap, params.seed),
                **control,
                "outcomes": trials.groupby(["arm", "outcome"]).size().unstack(fill_value=0).to_dict("index"),
            }
        )
    )


if __name__ == "__main__":
    main()
