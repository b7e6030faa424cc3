"""Results as data: each study's per-network, per-test-datapoint tables in ``results/<study>/``, and every figure the
README and docs/results.md quote, recomputed from them (issue #58).

``results/attribution/`` (written by ``graspaug study attribution``, read by :func:`recompute`):

* ``networks.parquet`` — one row per draw, training seed and network: ``draw`` (``data_seed``), ``pool``,
  ``base_size``, ``ratio``, ``seed``, ``val_ap``, ``test_ap``, ``test_roc_auc``, ``train_datapoints``
  (:func:`~graspaug.experiments.ap.numbers.collect`'s columns);
* ``predictions-d<draw>-s<seed>.parquet`` — one per draw and training seed (each under 2 MB), one row per test
  datapoint, one float32 column per network of that draw and seed, ``<draw>/<seed>/<pool>/<B>-<R>``: its P(success);
* ``test.parquet`` — one row per test datapoint, in the same order: ``label`` (1: a successful grasp), ``object``
  (its test shape);
* ``meta.json`` — the exact ``command`` and code ``commit`` that made them, the date (and per draw, ``draws``), and
  the params the combination reads (``base_sizes``, ``ratios``, ``augment_base_sizes``, ``pools``,
  ``control_ratios``, ``n_resamples``, ``seed``), written last.

Each draw is added as it finishes (:func:`add_attribution_draw`), so a study that stops keeps what it finished, and
``graspaug study attribution --combine-only`` combines from these files alone, on any machine.

``results/lifelong/`` (written by ``graspaug study lifelong``, :func:`write_lifelong`): ``predictions.parquet`` (one
float32 column per round, draw, training seed and arm, ``r<k>/<draw>/<seed>/<arm>``), ``test.parquet`` and
``meta.json`` as above.

``results/fidelity-<label>/`` (from ``graspaug study heldout-fidelity``, one run per AutoEncoder compared):
``per_shape.parquet`` (each run's ``per_shape.csv``, stacked, its ``ae`` column naming the AutoEncoder) and
``meta.json`` (the commands and commit); :func:`combine_fidelity` gives each AutoEncoder's figures.

``results/precision-<label>/`` (from ``graspaug study precision --results``): ``networks.parquet`` (member 0's
validation AP per run, seed and network), ``ae_iou.parquet`` (held-out IoU per AutoEncoder and test shape, both
precisions), ``recon.parquet`` (the recon pool's fidelity row of each run) and ``meta.json``;
:func:`combine_precision` gives :func:`graspaug.experiments.precision.summarize` of them.

A quoted figure is marked in the markdown by an html comment naming its key, the figure right after it::

    <!-- results:attribution/targeted_vs_none@100 -->+0.0100 [+0.0010, +0.0210]

and :func:`check_markdown` says where a marked figure differs from the recomputed one (``graspaug results --check``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.stats import interval_text, share_text

MARKER = re.compile(r"<!-- results:([\w@./+-]+) -->")
LOOSE = re.compile(r"<!--\s*results\b.*?-->", re.DOTALL)  # anything that looks like a marker, well formed or not
CONTINUES = re.compile(r"[\w%\[]|[.,]\d")  # after a figure: it would go on (a digit, a letter, %, [, .5 or ,5)
FILES = ("networks.parquet", "test.parquet", "meta.json")  # and predictions-d<draw>-s<seed>.parquet
DOCUMENTS = ("README.md", "docs/results.md")  # the markdown whose marked figures must equal the recomputed ones


def _column(draw: int, seed: int, key: tuple) -> str:
    from graspaug.training.variants import network_variant

    return f"{draw}/{seed}/{network_variant(*key).name}"


def write_attribution(
    folder: Path, draws: Mapping[int, Mapping[int, Path]], labels, object_ids, generate, gqcnn, meta: dict
) -> None:
    """Write the attribution study's tables (module docstring) into ``folder`` from its networks' folders: one
    :func:`add_attribution_draw` per draw.

    Parameters
    ----------
    draws : data seed → training seed → the folder of that seed's networks (``summary.json``, ``test_predictions.npy``)
    labels, object_ids : (N,) — the test datapoints' labels and objects, in the predictions' order
    generate, gqcnn : the params sections the draws ran with
    meta : ``command``, ``commit``, ``date``, ``n_resamples``, ``seed`` — kept in ``meta.json``
    """
    for d, seed_dirs in draws.items():
        add_attribution_draw(folder, d, seed_dirs, labels, object_ids, generate, gqcnn, meta)


def _kept_params(generate, gqcnn) -> dict:
    """The params an attribution combination reads, as ``meta.json`` keeps them."""
    return {
        "base_sizes": [int(b) for b in generate.base_sizes],
        "ratios": [float(r) for r in generate.ratios],
        "augment_base_sizes": [int(b) for b in gqcnn.augment_base_sizes],
        "pools": list(gqcnn.pools),
        "control_ratios": None if gqcnn.control_ratios is None else [float(r) for r in gqcnn.control_ratios],
    }


def _flat(tree: Mapping, prefix: str = "") -> dict:
    """A nested params mapping as ``{"a.b.c": value}``."""
    out = {}
    for key, value in tree.items():
        if isinstance(value, Mapping):
            out |= _flat(value, f"{prefix}{key}.")
        else:
            out[f"{prefix}{key}"] = value
    return out


def add_attribution_draw(
    folder: Path, draw: int, seed_dirs: Mapping[int, Path], labels, object_ids, generate, gqcnn, meta: dict
) -> None:
    """Add (or replace) one finished draw's tables in ``folder`` at once, so a study that stops keeps every draw it
    finished: ``predictions-d<draw>-s<seed>.parquet`` (one float32 column per network,
    ``<draw>/<seed>/<pool>/<B>-<R>``), its rows of ``networks.parquet``, ``test.parquet`` (written by the first
    draw, checked by the others) and ``meta.json`` (written last; ``draws``: draw → its ``command``, ``commit``,
    ``date`` and ``seconds``).

    Parameters
    ----------
    draw : int — the draw's data seed
    seed_dirs : training seed → the folder of that seed's networks (``summary.json``, ``test_predictions.npy``)
    labels, object_ids : (N,) — the test datapoints' labels and objects, in the predictions' order
    generate, gqcnn : the params sections the draw ran with; a folder of other params is refused, naming the key
    meta : ``command``, ``commit``, ``date``, ``n_resamples``, ``seed`` (and the draw's wall time, ``seconds``), and
        ``params``: the draw's params but ``data_seed`` (a draw whose params differ from the folder's in any key is
        refused, naming it)
    """
    from graspaug.experiments.ap.numbers import collect, test_predictions
    from graspaug.experiments.kept import write_predictions
    from graspaug.io.atomic import atomic_path
    from graspaug.training.variants import seed_variants

    folder.mkdir(parents=True, exist_ok=True)
    keep = _kept_params(generate, gqcnn)
    test = pd.DataFrame({"label": np.asarray(labels, dtype=np.int8), "object": np.asarray(object_ids)})
    meta_file, networks_file, test_file = folder / "meta.json", folder / "networks.parquet", folder / "test.parquet"
    old = json.loads(meta_file.read_text()) if meta_file.is_file() else {}
    for key, value in keep.items():
        if key in old and old[key] != value:
            raise DataError(f"{folder}: its draws ran with {key} = {old[key]}, draw {draw} with {value}")
    ran, runs_with = _flat(old.get("params") or {}), _flat(meta.get("params") or {})
    for key in sorted(set(ran) & set(runs_with)):  # every other setting (steps, views, corpus) must agree too
        if ran[key] != runs_with[key]:
            raise DataError(f"{folder}: its draws ran with {key} = {ran[key]}, draw {draw} with {runs_with[key]}")
    if test_file.is_file() and not pd.read_parquet(test_file).equals(test):
        raise DataError(f"{folder}: draw {draw} was tested on other datapoints than the draws already there")
    variants = seed_variants(
        generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, False, gqcnn.pools, gqcnn.control_ratios
    )
    runs = collect(seed_dirs, variants)
    by_seed = {
        s: {
            _column(draw, s, (v.pool, v.base_size, float(v.ratio))): test_predictions(
                folder_s, (v.pool, v.base_size, float(v.ratio))
            ).astype(np.float32)
            for v in variants
        }
        for s, folder_s in seed_dirs.items()
    }
    networks = runs.assign(draw=draw)[["draw", *runs.columns]]
    if networks_file.is_file():
        others = pd.read_parquet(networks_file)
        networks = pd.concat([others[others.draw != draw], networks], ignore_index=True)
        networks = networks.sort_values("draw", kind="stable")
    meta_file.unlink(missing_ok=True)  # a folder without meta.json is an unfinished one
    for old_file in folder.glob(f"predictions-d{draw}-s*.parquet"):
        old_file.unlink()
    for s, columns in by_seed.items():
        write_predictions(columns, folder / f"predictions-d{draw}-s{s}.parquet")
    for name, frame in {"networks.parquet": networks.reset_index(drop=True), "test.parquet": test}.items():
        with atomic_path(folder / name) as tmp:
            frame.to_parquet(tmp, index=False)
    by_draw = old.get("draws", {}) | {
        str(draw): {k: meta[k] for k in ("command", "commit", "date", "seconds") if k in meta}
    }
    by_draw = dict(sorted(by_draw.items(), key=lambda kv: int(kv[0])))
    with atomic_path(meta_file) as tmp:  # command, commit and date at the top: the latest draw's
        top = {k: v for k, v in meta.items() if k != "seconds"}
        tmp.write_text(json.dumps(old | top | keep | {"draws": by_draw}, indent=1) + "\n")


def combine_attribution(folder: Path, draws: Sequence[int] | None = None) -> dict:
    """:func:`~graspaug.experiments.ap.attribution.combine_runs` of the tables in ``folder`` (module docstring), with
    the resamples and seed its ``meta.json`` names: the study's ``summary.json``, figure for figure. ``draws``: the
    draws to combine (default: every draw the folder holds)."""
    from graspaug.experiments.ap.attribution import combine_runs

    missing = [name for name in FILES if not (folder / name).is_file()]
    if missing:
        raise DataError(f"{folder}: no {', '.join(missing)} (an unfinished or foreign results folder)")
    meta = json.loads((folder / "meta.json").read_text())
    networks = pd.read_parquet(folder / "networks.parquet")
    test = pd.read_parquet(folder / "test.parquet")
    runs = {int(d): g.drop(columns="draw").reset_index(drop=True) for d, g in networks.groupby("draw", sort=True)}
    if draws is not None:
        absent = sorted(set(draws) - set(runs))
        if absent:
            raise DataError(f"{folder}: no draw {', '.join(map(str, absent))} (it holds {sorted(runs)})")
        runs = {d: runs[d] for d in sorted(draws)}
    files = {(d, s): folder / f"predictions-d{d}-s{s}.parquet" for d, r in runs.items() for s in sorted(set(r.seed))}
    missing = [str(f.name) for f in files.values() if not f.is_file()]
    if missing:
        raise DataError(f"{folder}: no {', '.join(missing)} (an unfinished or foreign results folder)")
    predictions = pd.concat([pd.read_parquet(f) for f in files.values()], axis=1)

    def network(d: int, s: int, key: tuple) -> np.ndarray:
        name = _column(d, s, key)
        if name not in predictions:
            raise DataError(f"{folder / f'predictions-d{d}-s{s}.parquet'}: no column {name!r}")
        return predictions[name].to_numpy()

    generate = SimpleNamespace(base_sizes=meta["base_sizes"], ratios=meta["ratios"])
    control = meta.get("control_ratios")  # absent from tables written before gqcnn.control_ratios: every ratio
    gqcnn = SimpleNamespace(
        augment_base_sizes=meta["augment_base_sizes"], pools=tuple(meta["pools"]), control_ratios=control
    )
    labels, objects = test.label.to_numpy(), test.object.to_numpy()
    result = combine_runs(runs, network, labels, objects, generate, gqcnn, meta["n_resamples"], meta["seed"])
    return result | {"augment_base_sizes": meta["augment_base_sizes"]}


def per_draw_text(c: Mapping) -> str:
    """A contrast's ``per_draw`` means (AP, in draw order) as a document quotes them: ``+0.0100, -0.0200``."""
    return ", ".join("-" if v is None else f"{v:+.4f}" for v in c.get("per_draw") or [])


def attribution_figures(result: dict, study: str = "attribution") -> dict[str, str]:
    """Every figure of an attribution result (:func:`combine_attribution`) as the text a document quotes, by key:
    ``<study>/<contrast>`` (``mean [low, high]``, AP, 4 decimals), ``<study>/<contrast>/per_draw`` (each draw's mean
    over seeds, in draw order), ``<study>/share/<pool>@<B>`` (the share with its
    interval by test inversion, or ``[unbounded]``), ``<study>/real_gain@<B>`` (the shares' denominator),
    ``<study>/gain/<pool>@<B>`` (their numerator: the pool's gain over no augmentation) and
    ``<study>/worth/<pool>@<B>`` (what the pool's shapes are worth in real shapes: ``exchange_rate``)."""
    from graspaug.experiments.ap.attribution import exchange_rate, exchange_text

    out = {f"{study}/{name}": interval_text(c) for name, c in result["contrasts"].items()}
    for name, c in result["contrasts"].items():  # the mean over seeds of each draw, in draw order
        out[f"{study}/{name}/per_draw"] = per_draw_text(c)
    for n, c in result.get("real_curve", {}).items():
        if c["gain"] is not None:
            out[f"{study}/real_curve/{n}"] = interval_text(c["gain"])
            out[f"{study}/real_curve/{n}/per_draw"] = per_draw_text(c["gain"])
    for pool, by_size in result["shares"].items():
        for b, s in by_size.items():
            out[f"{study}/share/{pool}@{b}"] = share_text(s)
            out[f"{study}/real_gain@{b}"] = interval_text(s["real_gain"])
            if s.get("gain") is not None:  # the share's numerator: the pool's own gain over no augmentation
                out[f"{study}/gain/{pool}@{b}"] = interval_text(s["gain"])
            if "shapes" in s:
                out[f"{study}/worth/{pool}@{b}"] = exchange_text(exchange_rate(s))
    return out


def recompute(results_dir: Path) -> tuple[dict[str, str], dict[str, dict]]:
    """Every figure of every study folder in ``results_dir`` (``results/``): (key → text, study → result). A study
    folder named ``<study>`` or ``<study>-<label>`` (e.g. ``attribution-real-objects``) is read by ``<study>``'s
    functions and its keys start with its folder name."""
    figures, results = {}, {}
    for folder in sorted(p for p in Path(results_dir).iterdir() if p.is_dir()) if Path(results_dir).is_dir() else ():
        kind = study_kind(folder)
        if kind not in STUDIES:
            raise DataError(f"{folder}: not a study folder (known: {', '.join(STUDIES)})")
        combine, figures_of = STUDIES[kind]
        try:
            results[folder.name] = combine(folder)
        except FileNotFoundError as exc:  # a committed table deleted: name it, not only its path
            gone = exc.filename or str(exc)
            raise DataError(f"{folder}: {gone} is gone; restore it from git (git checkout -- {gone})") from None
        figures |= figures_of(results[folder.name], folder.name)
    return figures, results


def study_kind(folder: Path) -> str:
    """The study a results folder holds: ``confirm`` where it has a plan (``plan.yaml``), ``picks`` where it has a
    table of pick attempts (``attempts.parquet``), else its name's first word (``attribution-real-objects``:
    ``attribution``), or ``external`` where that names no study and it holds one table of predictions of a
    confirmatory study's networks on an external test set (``test.parquet``, ``predictions-d<draw>.parquet``)."""
    from graspaug.experiments.confirm.tables import PLAN

    if (Path(folder) / PLAN).is_file():
        return "confirm"
    if (Path(folder) / "attempts.parquet").is_file():
        return "picks"
    named = Path(folder).name.split("-")[0]
    if named not in STUDIES and (Path(folder) / "test.parquet").is_file() and any(Path(folder).glob("predictions-d*")):
        return "external"
    return named


def history_problems(results_dir: Path) -> list[str]:
    """What git says is wrong with the results folders whose history matters: a confirmatory study's plan committed
    after its data, edited, or a draw dropped (:func:`~graspaug.experiments.confirm.tables.check_plan_history`)."""
    from graspaug.experiments.confirm.tables import check_plan_history

    folders = sorted(p for p in Path(results_dir).iterdir() if p.is_dir()) if Path(results_dir).is_dir() else []
    return [p for folder in folders if study_kind(folder) == "confirm" for p in check_plan_history(folder)]


def marked_figures(text: str) -> list[tuple[str, int]]:
    """The marked figures of a markdown ``text``: (key, offset of the figure's first character), in order."""
    return [(m.group(1), m.end()) for m in MARKER.finditer(text)]


def check_markdown(text: str, figures: Mapping[str, str], name: str = "markdown") -> list[str]:
    """One line per problem of a markdown ``text`` against the recomputed ``figures`` (key → text); empty when every
    marked figure is what the data say. Problems: no marked figure at all (:func:`marked_figures`); a marker that is
    not exactly ``<!-- results:KEY -->`` (a space after the colon, a missing one before ``-->``…); a key no study
    recomputes; a quoted figure that differs in any character from the recomputed one, or goes on after it (a
    digit, letter, ``%`` or ``[`` right after it: "49 of 620" quoted for "49 of 62")."""
    marked = marked_figures(text)
    problems = [] if marked else [f"{name}: no marked figure (a `<!-- results:KEY -->` before each quoted figure)"]
    problems += [
        f"{name}: malformed marker {m.group(0)!r} (write `<!-- results:KEY -->`, KEY of letters, digits, @./+-_)"
        for m in LOOSE.finditer(text)
        if not MARKER.fullmatch(m.group(0))
    ]
    for key, at in marked:
        if key not in figures:
            problems.append(f"{name}: {key}: no study in results/ recomputes it")
            continue
        want, end = figures[key], at + len(figures[key])
        if not text.startswith(want, at) or CONTINUES.match(text, end):
            quoted = text[at:end] + (CONTINUES.match(text, end).group(0) if CONTINUES.match(text, end) else "")
            problems.append(f"{name}: {key}: quoted {quoted!r}, recomputed {want!r}")
    return problems


def write_recomputed(results: Mapping[str, dict], figures: Mapping[str, str], out: Path) -> None:
    """Write each study's recomputed result into ``out``/<study>/: ``summary.json``, ``figures.json`` (its figures by
    key) and, for an attribution study, ``decomposition.md`` (its report); each file atomically."""
    from graspaug.experiments.ap.attribution import decomposition_markdown
    from graspaug.io.atomic import atomic_path

    for study, result in results.items():
        folder = Path(out) / study
        folder.mkdir(parents=True, exist_ok=True)
        own = {k: v for k, v in figures.items() if k.startswith(f"{study}/")}
        files = {"summary.json": json.dumps(result, indent=1), "figures.json": json.dumps(own, indent=1)}
        if study.split("-")[0] == "attribution":
            command = f"graspaug results (results/{study})"
            files["decomposition.md"] = decomposition_markdown(result, result["augment_base_sizes"], command)
        for name, text in files.items():
            with atomic_path(folder / name) as tmp:
                tmp.write_text(text + ("" if text.endswith("\n") else "\n"))


def write_lifelong(folder: Path, rounds: Mapping[int, Mapping], labels, object_ids, meta: dict) -> None:
    """Write the lifelong study's tables into ``folder``: ``predictions.parquet`` (one float32 column per round, draw,
    training seed and arm, ``r<k>/<draw>/<seed>/<arm>``), ``test.parquet`` (``label``, ``object``) and ``meta.json``
    (``meta``: ``command``, ``commit``, ``date``, ``n_resamples``, ``seed``; written last).

    Parameters
    ----------
    rounds : round → :func:`~graspaug.experiments.lifelong.numbers.arm_contrasts`'s ``networks`` of that round
        (draw → seed → arm → network folder)
    labels, object_ids : (N,) — the test datapoints' labels and objects, in the predictions' order
    """
    from graspaug.experiments.lifelong.numbers import network_predictions
    from graspaug.io.atomic import atomic_path

    columns = {
        f"r{k}/{d}/{s}/{arm}": network_predictions(network).astype(np.float32)
        for k, networks in rounds.items()
        for d, by_seed in networks.items()
        for s, by_arm in by_seed.items()
        for arm, network in by_arm.items()
    }
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "meta.json").unlink(missing_ok=True)  # a folder without meta.json is an unfinished one
    test = pd.DataFrame({"label": np.asarray(labels, dtype=np.int8), "object": np.asarray(object_ids)})
    for name, frame in {"predictions.parquet": pd.DataFrame(columns), "test.parquet": test}.items():
        with atomic_path(folder / name) as tmp:
            frame.to_parquet(tmp, index=False)
    with atomic_path(folder / "meta.json") as tmp:
        tmp.write_text(json.dumps(dict(meta), indent=1) + "\n")


def combine_lifelong(folder: Path) -> dict:
    """Round → :func:`~graspaug.experiments.lifelong.numbers.arm_contrasts` of the tables :func:`write_lifelong` wrote
    in ``folder``, with the resamples and seed of its ``meta.json``: the study's ``summary.json``, figure for figure."""
    from graspaug.experiments.lifelong.numbers import arm_contrasts

    missing = [name for name in ("predictions.parquet", "test.parquet", "meta.json") if not (folder / name).is_file()]
    if missing:
        raise DataError(f"{folder}: no {', '.join(missing)} (an unfinished or foreign results folder)")
    meta = json.loads((folder / "meta.json").read_text())
    predictions, test = pd.read_parquet(folder / "predictions.parquet"), pd.read_parquet(folder / "test.parquet")
    rounds: dict = {}
    for name in predictions.columns:
        k, d, s, arm = name.split("/")
        by_arm = rounds.setdefault(int(k[1:]), {}).setdefault(int(d), {}).setdefault(int(s), {})
        by_arm[arm] = predictions[name].to_numpy()
    labels, objects = test.label.to_numpy(), test.object.to_numpy()
    return {
        k: arm_contrasts(networks, labels, objects, meta["n_resamples"], meta["seed"])
        for k, networks in sorted(rounds.items())
    }


def lifelong_figures(result: dict, study: str = "lifelong") -> dict[str, str]:
    """Every figure of a lifelong result (:func:`combine_lifelong`) by key: ``<study>/r<k>/<contrast>``,
    ``<study>/r<k>/ap/<arm>`` (``mean [low, high]``, AP) and ``<study>/r<k>/share`` (its interval by test inversion,
    or ``[unbounded]``)."""
    out = {}
    for k, r in result.items():
        out |= {f"{study}/r{k}/ap/{arm}": interval_text(c, ".4f") for arm, c in r["ap"].items()}
        out |= {f"{study}/r{k}/{name}": interval_text(c) for name, c in r["contrasts"].items()}
        if "share" in r:
            out[f"{study}/r{k}/share"] = share_text(r["share"])
    return out


def write_fidelity(folder: Path, ae: str, per_shape: pd.DataFrame, meta: dict) -> None:
    """Add (or replace) AutoEncoder ``ae``'s rows of a held-out fidelity run (``per_shape``: the study's per-shape
    table) in ``folder``'s ``per_shape.parquet``, and its ``meta`` (``command``, ``commit``, ``date``, where the
    project was) under ``meta.json``'s ``runs``; ``meta.json`` is written last."""
    from graspaug.io.atomic import atomic_path

    folder.mkdir(parents=True, exist_ok=True)
    table, meta_file = folder / "per_shape.parquet", folder / "meta.json"
    runs = json.loads(meta_file.read_text())["runs"] if meta_file.is_file() else {}
    meta_file.unlink(missing_ok=True)  # a folder without meta.json is an unfinished one
    old = pd.read_parquet(table) if table.is_file() else pd.DataFrame({"ae": []})
    rows = per_shape.assign(ae=ae)
    new = pd.concat([old[old.ae != ae], rows], ignore_index=True) if len(old) else rows
    with atomic_path(table) as tmp:
        new.to_parquet(tmp, index=False)
    with atomic_path(meta_file) as tmp:
        tmp.write_text(json.dumps({"runs": runs | {ae: dict(meta)}}, indent=1) + "\n")


def combine_fidelity(folder: Path) -> dict:
    """AutoEncoder → :func:`~graspaug.experiments.fidelity.numbers.heldout_summary` of its held-out shapes, from the
    ``per_shape.parquet`` of ``folder`` (one row per AutoEncoder and shape, its ``ae`` column naming the
    AutoEncoder; ``graspaug study heldout-fidelity``'s ``per_shape.csv`` of each, stacked) and its ``meta.json``."""
    from graspaug.experiments.fidelity.numbers import heldout_summary

    missing = [name for name in ("per_shape.parquet", "meta.json") if not (folder / name).is_file()]
    if missing:
        raise DataError(f"{folder}: no {', '.join(missing)} (an unfinished or foreign results folder)")
    per_shape = pd.read_parquet(folder / "per_shape.parquet")
    return {ae: heldout_summary(rows) for ae, rows in per_shape.groupby("ae", sort=True)}


def fidelity_figures(result: dict, study: str = "fidelity") -> dict[str, str]:
    """Every figure of a held-out fidelity result (:func:`combine_fidelity`) by key: ``<study>/<ae>/graspness_kept``
    and ``<study>/<ae>/datapoints_kept`` (``kept [low, high]`` in %, Fieller 95%; ``[unbounded]`` without ends) and
    ``<study>/<ae>/meshed`` (``meshed of shapes``)."""

    def kept(value, low, high) -> str:
        ends = "[unbounded]" if low is None or high is None else f"[{low:.1%}, {high:.1%}]"
        return f"{value:.1%} {ends}"

    out = {}
    for ae, r in result.items():
        out[f"{study}/{ae}/graspness_kept"] = kept(r["kept"], r["kept_low"], r["kept_high"])
        out[f"{study}/{ae}/datapoints_kept"] = kept(
            r["datapoints_kept"], r["datapoints_kept_low"], r["datapoints_kept_high"]
        )
        out[f"{study}/{ae}/meshed"] = f"{r['meshed']} of {r['shapes']}"
    return out


PRECISION_FILES = ("networks.parquet", "ae_iou.parquet", "recon.parquet")


def write_precision(folder: Path, tables: Mapping[str, pd.DataFrame], meta: dict) -> None:
    """``tables`` (``networks``, ``ae_iou``, ``recon``: the precision study's) as parquet files in ``folder``, then
    ``meta`` (``command``, ``commit``, ``date``, the projects) as ``meta.json``, last."""
    from graspaug.io.atomic import atomic_path

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "meta.json").unlink(missing_ok=True)  # a folder without meta.json is an unfinished one
    for name in PRECISION_FILES:
        with atomic_path(folder / name) as tmp:
            tables[name.removesuffix(".parquet")].to_parquet(tmp, index=False)
    with atomic_path(folder / "meta.json") as tmp:
        tmp.write_text(json.dumps(meta, indent=1) + "\n")


def combine_precision(folder: Path) -> dict:
    """:func:`graspaug.experiments.precision.summarize` of a ``results/precision-<label>/`` folder."""
    from graspaug.experiments.precision import summarize

    missing = [name for name in (*PRECISION_FILES, "meta.json") if not (folder / name).is_file()]
    if missing:
        raise DataError(f"{folder}: no {', '.join(missing)} (an unfinished or foreign results folder)")
    return summarize(*(pd.read_parquet(folder / name) for name in PRECISION_FILES))


def precision_figures(result: dict, study: str = "precision") -> dict[str, str]:
    """Every figure of a precision comparison by key: ``<study>/gqcnn/<network or pooled>`` (bfloat16 − float32 of
    validation AP, t over seeds), ``<study>/gqcnn/rule`` and ``<study>/ae/rule`` (keep or reject),
    ``<study>/ae/<ae>/<float32, bfloat16 or difference>`` (held-out IoU) and ``<study>/recon/<figure>/<precision>``."""
    out = {f"{study}/gqcnn/{name}": interval_text(c) for name, c in result["gqcnn"].items()}
    for ae, r in result["ae"].items():
        for key in ("float32", "bfloat16", "difference"):
            out[f"{study}/ae/{ae}/{key}"] = interval_text(r[key], "+.4f" if key == "difference" else ".4f")
    out |= {f"{study}/recon/{key}": interval_text(c, ".3f") for key, c in result["recon"].items()}
    out[f"{study}/gqcnn/rule"] = "keep" if result["gqcnn_keeps_bfloat16"] else "reject"
    out[f"{study}/ae/rule"] = "keep" if result["ae_keeps_bfloat16"] else "reject"
    return out


def _confirm():
    from graspaug.experiments.confirm.tables import combine_confirm
    from graspaug.experiments.confirm.words import confirm_figures

    return combine_confirm, confirm_figures


def combine_picks(folder: Path) -> dict:
    """The robot picks' summary (:func:`~graspaug.experiments.cell.picks.pick_summary`) of ``attempts.parquet``,
    with the bootstrap settings its ``meta.json`` names."""
    from graspaug.experiments.cell.picks import feasible_summary, pick_summary

    attempts = pd.read_parquet(folder / "attempts.parquet")
    meta = json.loads((folder / "meta.json").read_text())
    arms, n, seed = list(dict.fromkeys(attempts.arm)), meta.get("n_bootstrap", 2000), meta.get("seed", 0)
    return pick_summary(attempts, arms, n, seed) | {"feasible": feasible_summary(attempts, n, seed)}


def picks_figures(result: dict, study: str) -> dict[str, str]:
    """``<study>/<arm>`` (success rate, ``mean [low, high]``), ``<study>/<contrast>`` and its ``/verdict``; the
    networks' ranking as ``<study>/ranking/<arm>`` (ROC AUC), ``<study>/ranking/<contrast>`` and its ``/verdict``."""

    def text(c, sign=""):
        return "n/a" if c["low"] is None else f"{c['mean']:{sign}.3f} [{c['low']:{sign}.3f}, {c['high']:{sign}.3f}]"

    out = {f"{study}/{arm}": text(c) for arm, c in result["arms"].items()}
    for name, c in result["contrasts"].items():
        out[f"{study}/{name}"] = text(c, "+")
        out[f"{study}/{name}/verdict"] = c["verdict"]
        if c.get("per_draw"):
            out[f"{study}/{name}/per_draw"] = ", ".join(f"{v:+.3f}" for v in c["per_draw"])
    d = result.get("draws") or []
    out[f"{study}/draws"] = f"{len(d)} draw{'s' if len(d) != 1 else ''} ({', '.join(str(x) for x in d)})"
    feasible = result.get("feasible") or {}
    if feasible:  # a table with the feasibility rule: the count, the oracle's verdict on the cell, each arm's share
        n, picked = feasible["object_draws"], feasible["all_object_draws"]
        out[f"{study}/feasible/object_draws"] = f"{n} feasible object-draws" + (f" of {picked}" if picked > n else "")
        if "oracle_fit" in feasible:
            fit = "fit to compare planners" if feasible["oracle_fit"] else "not fit to compare planners"
            out[f"{study}/feasible/oracle_fit"] = fit
        out |= {f"{study}/feasible/span/{a}": f"{v:.2f}" for a, v in feasible.get("span_share", {}).items()}
    ranking = result.get("ranking") or {}
    out |= {f"{study}/ranking/{arm}": text(c) for arm, c in ranking.get("arms", {}).items()}
    for name, c in ranking.get("contrasts", {}).items():
        out[f"{study}/ranking/{name}"] = text(c, "+")
        out[f"{study}/ranking/{name}/verdict"] = c["verdict"]
        if c.get("per_draw"):
            out[f"{study}/ranking/{name}/per_draw"] = ", ".join(f"{v:+.3f}" for v in c["per_draw"])
    return out


def _external():
    from graspaug.experiments.confirm.external import combine_external, external_figures

    return combine_external, external_figures


STUDIES = {
    "picks": (combine_picks, picks_figures),
    "external": (lambda folder: _external()[0](folder), lambda result, study: _external()[1](result, study)),
    "confirm": (lambda folder: _confirm()[0](folder), lambda result, study: _confirm()[1](result, study)),
    "attribution": (combine_attribution, attribution_figures),
    "lifelong": (combine_lifelong, lifelong_figures),
    "fidelity": (combine_fidelity, fidelity_figures),
    "precision": (combine_precision, precision_figures),
}
"""Study name → (read and combine its ``results/<study>/`` folder, its figures by key)."""
