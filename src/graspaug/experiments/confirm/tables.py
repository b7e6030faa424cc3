"""The confirmatory study's folder, ``results/<name>/`` with a ``plan.yaml`` (issue #74): its plan, its draws'
tables, and the checks that the plan came first.

* ``plan.yaml`` — committed before any other file of the folder and never edited (a new plan is a new folder):
  hypotheses, arms, statistic and test, alpha, draws (data seeds) and seeds per draw, the training rule, the power
  computation and the words each outcome is reported in (:func:`read_plan` names what it needs);
* ``networks.parquet`` — one row per draw, training seed and network (:func:`~graspaug.experiments.ap.numbers.collect`'s
  columns, ``train_steps`` among them);
* ``predictions-d<draw>-s<seed>.parquet`` — each network's P(success) on that draw's test datapoints, one float32
  column per network, ``<draw>/<seed>/<pool>/<B>-<R>``;
* ``test-d<draw>.parquet`` — that draw's test datapoints (``label``, ``object``): every draw has its own test objects;
* ``networks/d<draw>-s0/`` — the kept seed-0 networks of the control and primary arms (``model.pt``, ``card.json``)
  with ``objects.json`` (the objects each trained on, the draw's validation and test objects);
* ``meta.json`` — per draw its command, commit, date, wall time and machine; the params the draws ran with.

:func:`combine_confirm` reads the plan's tests (:mod:`graspaug.experiments.confirm`) once every planned draw is in;
before that it reports progress and nothing else (no interim look). :func:`check_plan_history` checks from git that
the plan was committed first and never changed, and that no draw once committed was dropped.
"""

from __future__ import annotations

import io
import json
import platform
import re
import subprocess
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from graspaug.errors import DataError
from graspaug.experiments.confirm import numbers as confirm
from graspaug.experiments.confirm.words import sentence_fields
from graspaug.experiments.kept import write_predictions
from graspaug.experiments.stats import weighted_average_precision

PLAN = "plan.yaml"
BASE_OBJECTS = "base-objects.parquet"  # each draw's base sets on actual counts (:func:`base_objects`)
PLAN_FORMAT = "graspaug.confirm-plan/1"
#: What a plan must say (its hypotheses and design); the study refuses a plan without one of them.
PLAN_KEYS = (
    "format",
    "question",
    "profile",
    "draws",
    "seeds",
    "arms",
    "training_rule",
    "statistic",
    "alpha",
    "control",
    "primary",
    "secondary",
    "power",
    "words",
)


def read_plan(path: Path) -> dict:
    """The plan at ``path`` (a ``plan.yaml``), checked: every key of :data:`PLAN_KEYS`, distinct draws, the arms the
    hypotheses name. A missing or incomplete plan is a :class:`DataError` naming what is missing."""
    path = Path(path)
    if not path.is_file():
        raise DataError(f"{path}: no plan; a confirmatory study runs only from a committed plan.yaml")
    try:
        plan = yaml.safe_load(path.read_text()) or {}
    except UnicodeDecodeError:
        raise DataError(f"{path}: not a text file; a plan is a YAML file (results/<name>/plan.yaml)") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = "" if mark is None else f" at line {mark.line + 1}, column {mark.column + 1}"
        raise DataError(f"{path}: not valid YAML{where}: {getattr(e, 'problem', None) or e}") from None
    if not isinstance(plan, dict):
        raise DataError(f"{path}: a plan is a YAML mapping of {', '.join(PLAN_KEYS)}; it holds a {type(plan).__name__}")
    missing = [k for k in PLAN_KEYS if k not in plan]
    if missing:
        raise DataError(f"{path}: the plan lacks {', '.join(missing)}")
    if plan["format"] != PLAN_FORMAT:
        raise DataError(f"{path}: format {plan['format']!r}, expected {PLAN_FORMAT!r}")
    if len(set(plan["draws"])) != len(plan["draws"]) or len(plan["draws"]) < 2:
        raise DataError(f"{path}: draws must be at least 2 distinct data seeds; got {plan['draws']}")
    named = {plan["control"]["a"], plan["control"]["b"], plan["primary"]["a"], plan["primary"]["b"]}
    named |= {s[k] for s in plan["secondary"] for k in ("a", "b") if k in s}
    unknown = sorted(named - set(plan["arms"]))
    if unknown:
        raise DataError(f"{path}: hypotheses name arms the plan does not define: {', '.join(unknown)}")
    level = interval_level(plan["alpha"])
    for key, words in plan["words"].items():
        for stated in re.findall(r"\((\d+(?:\.\d+)?)%", str(words)):
            if f"{stated}%" != level:
                raise DataError(
                    f"{path}: words.{key} labels its interval ({stated}%, but alpha {plan['alpha']} gives {level} "
                    "intervals; write ({level}, ...) and the level used is filled in"
                )
    return plan


def interval_level(alpha: float) -> str:
    """The two-sided level of a plan's intervals, 1 − ``alpha``, as a plan's words print it: ``95%``, ``90%``."""
    return f"{100 * (1 - float(alpha)):.10g}%"


def arm_key(plan: Mapping, arm: str) -> tuple[str, int, float]:
    """(pool, B, R) of a plan's arm name (``none@50`` is the targeted pool at 1:0, as the pipeline names it)."""
    pool, b, r = plan["arms"][arm]
    return str(pool), int(b), float(r)


def column(draw: int, seed: int, key: tuple) -> str:
    """A network's predictions column: ``<draw>/<seed>/<pool>/<B>-<R>``."""
    pool, b, r = key
    return f"{draw}/{seed}/{pool}/{b}-{r:g}"


def add_confirm_draw(
    folder: Path,
    plan: Mapping,
    draw: int,
    seed_dirs: Mapping[int, Path],
    labels,
    objects,
    meta: dict,
    roles: dict,
    external: Mapping[str, tuple] | None = None,
) -> None:
    """Add one finished draw to ``folder``: its predictions per seed, ``test-d<draw>.parquet``, its rows of
    ``networks.parquet``, the kept seed-0 networks (the plan's ``keep`` arms) with ``objects.json`` (``roles``: the
    draw's split by role, shape ids), each external test set's predictions (``external``: set name → (labels,
    objects, seed → column → P(success)); ``test-<set>.parquet`` once, the same for every draw,
    ``predictions-<set>-d<draw>-s<seed>.parquet``), and ``meta.json`` last. A draw the plan does not list, or an
    external set the plan does not name or whose datapoints differ from an earlier draw's, is refused."""
    from graspaug.experiments.ap.numbers import collect, test_predictions
    from graspaug.experiments.kept import keep_networks
    from graspaug.io.atomic import atomic_path
    from graspaug.training.variants import Variant

    if draw not in plan["draws"]:
        raise DataError(f"draw {draw} is not in the plan's draws {plan['draws']}: an extra draw is exploratory")
    keys = {arm: arm_key(plan, arm) for arm in plan["arms"]}
    variants = [Variant(*k) for k in keys.values()]
    runs = collect(seed_dirs, variants).assign(draw=draw)
    networks_file, meta_file = folder / "networks.parquet", folder / "meta.json"
    old = json.loads(meta_file.read_text()) if meta_file.is_file() else {}
    if "params" in old and old["params"] != meta["params"]:
        ran, runs = old["params"], meta["params"]
        changed = sorted(k for k in set(ran) | set(runs) if ran.get(k) != runs.get(k))
        raise DataError(f"{folder}: draw {draw} ran with other params than the draws there ({', '.join(changed)})")
    meta_file.unlink(missing_ok=True)  # a folder without meta.json is an unfinished one
    for s, seed_dir in seed_dirs.items():
        columns = {column(draw, s, k): test_predictions(seed_dir, k).astype(np.float32) for k in keys.values()}
        write_predictions(columns, folder / f"predictions-d{draw}-s{s}.parquet")
    test = pd.DataFrame({"label": np.asarray(labels, dtype=np.int8), "object": np.asarray(objects)})
    with atomic_path(folder / f"test-d{draw}.parquet") as tmp:
        test.to_parquet(tmp, index=False)
    for name, (set_labels, set_objects, by_seed) in (external or {}).items():
        if name not in external_sets(plan):
            raise DataError(f"test set {name!r} is not one the plan names ({', '.join(external_sets(plan))})")
        table = pd.DataFrame({"label": np.asarray(set_labels, dtype=np.int8), "object": np.asarray(set_objects)})
        path = folder / f"test-{name}.parquet"
        if path.is_file() and not pd.read_parquet(path).equals(table):
            raise DataError(f"{path}: draw {draw}'s {name} datapoints differ from the earlier draws' (one set for all)")
        with atomic_path(path) as tmp:
            table.to_parquet(tmp, index=False)
        for s, columns in by_seed.items():
            columns = {k: np.asarray(v, dtype=np.float32) for k, v in columns.items()}
            write_predictions(columns, folder / f"predictions-{name}-d{draw}-s{s}.parquet")
    networks = runs[["draw", *[c for c in runs.columns if c != "draw"]]]
    if networks_file.is_file():
        others = pd.read_parquet(networks_file)
        networks = pd.concat([others[others.draw != draw], networks], ignore_index=True).sort_values(
            ["draw", "seed"], kind="stable"
        )
    with atomic_path(networks_file) as tmp:
        networks.reset_index(drop=True).to_parquet(tmp, index=False)
    kept = folder / "networks" / f"d{draw}-s0"
    if 0 in seed_dirs:
        keep_networks(seed_dirs[0], kept, [keys[a] for a in plan.get("keep", [])])
        with atomic_path(kept / "objects.json") as tmp:
            tmp.write_text(json.dumps(roles | {"arms": {a: list(keys[a]) for a in plan.get("keep", [])}}, indent=1))
    by_draw = old.get("draws", {}) | {
        str(draw): {k: meta[k] for k in ("command", "commit", "date", "seconds") if k in meta} | {"machine": machine()}
    }
    with atomic_path(meta_file) as tmp:
        top = {k: v for k, v in meta.items() if k not in ("seconds",)}
        by_draw = dict(sorted(by_draw.items(), key=lambda kv: int(kv[0])))
        tmp.write_text(json.dumps(old | top | {"draws": by_draw}, indent=1) + "\n")


def machine() -> str:
    """This machine in a few words (CPU model and cores), recorded with each draw's wall time."""
    import os

    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores"


def draw_values(folder: Path, plan: Mapping, draw: int, seeds: list[int]) -> dict[str, float]:
    """One draw's mean test AP over its seeds of every plan arm, by arm name. A file of the draw that is gone is a
    :class:`DataError` naming the draw and the file."""
    for name in [f"test-d{draw}.parquet", *(f"predictions-d{draw}-s{s}.parquet" for s in seeds)]:
        if not (folder / name).is_file():
            raise DataError(
                f"{folder}: draw {draw}'s {name} is gone (networks.parquet holds the draw); restore it from git "
                f"(git checkout -- {folder / name}) or run the draw again"
            )
    test = pd.read_parquet(folder / f"test-d{draw}.parquet")
    labels = test.label.to_numpy()
    out: dict[str, list[float]] = {arm: [] for arm in plan["arms"]}
    ones = np.ones(len(labels), dtype=np.float32)
    for s in seeds:
        predictions = pd.read_parquet(folder / f"predictions-d{draw}-s{s}.parquet")
        for arm in plan["arms"]:
            name = column(draw, s, arm_key(plan, arm))
            if name not in predictions:
                raise DataError(f"{folder}/predictions-d{draw}-s{s}.parquet: no column {name!r}")
            p = predictions[name].to_numpy()
            out[arm].append(float(weighted_average_precision(labels, p, ones)))
    return {arm: float(np.mean(v)) for arm, v in out.items()}


def combine_confirm(folder: Path) -> dict:
    """The plan's result from the folder's tables: progress until every planned draw is in, then the control, the
    primary and the secondary hypotheses with their verdicts in the plan's words (:func:`read_plan_result`). A draw
    the plan does not list, or a planned seed missing from a draw, is a :class:`DataError`."""
    plan = read_plan(folder / PLAN)
    planned, done = [int(d) for d in plan["draws"]], []
    networks = None
    if (folder / "networks.parquet").is_file():
        networks = pd.read_parquet(folder / "networks.parquet")
        extra = sorted(set(int(d) for d in networks.draw) - set(planned))
        if extra:
            raise DataError(f"{folder}: draws {extra} are not in the plan's draws {planned} (report them apart)")
        done = sorted(set(int(d) for d in networks.draw))
        for d in done:
            seeds = sorted(set(int(s) for s in networks.seed[networks.draw == d]))
            if seeds != sorted(plan["seeds"]):
                raise DataError(f"{folder}: draw {d} holds seeds {seeds}, the plan {sorted(plan['seeds'])}")
    meta = json.loads((folder / "meta.json").read_text()) if (folder / "meta.json").is_file() else {}
    out = {"draws_planned": planned, "draws_done": done, "complete": done == sorted(planned)}
    out["wall_seconds"] = {d: v.get("seconds") for d, v in meta.get("draws", {}).items()}
    if networks is not None:
        steps = networks.groupby(["pool", "base_size", "ratio"]).train_steps.agg(["min", "max"]).reset_index()
        out["train_steps"] = steps.to_dict(orient="records")
    if not out["complete"]:
        out["status"] = f"in progress: {len(done)} of {len(planned)} planned draws"
        return out
    values = {d: draw_values(folder, plan, d, sorted(plan["seeds"])) for d in planned}
    external = {name: external_result(folder, plan, name) for name in external_sets(plan)}
    counts = None
    if (folder / BASE_OBJECTS).is_file():
        counts = pd.read_parquet(folder / BASE_OBJECTS)
        check_base_objects(counts, networks)
    result = read_plan_result(plan, values, counts)
    return out | {"status": "complete"} | result | ({"external": external} if external else {})


def external_sets(plan: Mapping) -> dict[str, dict]:
    """The plan's external test sets (``test_sets``: name → ``corpus``, ``readout`` ``pooled`` or ``per_object``,
    ``resamples``, and its own ``words``), read beside each draw's own held-out objects, each gated by its own
    control."""
    return {k: dict(v) for k, v in (plan.get("test_sets") or {}).items() if isinstance(v, Mapping) and v.get("corpus")}


def external_result(folder: Path, plan: Mapping, name: str) -> dict:
    """The plan's tests on its external set ``name``: per draw, seed and arm the set's readout (its ``readout``:
    pooled AP or the mean of per-object AP) on all objects and under the objects' resamples (one set, the same
    resamples for every network), each contrast by :func:`~graspaug.experiments.confirm.numbers.nested_draw_test`."""
    spec = external_sets(plan)[name]
    readout, n = spec.get("readout", "pooled"), int(spec.get("resamples", 1000))
    test = pd.read_parquet(folder / f"test-{name}.parquet")
    labels, objects = test.label.to_numpy().astype(bool), test.object.to_numpy()
    draws, seeds = sorted(int(d) for d in plan["draws"]), sorted(plan["seeds"])
    cells: dict[tuple, tuple] = {}
    for d in draws:
        for s in seeds:
            path = folder / f"predictions-{name}-d{d}-s{s}.parquet"
            if not path.is_file():
                raise DataError(f"{path}: draw {d}'s {name} predictions are missing")
            predictions = pd.read_parquet(path)
            for arm in plan["arms"]:
                col = column(d, s, arm_key(plan, arm))
                if col not in predictions:
                    raise DataError(f"{path}: no column {col!r}")
                cells[d, s, arm] = confirm.network_values(labels, objects, predictions[col].to_numpy(), n, 0)[readout]

    def test_of(c):
        full = np.array([[cells[d, s, c["a"]][0] - cells[d, s, c["b"]][0] for s in seeds] for d in draws])
        boot = np.array([[cells[d, s, c["a"]][1] - cells[d, s, c["b"]][1] for s in seeds] for d in draws])
        return confirm.nested_draw_test(full, boot, 1 - float(plan["alpha"]))

    out = read_plan_tests(plan, test_of, words=spec.get("words"))
    out["exploratory"] = {e["name"]: test_of(e) for e in exploratory_contrasts(plan)}
    arms = {arm: float(np.mean([cells[d, s, arm][0] for d in draws for s in seeds])) for arm in plan["arms"]}
    held = test.groupby("object").label.any()
    counts = {"objects": int(len(held)), "objects_with_positive": int(held.sum()), "datapoints": int(len(test))}
    return out | {"readout": readout, "arms": arms, "counts": counts | {"positives": int(test.label.sum())}}


def base_objects(
    objects: pd.DataFrame,
    original: Path,
    draws: list[int],
    base_sizes: list[int],
    test_fraction: float,
    val_shapes: int,
    seed: int,
    independent_draws: bool = True,
) -> pd.DataFrame:
    """What each draw's base sets hold on actual counts: the objects table ``objects`` (ingest's) split as the
    ``split`` stage splits it for each data seed of ``draws``, the base sets drawn as ``train_gqcnn`` draws them, kept
    where the rendered original corpus (dataset folder ``original``) holds datapoints of the object. One row a
    (draw, base size): ``draw``, ``base_size`` (nominal), ``objects`` (base objects holding datapoints),
    ``datapoints`` (theirs: what a 1:0 network of that size trains on) and ``train_objects`` (the draw's train
    split, every object of which the draw's AutoEncoder-Critic learned)."""
    from graspaug.augment.corpus import split_objects, split_seed
    from graspaug.io.tables import read_table
    from graspaug.training.gqcnn_data import load_split

    per_object = read_table(Path(original) / "index.parquet").groupby("shape_id").size()
    rows = []
    for draw in draws:
        shapes = split_objects(objects, test_fraction, split_seed(seed, draw, independent_draws))
        split = load_split(Path(original), shapes, sorted(base_sizes), val_shapes, draw)
        for size, ids in split.base.items():
            rows.append(
                {
                    "draw": int(draw),
                    "base_size": int(size),
                    "objects": len(ids),
                    "datapoints": int(per_object.reindex(list(ids)).fillna(0).sum()),
                    "train_objects": int((shapes.split == "train").sum()),
                }
            )
    return pd.DataFrame(rows)


def check_base_objects(counts: pd.DataFrame, networks: pd.DataFrame) -> None:
    """A :func:`base_objects` table agrees with the draws it describes: every 1:0 network of ``networks`` (a plan
    folder's ``networks.parquet``) trained on exactly the datapoints the table gives its draw and base size; else a
    :class:`DataError` naming the first that does not (the objects or renders it was made from are not the draws')."""
    keys = ["draw", "base_size"]
    plain = networks.loc[networks.ratio == 0, [*keys, "train_datapoints"]].drop_duplicates(keys)
    both = plain.merge(counts[[*keys, "datapoints"]], on=keys, how="left")
    wrong = both[both.datapoints.isna() | (both.datapoints != both.train_datapoints)]
    if len(wrong):
        draw, size, trained, counted = wrong[[*keys, "train_datapoints", "datapoints"]].to_numpy()[0]
        counted = "none" if np.isnan(counted) else f"{counted:.0f}"
        raise DataError(
            f"draw {draw:.0f}, base size {size:.0f}: its 1:0 network trained on {trained:.0f} datapoints, the counted "
            f"base set holds {counted} (count again from a finished draw's clone: `graspaug study confirm --plan "
            "<plan> --count-objects <clone>`)"
        )


def exploratory_contrasts(plan: Mapping) -> list[dict]:
    """The contrasts a plan's ``exploratory`` text names as ``<arm> - <arm>`` between two of its arms, in its order, as
    specs (``name`` ``<a>-<b>``, ``a``, ``b``): read over draws with the plan's intervals, given no verdict."""
    text = plan.get("exploratory")
    if not isinstance(text, str):
        return []
    pairs = re.findall(r"([\w@]+)\s+[-−]\s+([\w@]+)", text)
    arms = plan["arms"]
    return [{"name": f"{a}-{b}", "a": a, "b": b} for a, b in pairs if a in arms and b in arms]


def read_plan_result(
    plan: Mapping, values: Mapping[int, Mapping[str, float]], counts: pd.DataFrame | None = None
) -> dict:
    """The plan's tests on per-draw arm values (draw → arm → mean test AP over its seeds), in the fixed sequence:
    the control, then the primary, then the secondary family under Holm; with the plan's words. With ``counts`` (a
    :func:`base_objects` table) the plan's exchange rate is also read on actual counts (``exchange_actual``: each
    draw's curve at the objects its base sets hold; ``base_objects``: the arm's base set on actual counts and the
    train objects its generator learned)."""
    alpha = float(plan["alpha"])
    draws = sorted(values)

    def diff(spec):
        return [values[d][spec["a"]] - values[d][spec["b"]] for d in draws]

    result = read_plan_tests(plan, lambda spec: confirm.draw_test(diff(spec), 1 - alpha), diff)
    result["primary"]["sensitivity"] = confirm.draw_sensitivity(result["primary"]["per_draw"], 1 - alpha)
    curve = plan.get("exchange")
    if curve and result["control"]["shows"]:
        sizes = curve["sizes"]
        grid = np.array([[values[d][f"none@{b}"] for b in sizes] for d in draws])
        arm = np.array([values[d][curve["arm"]] for d in draws])
        result["exchange"] = confirm.exchange_rate_on_curve(sizes, grid, arm, 1 - alpha) | {"arm": curve["arm"]}
        if counts is not None:
            actual = counts.set_index(["draw", "base_size"]).objects
            held = np.array([[actual[d, b] for b in sizes] for d in draws], dtype=float)
            result["exchange_actual"] = confirm.exchange_rate_on_curve(held, grid, arm, 1 - alpha) | {
                "arm": curve["arm"]
            }
            own = int(arm_key(plan, curve["arm"])[1])
            on = counts[counts.base_size == own]
            result["base_objects"] = {
                "nominal": own,
                "min": int(on.objects.min()),
                "max": int(on.objects.max()),
                "mean": float(on.objects.mean()),
                "train_objects_min": int(on.train_objects.min()),
                "train_objects_max": int(on.train_objects.max()),
            }
    result["exploratory"] = {e["name"]: confirm.draw_test(diff(e), 1 - alpha) for e in exploratory_contrasts(plan)}
    result["per_draw_ap"] = {str(d): values[d] for d in draws}
    result["arms"] = {arm: float(np.mean([values[d][arm] for d in draws])) for arm in plan["arms"]}
    return result


def read_plan_tests(plan: Mapping, test_of, diff=None, words: Mapping | None = None) -> dict:
    """The plan's tests in its fixed sequence, each ``test_of(spec)`` (a spec names arms ``a`` and ``b``; a test
    gives ``mean``, ``low``, ``high``, ``p``, ``n_draws``): the control first (it "shows" when p < alpha and its mean
    is positive; if not, the verdict is "uninformative"), the primary, then the secondary family under Holm (an
    equivalence verdict where a secondary names a ``margin`` and ``diff(spec)``, the per-draw values, is given);
    with the plan's sentence (``words``: another test set's own, else the plan's ``words``)."""
    alpha = float(plan["alpha"])
    control = test_of(plan["control"])
    shows = control["p"] is not None and control["p"] < alpha and control["mean"] > 0
    primary = test_of(plan["primary"])
    secondary = {s["name"]: test_of(s) for s in plan["secondary"] if "a" in s}
    adjusted = confirm.holm({k: v["p"] for k, v in secondary.items()})
    for name, c in secondary.items():
        c["p_holm"] = adjusted[name]
        spec = next(s for s in plan["secondary"] if s.get("name") == name)
        if "margin" in spec and diff is not None:
            c["equivalence"] = confirm.tost(diff(spec), float(spec["margin"]), alpha)
            c["verdict"] = confirm.equivalence_verdict(c, c["equivalence"], alpha, adjusted[name])
        elif not shows:
            c["verdict"] = confirm.UNINFORMATIVE
        else:
            held = adjusted[name] is not None and adjusted[name] < alpha
            c["verdict"] = ("higher" if c["mean"] > 0 else "lower") if held else "not shown"
    words = words or plan["words"]
    if not shows:
        verdict, sentence = confirm.UNINFORMATIVE, words["uninformative"]
    elif primary["p"] < alpha:
        verdict = "raises" if primary["mean"] > 0 else "lowers"
        sentence = words[verdict]
    else:
        verdict, sentence = "not shown", words["not_shown"]
    result = {"control": control | {"shows": shows}, "primary": primary | {"verdict": verdict}, "secondary": secondary}
    fields = sentence_fields(primary) | {"level": interval_level(alpha)}
    result["sentence"] = sentence.format(**fields, control=sentence_fields(control))
    return result


def _git(root: Path, *args: str) -> str:
    done = subprocess.run(["git", *args], cwd=root, capture_output=True, text=True)
    if done.returncode != 0:
        why = done.stderr.strip() or "failed"
        raise DataError(f"git {' '.join(args)} in {root}: {why} (the plan's history is read from git)")
    return done.stdout


def check_plan_history(folder: Path) -> list[str]:
    """The problems of a confirmatory folder's git history (none: an empty list): the plan was not committed, was
    changed after its first commit or differs from it now; another file of the folder was committed in or before the
    plan's commit; a draw that a commit of ``networks.parquet`` held is gone."""
    folder = Path(folder).resolve()
    root = Path(_git(folder, "rev-parse", "--show-toplevel").strip())
    if _git(root, "rev-parse", "--is-shallow-repository").strip() == "true":
        return [f"{folder.name}: a shallow clone holds no history to check the plan against (git fetch --unshallow)"]
    rel = folder.relative_to(root)
    plan = (rel / PLAN).as_posix()
    commits = _git(root, "log", "--format=%H", "--follow", "--", plan).split()
    if not commits:
        return [f"{plan}: not committed (commit the plan before its first draw)"]
    problems = []
    if len(commits) > 1:
        later = len(commits) - 1
        problems.append(f"{plan}: changed after its first commit ({later} later commit(s)); a new plan is a new folder")
    if _git(root, "status", "--porcelain", "--", plan).strip():
        problems.append(f"{plan}: differs from its committed text")
    first, added = commits[-1], {}
    for line in _git(root, "log", "--format=@%H", "--name-only", "--diff-filter=A", "--", rel.as_posix()).splitlines():
        if line.startswith("@"):
            commit = line[1:]
        elif line.strip() and line.strip() != plan:
            added.setdefault(commit, []).append(line.strip())
    for commit, files in added.items():
        if commit == first or _is_ancestor(root, commit, first):
            problems.append(f"{files[0]}: committed in or before the plan's commit {first[:10]}")
    networks = (rel / "networks.parquet").as_posix()
    now = set()
    if (root / networks).is_file():
        now = set(int(d) for d in pd.read_parquet(root / networks).draw)
    for commit in _git(root, "log", "--format=%H", "--", networks).split():
        blob = subprocess.run(["git", "show", f"{commit}:{networks}"], cwd=root, capture_output=True)
        if blob.returncode != 0:
            continue  # the file was deleted in that commit
        gone = set(int(d) for d in pd.read_parquet(io.BytesIO(blob.stdout)).draw) - now
        if gone:
            problems.append(f"{networks}: draw(s) {sorted(gone)} committed in {commit[:10]} are gone")
            break
    return problems


def _is_ancestor(root: Path, a: str, b: str) -> bool:
    return subprocess.run(["git", "merge-base", "--is-ancestor", a, b], cwd=root).returncode == 0


def exploratory_contrast(folder: Path, a: tuple, b: tuple, n_resamples: int, seed: int) -> tuple[np.ndarray, ...]:
    """A contrast (network ``a`` − ``b``, each (pool, B, R)) of an attribution study's folder (one test set for every
    draw): (D, S) on all test objects and (D, S, ``n_resamples``) under the same object resamples in every cell."""
    from graspaug.experiments.stats import ObjectBootstrap

    networks, test = pd.read_parquet(folder / "networks.parquet"), pd.read_parquet(folder / "test.parquet")
    labels = test.label.to_numpy()
    boot = ObjectBootstrap(test.object.to_numpy(), n_resamples, seed)
    ones = np.ones(len(labels), dtype=np.float32)
    draws, seeds = sorted(set(networks.draw)), sorted(set(networks.seed))
    full, resampled = np.zeros((len(draws), len(seeds))), np.zeros((len(draws), len(seeds), n_resamples))
    for i, d in enumerate(draws):
        for j, s in enumerate(seeds):
            p = pd.read_parquet(folder / f"predictions-d{d}-s{s}.parquet")
            pa, pb = (p[column(d, s, (k[0], int(k[1]), float(k[2])))].to_numpy() for k in (a, b))
            full[i, j] = weighted_average_precision(labels, pa, ones) - weighted_average_precision(labels, pb, ones)
            resampled[i, j] = boot.average_precision(labels, pa) - boot.average_precision(labels, pb)
    return full, resampled


def design(
    exploratory: Path,
    a: tuple,
    b: tuple,
    effect: float,
    alpha: float,
    draw_minutes: float,
    seed_minutes: float,
    draws: int,
    seeds: int,
    n_sims: int = 2000,
    seed: int = 0,
) -> dict:
    """The plan's power and coverage from an exploratory study: the contrast's variance parts, the draws needed for
    80% power at ``effect`` for 1 … 8 seeds a draw with their compute, the power of ``draws`` × ``seeds``, and the
    coverage of the draw-level t-interval at that design, simulated on the exploratory networks."""
    full, resampled = exploratory_contrast(exploratory, a, b, max(n_sims * draws, 2000), seed)
    parts = confirm.variance_components(full, resampled)
    sd = confirm.draw_mean_sd(parts, seeds)
    coverage = confirm.simulate_coverage(full, resampled, draws, seeds, n_sims, np.random.default_rng(seed), 1 - alpha)
    return {
        "exploratory": str(exploratory),
        "contrast": {"a": list(a), "b": list(b)},
        "components": parts,
        "effect": effect,
        "alpha": alpha,
        "draw_minutes": draw_minutes,
        "seed_minutes": seed_minutes,
        "by_seeds": confirm.seeds_for_cost(parts, effect, draw_minutes, seed_minutes, alpha),
        "planned": {"draws": draws, "seeds": seeds, "draw_sd": sd, "power": confirm.power(draws, sd, effect, alpha)},
        "coverage": coverage,
    }
