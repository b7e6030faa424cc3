"""``graspaug study real-picks``: the paper's robot experiment on real objects (issue #76).

For each draw's kept seed-0 networks (``<networks>/d<k>-s0/``: none@50, targeted@50, none@150), the random
antipodal grasp (the floor) and the mesh oracle (the ceiling: :class:`graspaug.sim.oracle.MeshOracle`), every test
object of that draw (``objects.json``'s ``test``, or the study's ``test.parquet``
objects for a folder of the exploratory study) is loaded from the corpora and sized as ingest sized it (the
networks' cards' ``test_set_rules``, else the ``--profile``'s ingest surface), then picked ``--attempts`` times in
the simulated Panda cell (the ``sim`` params: depth noise, mass from density, the 70 N hand of ``grasps.gripper``), each
attempt a seeded drop that every arm shares. ``--objects DIR`` picks the meshes of any folder instead (the same
objects for every draw). Each object is declared feasible or not from its geometry before any pick
(:func:`graspaug.sim.feasibility.feasibility`); the report gives success on feasible objects first, with the
oracle's verdict on the cell. ``--paper K``: the paper's protocol, K feasible objects a draw, each in one fixed
pose. Writes one row per attempt to ``results/<results>/attempts.parquet`` (with the command and
commit in ``meta.json``), and the summary, the table beside the paper's and a success and a failure picture of each
network arm to ``--out``.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.cell.picks import (
    ANTIPODAL,
    ORACLE,
    feasible_summary,
    hardest_objects,
    never_held,
    paper_table,
    pick_summary,
)
from graspaug.experiments.cell.trials import ObjectJob, run_trials
from graspaug.experiments.cell.words import picks_feasible_lines
from graspaug.rng import shape_rng

log = logging.getLogger(__name__)

#: The arms a draw's kept networks give, by the folder each network is kept in (``<pool>-<B>-<R>``); the control
#: arm is none@150 where kept, else the largest none@B above 50 (the exploratory study kept 50 and 100).
ARM_FOLDERS = {"none@50": "targeted-50-0", "targeted@50": "targeted-50-1"}


def draw_arms(folder: Path) -> dict[str, str]:
    """Arm → its network's folder name in a draw's kept folder: none@50, targeted@50 and the control's none@B."""
    sizes = sorted(int(p.name.split("-")[1]) for p in folder.glob("targeted-*-0") if (p / "model.pt").is_file())
    above = [b for b in sizes if b > 50]
    if not above:
        raise DataError(f"{folder}: no 1:0 network above B = 50 (targeted-<B>-0) for the positive control")
    b = 150 if 150 in above else above[-1]
    return ARM_FOLDERS | {f"none@{b}": f"targeted-{b}-0"}


def draw_folders(networks: Path, draws: list[int] | None) -> dict[int, Path]:
    """Draw → its kept seed-0 networks' folder (``networks``/d<k>-s0); every arm's ``model.pt`` must be there."""
    networks = Path(networks).resolve()  # absolute: worker processes may run in another folder
    if not networks.is_dir():
        raise DataError(f"--networks {networks}: no such folder")
    found = {int(p.name[1:].split("-")[0]): p for p in networks.glob("d*-s0") if p.is_dir()}
    chosen = sorted(found) if draws is None else draws
    if not chosen:
        raise DataError(f"--networks {networks}: no d<draw>-s0 folder of kept networks")
    out = {}
    for d in chosen:
        if d not in found:
            raise DataError(f"draw {d}: no networks in {networks / f'd{d}-s0'} (it holds {sorted(found)})")
        absent = [f for f in draw_arms(found[d]).values() if not (found[d] / f / "model.pt").is_file()]
        if absent:
            raise DataError(f"draw {d}: {found[d]} lacks {', '.join(f + '/model.pt' for f in absent)}")
        out[d] = found[d]
    return out


def test_objects(folder: Path) -> list[str]:
    """The draw's test objects (shape ids): its ``objects.json``, else the study's ``test.parquet`` (the exploratory
    study, whose draws share one test split)."""
    roles = folder / "objects.json"
    if roles.is_file():
        return list(json.loads(roles.read_text())["test"])
    table = folder.parent.parent / "test.parquet"
    if table.is_file():
        return sorted(set(pd.read_parquet(table).object))
    raise DataError(f"{folder}: no objects.json and no {table}: which objects did this draw test on?")


def card_surface(folder: Path, fallback):
    """The ingest surface settings the draw's networks' data were made by (their cards' ``test_set_rules``), else
    ``fallback()`` (read only then: a profile of the project the command runs in)."""
    from graspaug.geometry.settings import SurfaceSettings

    card = json.loads((folder / ARM_FOLDERS["none@50"] / "card.json").read_text())
    rules = card.get("test_set_rules")
    return (SurfaceSettings(**rules["ingest"]["surface"]) if rules else fallback()), card


def check_camera(card: dict, cell, where: Path) -> None:
    """The cell's camera must be one the networks were trained for: its height inside the card's camera distances
    (with the planner's tolerance) and its intrinsics the card's."""
    from graspaug.planning.camera import DISTANCE_TOLERANCE

    low, high = card["camera_distance"]
    if not (low - DISTANCE_TOLERANCE <= cell.camera_height <= high + DISTANCE_TOLERANCE):
        raise DataError(
            f"{where}: trained for a camera {low:g}-{high:g} m above the table; the cell's is {cell.camera_height:g} m "
            "(sim.cell.camera_height)"
        )
    ours = {k: getattr(cell.intrinsics, k) for k in card["intrinsics"]}
    if any(abs(float(ours[k]) - float(v)) > 1e-6 for k, v in card["intrinsics"].items()):
        raise DataError(f"{where}: trained for intrinsics {card['intrinsics']}, the cell's are {ours}")


def object_sources(folder: Path, unit_scale: float) -> list:
    """Every mesh file under ``folder`` (``--objects``: the formats and names evaluate reads, each in ``unit_scale``
    metres per file unit); a missing folder or one without a mesh is a :class:`DataError`."""
    from graspaug.geometry.loading import MESH_SUFFIXES
    from graspaug.io.sources import folder_sources

    if not Path(folder).is_dir():
        raise DataError(f"--objects {folder}: no such folder")
    sources = folder_sources(folder, unit_scale, None)
    if not sources:
        raise DataError(f"--objects {folder} holds no mesh file ({', '.join(MESH_SUFFIXES)})")
    return sources


def corpus_meshes(
    corpora: Path, ids: list[str], surface, limit: int | None, unit_scale: float = 1.0
) -> tuple[list, dict[str, str]]:
    """The meshes of the objects ``ids`` (shape ids as ingest names them) found in the folder ``corpora`` (files in
    ``unit_scale`` metres per unit), each loaded, closed and sized as ingest does (``surface``); those not found or
    broken, with the reason."""
    from graspaug.geometry.loading import MeshRejected, load_shape
    from graspaug.geometry.prepare import prepare_shape
    from graspaug.io.sources import folder_sources

    by_id = {s.shape_id: s for s in folder_sources(corpora, unit_scale, None)}
    meshes, skipped = [], {}
    for shape_id in ids[:limit] if limit else ids:
        source = by_id.get(shape_id)
        if source is None:
            skipped[shape_id] = f"not found in {corpora}"
            continue
        try:
            meshes.append((shape_id, prepare_shape(load_shape(source.path, source.unit_scale), surface).mesh))
        except (MeshRejected, OSError, ValueError) as exc:
            skipped[shape_id] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return meshes, skipped


RECORDED = 12  # objects whose first attempt is recorded in every arm (the pictures are drawn from them)


def paper_objects(objects, rule: dict[str, dict], k: int, seed: int) -> list:
    """The paper's protocol's objects: ``k`` of ``objects`` that the feasibility ``rule`` (name → its
    :func:`~graspaug.sim.feasibility.feasibility`) declares feasible, a seeded choice (by the rule, never by an
    outcome); all of them where fewer are feasible."""
    feasible = sorted((o for o in objects if rule[o.name]["feasible"]), key=lambda o: o.name)
    order = np.random.default_rng([seed, 83]).permutation(len(feasible))[:k]
    return [feasible[i] for i in sorted(order)]


def fixed_poses(objects, seed: int, layout, settings, gripper) -> dict[str, tuple]:
    """Each object's one resting pose of the paper's protocol: where its first drop (seed from ``seed`` and its
    name) comes to rest in the cell (:func:`graspaug.sim.trials.resting_pose`)."""
    from graspaug.sim.trials import resting_pose

    poses = {}
    for obj in objects:
        drop = int(shape_rng(seed, obj.name, "sim-fixed-pose").integers(2**31 - 1))
        position, quaternion = resting_pose(obj.body, drop, layout, settings, gripper)
        poses[obj.name] = (tuple(float(x) for x in position), tuple(float(x) for x in quaternion))
    return poses


def jobs_for_draw(
    draw: int, folder: Path, objects, attempts: int, seed: int, pictures: bool, poses: dict | None = None
) -> list[ObjectJob]:
    """An :class:`ObjectJob` per object and arm (the draw's networks, the ``antipodal`` floor and the ``oracle``
    ceiling); an object's drops and planner seeds are drawn from ``seed`` and its name, the same in every arm (and
    every draw: the same object is dropped alike). Every network of the draw scores each executed grasp of the
    image-planning arms (``score_<arm>``), for their ranking of the cell's outcomes. ``poses`` (object name →
    resting pose): the paper's protocol, every attempt from that pose (the drop seeds draw the sensor noise)."""
    jobs = []
    for index, obj in enumerate(objects):
        record = pictures and index < RECORDED  # frames of the first attempt: a success and a failure to draw
        drops = tuple(int(shape_rng(seed, obj.name, f"sim-drop-{a}").integers(2**31 - 1)) for a in range(attempts))
        plans = tuple(int(shape_rng(seed, obj.name, f"sim-plan-{a}").integers(2**31 - 1)) for a in range(attempts))
        scorers = tuple((arm, str(folder / name / "model.pt")) for arm, name in draw_arms(folder).items())
        for arm, name in (draw_arms(folder) | {ANTIPODAL: None, ORACLE: None}).items():
            model = None if name is None else str(folder / name / "model.pt")
            scored = () if arm == ORACLE else scorers
            placement = None if poses is None else poses[obj.name]
            job = ObjectJob(arm, 0, model, obj.name, obj.kind, obj.body, drops, plans, record, scored, placement)
            jobs.append(job)
    return jobs


ATTEMPT_COLUMNS = (
    "draw", "seed", "arm", "object", "attempt", "drop_seed", "success", "outcome", "quality",
    "grasp_x", "grasp_y", "grasp_z", "jaw_angle", "feasible", "feasible_share", "mass", "contact_force", "contacts",
    "oracle_eps", "oracle_tilt",
)  # fmt: skip


def run(
    networks: Path,
    draws: list[int] | None,
    corpora: Path | None,
    objects_dir: Path | None,
    attempts: int,
    limit: int | None,
    params,
    fallback_surface,
    out: Path,
    pictures: bool,
    done: pd.DataFrame | None = None,
    on_draw=None,
    paper_k: int | None = None,
    feasible_only: bool = False,
    unit_scale: float = 1.0,
) -> tuple[pd.DataFrame, dict, str]:
    """Pick every object of every draw in every arm; (the attempts table, the summary, the report's markdown).
    ``out``: the folder the pictures go to (a staging folder). ``done``: attempts of earlier runs (a results
    folder's table); its draws are not picked again and its rows join the summary. ``on_draw(table, seconds)`` is
    called after each draw with every attempt so far, so a long study keeps each draw as it finishes. ``paper_k``:
    the paper's protocol instead of fresh drops: ``paper_k`` feasible objects a draw (:func:`paper_objects`), each
    in one fixed resting pose for all its attempts (:func:`fixed_poses`). ``feasible_only``: pick only the objects
    the feasibility rule declares feasible (fresh drops; the others are listed in ``skipped``). ``unit_scale``: metres
    per file unit of ``objects_dir``'s meshes."""
    from graspaug.sim.feasibility import feasibility
    from graspaug.sim.objects import prepare_objects

    folders = draw_folders(networks, draws)
    earlier = set() if done is None or done.empty else set(int(d) for d in done.draw)
    sim, rows, skipped, seconds = params.sim, [], {}, {}
    for d, folder in folders.items():
        if d in earlier:
            log.info("real-picks draw %d: in the results table already, not picked again", d)
            continue
        began = time.perf_counter()
        surface, card = card_surface(folder, fallback_surface)
        check_camera(card, sim.cell, folder)
        if objects_dir is not None:  # every mesh under it, read as evaluate reads --corpus (formats, --unit-scale)
            ids = [source.shape_id for source in object_sources(objects_dir, unit_scale)]
            meshes, missed = corpus_meshes(objects_dir, ids, surface, limit, unit_scale)
        else:
            meshes, missed = corpus_meshes(corpora, test_objects(folder), surface, limit)
        if not meshes:
            why = "; ".join(f"{k}: {v}" for k, v in missed.items())
            raise DataError(f"draw {d}: no object could be loaded ({why})")
        skipped |= {f"d{d}/{k}": v for k, v in missed.items()}
        physics = (sim.physics, params.seed, sim.vhacd_resolution)
        rule = {name: feasibility(mesh, params.grasps.gripper.max_width) for name, mesh in meshes}  # before any pick
        if feasible_only:
            skipped |= {f"d{d}/{n}": "not feasible (--feasible-only)" for n, _ in meshes if not rule[n]["feasible"]}
            meshes = [(n, m) for n, m in meshes if rule[n]["feasible"]]
            if not meshes:
                raise DataError(f"draw {d}: no feasible object (--feasible-only)")
        objects = prepare_objects((), (), Path("."), *physics, meshes, None, params.workers)
        poses = None
        if paper_k is not None:
            objects = paper_objects(objects, rule, paper_k, params.seed)
            if not objects:
                raise DataError(f"draw {d}: no feasible object for the paper's protocol")
            poses = fixed_poses(objects, params.seed, sim.cell, sim.trial, params.grasps.gripper)
        jobs = jobs_for_draw(d, folder, objects, attempts, params.seed, pictures, poses)
        arms = [*draw_arms(folder)]
        log.info("real-picks draw %d: %d objects × %d attempts, arms %s", d, len(objects), attempts, arms)
        picked = run_trials(jobs, sim, params.render.crop, params.workers, params.grasps.gripper, params.grasps)
        for row in picked:
            row["draw"] = d
            row["feasible"], row["feasible_share"] = rule[row["object"]]["feasible"], rule[row["object"]]["share"]
        rows += picked
        seconds[d] = round(time.perf_counter() - began)
        log.info("real-picks draw %d: %d attempts in %d s", d, len(picked), seconds[d])
        if on_draw is not None:
            on_draw(attempts_table(rows, done), seconds)
    table = attempts_table(rows, done)  # never empty: a draw is picked now or was kept before
    summary = pick_summary(table, list(dict.fromkeys(table.arm)), sim.n_bootstrap, params.seed)
    summary["feasible"] = feasible_summary(table, sim.n_bootstrap, params.seed)
    summary["feasibility_rule"] = {"max_width": params.grasps.gripper.max_width, "margin": 0.005, "min_height": 0.015}
    summary |= {"never_held": never_held(table), "skipped": skipped, "seconds": seconds, "attempts": attempts}
    summary["kept_before"] = sorted(earlier & set(folders))
    summary["protocol"] = "drops" if paper_k is None else f"paper: {paper_k} feasible objects a draw, one pose each"
    if pictures:
        draw_pictures(rows, out)
    return table, summary, report_markdown(table, summary)


def attempts_table(rows: list[dict], done: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per attempt (:data:`ATTEMPT_COLUMNS` and each network's ``score_<arm>`` of the executed grasp),
    earlier runs' ``done`` first."""
    scores = list(dict.fromkeys(k for row in rows for k in row if k.startswith("score_")))
    columns = [*ATTEMPT_COLUMNS, *scores]
    table = pd.DataFrame([{k: row.get(k) for k in columns} for row in rows], columns=columns)
    if done is not None and not done.empty:
        table = pd.concat([done, table], ignore_index=True) if len(table) else done.copy()
    return table.assign(success=table.success.astype(bool))


def earlier_attempts(folder: Path, attempts: int) -> tuple[pd.DataFrame | None, dict]:
    """The attempts table and meta of a results folder from an earlier run (``None`` where there is none); a run
    with another ``--attempts`` is refused: its draws would not be alike."""
    table, meta = folder / "attempts.parquet", folder / "meta.json"
    if not table.is_file():
        return None, {}
    meta = json.loads(meta.read_text()) if meta.is_file() else {}
    if meta.get("attempts") not in (None, attempts):
        raise DataError(f"{folder}: its draws have {meta['attempts']} attempts an object and arm, this run {attempts}")
    return pd.read_parquet(table), meta


def draw_pictures(rows: list[dict], out: Path) -> None:
    """One success and one failure of each network arm (the first recorded of each), drawn as the cell's pictures."""
    from graspaug.experiments.cell.figures import pick_story, trial_picture

    for arm in dict.fromkeys(r["arm"] for r in rows if r["arm"] not in (ANTIPODAL, ORACLE)):  # the networks
        for success in (True, False):
            row = next((r for r in rows if r["arm"] == arm and r["success"] == success and r.get("_frames")), None)
            if row is not None:
                pic = trial_picture(row, 0.0 if arm.startswith("none@") else 1.0)  # the network's ratio R
                name = f"{arm.replace('@', '-')}-{'success' if success else 'failure'}.png"
                pick_story(pic["depth"], pic["jaw"], pic["window"], pic["frames"], out / name, f"{arm}: {pic['title']}")


def report_markdown(table: pd.DataFrame, summary: dict) -> str:
    """The report: the table beside the paper's, rates and contrasts with their intervals and verdicts, the
    hardest objects and those no arm held."""

    def text(c: dict, sign: str = "+") -> str:  # sign "": a rate or an AUC, not a difference
        if c["low"] is None:  # too few objects or draws: say why, print no interval
            return f"{c['mean']:{sign}.3f} ({c.get('why', 'no interval')}; n = {c['n']} {c['over']})"
        ends = f"[{c['low']:{sign}.3f}, {c['high']:{sign}.3f}]"
        return f"{c['mean']:{sign}.3f} {ends} (95% over {c['over']}, n = {c['n']})"

    paper = paper_table(summary)
    lines = [
        "# Picks of real objects by arm",
        "",
        *picks_feasible_lines(summary.get("feasible") or {}, text),
        f"{summary['objects']} objects (object × draw), {summary['attempts']} attempts each and arm, draws "
        f"{summary['draws']}; an object's attempts are one unit (its share of successes)."
        + (
            f" Draws {summary['kept_before']}: in the results table already, not picked again."
            if summary.get("kept_before")
            else ""
        ),
        "",
        "| who | objects | attempts | before (none@50) | after (targeted@50) |",
        "|---|---|---|---|---|",
        *(f"| {r.who} | {r.objects} | {r.attempts} | {r.before} | {r.after} |" for r in paper.itertuples()),
        "",
        "| arm | success rate [95%] |",
        "|---|---|",
        *(f"| {a} | {text(c, '')} |" for a, c in summary["arms"].items()),
        "",
        "| contrast | difference [95%] | verdict |",
        "|---|---|---|",
        *(f"| {n} ({c['a']} − {c['b']}) | {text(c)} | {c['verdict']} |" for n, c in summary["contrasts"].items()),
        "",
        *ranking_lines(summary.get("ranking") or {}, text),
        f"Objects no arm ever held ({len(summary['never_held'])}): {', '.join(summary['never_held']) or 'none'}.",
        "",
        "The hardest objects (success share by arm):",
        "",
        hardest_objects(table).round(2).to_markdown(),
    ]
    return "\n".join(lines) + "\n"


def ranking_lines(ranking: dict, text) -> list[str]:
    """The report's lines on the networks' ranking of the executed grasps' outcomes (ROC AUC), if any."""
    if not ranking:
        return []
    if not ranking["arms"]:
        return [f"Ranking: {ranking['grasps']} executed grasps, all of one outcome in every draw: nothing to rank.", ""]
    return [
        f"Each network's ranking of the cell's outcomes: ROC AUC of its success probability against the outcome of "
        f"every executed grasp of every arm ({ranking['grasps']} grasps; every network scores the same ones):",
        "",
        "| network | ROC AUC [95%] |",
        "|---|---|",
        *(f"| {a} | {text(c, '')} |" for a, c in ranking["arms"].items()),
        "",
        "| ranking contrast | AUC difference [95%] | verdict |",
        "|---|---|---|",
        *(f"| {n} ({c['a']} − {c['b']}) | {text(c)} | {c['verdict']} |" for n, c in ranking["contrasts"].items()),
        "",
    ]


def write_results(folder: Path, table: pd.DataFrame, meta: dict) -> None:
    """``attempts.parquet`` (one row per attempt) and ``meta.json`` into the results folder ``folder``."""
    from graspaug.io.atomic import atomic_path

    folder.mkdir(parents=True, exist_ok=True)
    with atomic_path(folder / "attempts.parquet") as tmp:
        table.to_parquet(tmp, index=False)
    with atomic_path(folder / "meta.json") as tmp:
        tmp.write_text(json.dumps(meta, indent=1, default=lambda v: v.item() if isinstance(v, np.generic) else str(v)))
