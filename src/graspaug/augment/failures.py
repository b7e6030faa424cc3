"""Shapes near the objects a planner fails on, each kept shape tabled as a pool's is: the ``from-failures``
stream (:func:`failure_shapes`, :func:`failure_summary`) and one round of the lifelong loop (:func:`loop_shapes`:
its failure and random arms, never a pair and weight an earlier round made).

Apart from :mod:`graspaug.augment.pools` (the ``generate`` stage's pools of one base set): the candidates are
anchored on failures the planner met (:class:`graspaug.augment.candidates.FailureStream`), not on a base set's
scores, and a stream is decoded by the same runner (:func:`graspaug.augment.decode.mesh_batches`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence

import numpy as np
import pandas as pd

from graspaug.augment.candidates import (
    Candidate,
    CandidateStream,
    Decoded,
    FailureStream,
    FollowStream,
    PoolExhausted,
    RandomStream,
    candidate_key,
    fill_pool,
)
from graspaug.augment.pool_tables import pool_tables
from graspaug.augment.pools import REJECT_COLUMNS, BaseSet
from graspaug.augment.settings import GenerateSettings
from graspaug.errors import DataError

log = logging.getLogger(__name__)


def stream_shapes(
    pool: BaseSet,
    stream: CandidateStream,
    name: str,
    count: int,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    first_order: int = 0,
    prefix: str = "",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` kept shapes of ``stream`` (candidates indexing ``pool``), decoded by ``run_batch``
    (:func:`~graspaug.augment.decode.mesh_batches` over ``pool``), as pool ``name``.

    Returns (index, rejects, kept, notes): ``index`` one row per kept shape (the columns of
    :func:`graspaug.augment.pool_tables.pool_tables`; ``order`` counts from ``first_order``, ``shape_id`` is
    ``<prefix><order>``), ``rejects`` (:data:`REJECT_COLUMNS`), the kept decodes (meshes in m) in
    ``index`` order and how the stream was widened; a :class:`DataError` if the candidates run out first.
    """
    try:
        kept, rejected = fill_pool(stream, count, run_batch)
    except PoolExhausted as exc:
        raise DataError(f"{name} pool: {exc}") from None
    rows, reject_rows = pool_tables({name: (pool.ids, pool.z)}, {name: (kept, rejected)}, len(pool.ids))
    index = pd.DataFrame(rows)
    index["order"] += first_order
    index["shape_id"] = [f"{prefix}{order:04d}" for order in index.order]
    return index, pd.DataFrame(reject_rows, columns=REJECT_COLUMNS), kept, stream.notes


def failure_shapes(
    pool: BaseSet,
    anchors: Sequence[int],
    failures: Sequence[str],
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    used: Iterable[tuple[frozenset, float]] = (),
    first_order: int = 0,
    prefix: str = "failure_",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` shapes generated from training shapes near objects a planner fails on.

    Parameters
    ----------
    pool : the training shapes (a :class:`BaseSet`) the anchors index
    anchors : indices into ``pool``, most failing first
        (:func:`graspaug.experiments.lifelong.numbers.failure_anchors`)
    failures : (len(anchors),) — the name of the failure object each anchor is nearest to
    count : shapes to keep
    cfg : the ``generate`` params: neighbours (``first_neighbour``, ``extra_neighbours``) and ``alphas``
    run_batch : :func:`~graspaug.augment.decode.mesh_batches` over ``pool``
    used, first_order, prefix : candidates (:func:`.candidates.candidate_key` of ``pool`` indices) not to
        make again, and the ids (:func:`stream_shapes`): the lifelong loop's later rounds

    Returns
    -------
    :func:`stream_shapes`'s (index, rejects, kept, notes), ``index`` with the column ``failure`` (the failure object
    each shape's anchor ``parent_a`` serves)
    """
    failing = FailureStream(pool.z, anchors, cfg.first_neighbour, cfg.extra_neighbours, cfg.alphas)
    stream = FollowStream([], failing, used)
    index, rejects, kept, notes = stream_shapes(pool, stream, "failure", count, run_batch, first_order, prefix)
    served = dict(zip(anchors, failures))
    index["failure"] = [served[d.candidate.a] for d in kept]
    rejects["failure"] = rejects.parent_a.map({pool.ids[a]: name for a, name in served.items()})
    return index, rejects, kept, notes


def failure_summary(failures: Sequence[str], served: Sequence[str], index: pd.DataFrame, rejects: pd.DataFrame):
    """One row per failure object (in the order of ``failures``): its ``anchors`` (how many entries of
    ``served``, the failure each anchor serves, name it), the ``shapes`` kept and decodes ``rejected`` for it
    (``index`` and ``rejects`` of :func:`failure_shapes`), and ``why`` in words when it got no shape.
    """
    anchors = pd.Series(list(served), dtype=object).value_counts()
    made, rejected = index.failure.value_counts(), rejects.failure.value_counts()
    reasons = rejects.groupby("failure").reason.agg(
        lambda r: "; ".join(f"{k}: {v}" for k, v in r.value_counts().items())
    )
    rows = []
    for name in failures:
        n_anchors, n_made, n_rejected = int(anchors.get(name, 0)), int(made.get(name, 0)), int(rejected.get(name, 0))
        if n_made:
            why = ""
        elif not n_anchors:
            why = "no anchor: its nearest train shapes already anchor failures listed before it"
        elif n_rejected:
            why = f"every decode near it was rejected ({reasons[name]})"
        else:
            why = "the requested count was reached before its anchors were used (raise --count)"
        rows.append(
            {
                "failure": name,
                "anchors": n_anchors,
                "shapes": n_made,
                "rejected": n_rejected,
                "reject_reasons": reasons.get(name, ""),
                "why_none": why,
            }
        )
    return pd.DataFrame(rows, columns=["failure", "anchors", "shapes", "rejected", "reject_reasons", "why_none"])


def log_failure_summary(summary: pd.DataFrame, notes: Sequence[str], out) -> None:
    """Log how the stream was widened (``notes``), one line per failure object of ``summary``
    (:func:`failure_summary`; a warning naming one that got no shape) and the total written to ``out``."""
    for note in notes:
        log.info("from-failures: %s", note)
    for row in summary.itertuples():
        shapes, decodes = ("shape" if row.shapes == 1 else "shapes"), ("decode" if row.rejected == 1 else "decodes")
        line = f"{row.failure}: {row.shapes} {shapes}, {row.rejected} {decodes} rejected {row.why_none}".rstrip()
        log.log(logging.WARNING if row.why_none else logging.INFO, "from-failures: %s", line)
    served = int((summary.shapes > 0).sum())
    log.info(
        "from-failures: %d shapes for %d of %d failure objects in %s", summary.shapes.sum(), served, len(summary), out
    )


def random_shapes(
    pool: BaseSet,
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    rng: np.random.Generator,
    used: Iterable[tuple[frozenset, float]] = (),
    first_order: int = 0,
    prefix: str = "random_",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` shapes of random pairs of ``pool`` in an order drawn from ``rng``, the weights cycling through
    ``cfg.alphas`` as every pool's do; ``used``, ``first_order``, ``prefix`` and the result as
    :func:`failure_shapes`."""
    stream = FollowStream([], RandomStream(len(pool.ids), cfg.alphas, rng), used)
    return stream_shapes(pool, stream, "random", count, run_batch, first_order, prefix)


def loop_shapes(
    base: BaseSet,
    anchors: Sequence[int],
    failures: Sequence[str],
    made: pd.DataFrame | None,
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    rng: np.random.Generator,
    round_: int,
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """One round of the lifelong loop's generated arms: ``count`` ``failure`` shapes (:func:`failure_shapes` from
    ``anchors``, base-set indices near the ``failures`` they serve) and ``count`` ``random`` ones
    (:func:`random_shapes` drawn by ``rng``), none a pair and weight an earlier round of its arm made.

    ``made``: the earlier rounds' shapes (this function's index; None in round 1). Returns (index, rejects, kept,
    notes): ``index`` with ``arm`` (= ``pool``), ``round`` = ``round_``, ``order`` counting on from the earlier
    rounds of the arm and ``shape_id`` ``r<round>_<f|r><order>``; the rest as :func:`stream_shapes`.
    """
    position = {shape_id: i for i, shape_id in enumerate(base.ids)}
    made = made if made is not None else pd.DataFrame(columns=["arm", "parent_a", "parent_b", "alpha"])

    def earlier(arm: str) -> tuple[list, int]:
        rows = made[made.arm == arm]
        keys = [
            candidate_key(position[a], position[b], al) for a, b, al in zip(rows.parent_a, rows.parent_b, rows.alpha)
        ]
        return keys, len(rows)

    used, first = earlier("failure")
    failing = failure_shapes(base, anchors, failures, count, cfg, run_batch, used, first, f"r{round_}_f")
    used, first = earlier("random")
    random = random_shapes(base, count, cfg, run_batch, rng, used, first, f"r{round_}_r")
    index = pd.concat([failing[0], random[0]], ignore_index=True)
    index["arm"], index["round"] = index.pool, round_
    rejects = pd.concat([failing[1], random[1]], ignore_index=True)
    return index, rejects, failing[2] + random[2], failing[3] + random[3]
