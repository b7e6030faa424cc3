"""Do the cell's outcomes follow the grasp labels? (issue 35) Labelled test grasps executed in the cell.

Chooses ``--n`` datapoints of the rendered test split (half labelled positive), puts each shape
in the datapoint's stable pose on the cell's table and executes its grasp with the Panda
(:mod:`graspaug.experiments.cell.calibration`), then prints one JSON line: success per label,
ROC AUC of the robust ε (all grasps, collision-free ones) and of the label, with bootstrap
intervals over shapes, outcome counts per label, and the time. ``--set`` changes sim params
(``hand``, ``trial``, ``physics``, ``cell``) to measure what each change does to agreement.
``--table`` writes the per-grasp table (.csv); ``--split train`` executes train-split datapoints
instead, to choose settings of the cell without looking at the test split. Run it in a project
where ``render@original`` has run (it reads ``data/gqcnn/original/index.parquet``,
``data/grasps/original.parquet`` and ``data/shapes``):

    python studies/grasp_calibration.py [--n 1000] [--workers 2] [--table out.csv] [--split train]
                                        [--set hand.grip_force=20 --set trial.pregrasp_height=0.1 ...]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from _cell import with_changes

from graspaug.experiments.cell.calibration import choose_grasps, run_calibration, shape_jobs, summarize
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import Params
from graspaug.pipeline.paths import SHAPES_DIR, gqcnn_dir, grasps_table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1000, help="grasps executed (half labelled positive)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--table", type=Path, default=None, help="write the per-grasp table here (.csv)")
    parser.add_argument("--set", dest="changes", action="append", default=[])
    parser.add_argument(
        "--split", default="test", choices=["test", "train"], help="whose datapoints (tune the cell on train)"
    )
    args = parser.parse_args()
    params = Params()
    sim = with_changes(params.sim, args.changes)
    start = time.perf_counter()
    chosen = choose_grasps(read_table(gqcnn_dir("original") / "index.parquet"), args.n, params.seed, args.split)
    jobs = shape_jobs(chosen, read_table(grasps_table("original")), SHAPES_DIR, sim, params.seed, args.workers)
    prepared = time.perf_counter() - start
    table = run_calibration(jobs, sim, args.workers)
    seconds = time.perf_counter() - start
    if args.table is not None:
        table.to_csv(args.table, index=False)
    summary = summarize(table, sim.n_bootstrap, params.seed)
    summary.update(
        changes=args.changes,
        seconds=round(seconds, 1),
        seconds_preparing=round(prepared, 1),
        seconds_per_grasp_and_worker=round((seconds - prepared) * args.workers / len(table), 2),
    )
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
