"""``graspaug study grasp-calibration``: do the cell's outcomes follow the grasp labels (issue 35), with changed cell
settings?

The ``grasp_calibration`` stage's work (:mod:`graspaug.experiments.cell.calibration`) with the project's ``sim``
params changed by ``section.key=value`` (``hand``, ``trial``, ``physics``, ``cell``), to measure what each change
does to agreement without editing params.yaml: chooses ``n`` datapoints of the rendered test split (half labelled
positive; ``split="train"``: of the train split, to choose settings of the cell without looking at the test split),
puts each shape in the datapoint's stable pose on the cell's table and executes its grasp with the Panda. Returns
the figures (success per label; ROC AUC of the robust ε over all grasps and collision-free ones and of the label,
with bootstrap intervals over shapes; outcome counts per label; the time) and the per-grasp table.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import pandas as pd
import yaml

from graspaug.errors import DataError
from graspaug.experiments.cell.calibration import choose_grasps, run_calibration, shape_jobs, summarize
from graspaug.io.tables import read_table
from graspaug.pipeline.params.base import ParamsError
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import SHAPES_DIR, SHAPES_TABLE, gqcnn_dir, grasps_table
from graspaug.training.gqcnn_data import with_split


def with_changes(sim, changes: list[str]):
    """``sim`` (SimParams) with ``section.key=value`` changes (values in YAML), e.g. ``hand.grip_force=20``; a change
    that names no section and key of ``sim`` is a :class:`ParamsError` naming it."""
    sections: dict[str, dict] = {}
    for change in changes:
        key, sep, value = change.partition("=")
        section, dot, name = key.partition(".")
        if not (sep and dot) or not dataclasses.is_dataclass(getattr(sim, section, None)):
            raise ParamsError(
                f"--set {change}: expected section.key=value with a section of sim (e.g. hand.grip_force=20)"
            )
        if name not in {f.name for f in dataclasses.fields(getattr(sim, section))}:
            raise ParamsError(f"--set {change}: sim.{section} has no key {name!r}")
        sections.setdefault(section, {})[name] = yaml.safe_load(value)
    try:
        return dataclasses.replace(sim, **{s: dataclasses.replace(getattr(sim, s), **v) for s, v in sections.items()})
    except ValueError as exc:  # pydantic's ValidationError: a value out of range
        raise ParamsError(f"--set {' '.join(changes)}: {' '.join(str(exc).split())}") from None


def run(project: Path, n: int, workers: int, changes: list[str], split: str) -> tuple[dict, pd.DataFrame]:
    """The calibration figures and the per-grasp table (one row per executed grasp) of ``n`` datapoints of
    ``split`` in ``project`` (where ``render@original`` has run), its params.yaml's ``sim`` with ``changes``."""
    params = load_params(project / "params.yaml")
    sim = with_changes(params.sim, changes)
    start = time.perf_counter()
    try:
        chosen = choose_grasps(
            with_split(
                read_table(project / gqcnn_dir("original") / "index.parquet"), read_table(project / SHAPES_TABLE)
            ),
            n,
            params.seed,
            split,
        )
    except ValueError as exc:
        raise DataError(f"grasp-calibration: {exc}") from None
    table = read_table(project / grasps_table("original"))
    jobs = shape_jobs(chosen, table, project / SHAPES_DIR, sim, params.seed, workers)
    prepared = time.perf_counter() - start
    executed = run_calibration(jobs, sim, workers, params.grasps.gripper)
    seconds = time.perf_counter() - start
    summary = summarize(executed, sim.n_bootstrap, params.seed)
    summary.update(
        changes=changes,
        seconds=round(seconds, 1),
        seconds_preparing=round(prepared, 1),
        seconds_per_grasp_and_worker=round((seconds - prepared) * workers / len(executed), 2),
    )
    return summary, executed
