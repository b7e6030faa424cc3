"""The lifelong loop over several draws of the data (issue #36): run the ``lifelong`` profile's rounds once per data
seed and give every round's arms and contrasts one interval over draws, training seeds and test objects.

Each draw k is a clone of this repository's HEAD in ``--workdir``/draw<k> with params.yaml written from the profile
plus ``data_seed: k``. By default it runs ``dvc repro lifelong@r<K>`` there (the whole pipeline up to the last round,
sharing this repository's DVC cache). With ``--reuse DIR`` the stages before the loop are not run again: their
outputs are linked from DIR/draw<k> (an attribution study's draws: the same profile's data, the same data seed) and
the rounds run as ``graspaug lifelong-start`` and ``graspaug lifelong --round r<k>``, the commands the DVC stages
run. A finished round is not run again. Then :func:`~graspaug.experiments.lifelong.numbers.arm_contrasts` combines
the draws per round and ``summary.json``, ``lifelong.md``, ``followed.csv``, ``curve.png`` (test AP) and ``gain.png``
(the gain over round 0) are written into ``--workdir``, and every network's test predictions with the command and
commit into this repository's ``results/<--results>/`` (``graspaug results`` recomputes every figure from them).

    python studies/lifelong.py [--draws 0 1 2] [--workdir ../lifelong] [--profile lifelong] [--reuse ../attribution]
        [--resamples 2000] [--combine-only] [--results lifelong]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.lifelong.figures import curve_series
from graspaug.experiments.lifelong.numbers import ARMS, arm_contrasts, arm_variant, curve_rows, round_networks
from graspaug.experiments.results import write_lifelong
from graspaug.experiments.stats import interval_text, share_text
from graspaug.io.tables import read_table
from graspaug.pipeline.params.profiles import merge, params_yaml, read_overlay
from graspaug.plots import lines

ROOT = Path(__file__).resolve().parents[1]
REUSED = (  # the loop's inputs, made by the stages before it
    "data/shapes.parquet",
    "data/latents.parquet",
    "data/scores.parquet",
    "data/voxels.npz",
    "models/ae_critic.pt",
    "data/gqcnn/original",
    "models/gqcnn",
)


def draw_params(profile: str, data_seed: int):
    from graspaug.pipeline.params.model import params_dict, parse_params

    return parse_params(merge(params_dict(), read_overlay(profile, ROOT / "profiles") | {"data_seed": data_seed}))


def run_draw(folder: Path, params, profile: str, reuse: Path | None) -> None:
    """Clone HEAD into ``folder`` (once), write params.yaml and run the rounds (module docstring)."""
    if not folder.exists():
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(folder)], check=True)
    header = f"graspaug params, profile `{profile}` with data_seed {params.data_seed}: written by studies/lifelong.py"
    (folder / "params.yaml").write_text(params_yaml(params, header))
    rounds = params.lifelong.round_numbers()
    env = {
        **os.environ,
        "DVC_NO_ANALYTICS": "1",
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
    }
    if reuse is None:
        cache = subprocess.run(
            [sys.executable, "-m", "dvc", "cache", "dir"], cwd=ROOT, check=True, capture_output=True, text=True
        ).stdout.strip()
        subprocess.run([sys.executable, "-m", "dvc", "cache", "dir", "--local", cache], cwd=folder, check=True)
        subprocess.run(
            [sys.executable, "-m", "dvc", "repro", f"lifelong@r{max(rounds)}"], cwd=folder, env=env, check=True
        )
        return
    for path in REUSED:
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        if not (folder / path).exists():
            os.symlink((reuse / path).resolve(), folder / path)
    for k in [0, *rounds]:
        if not (folder / f"data/lifelong/r{k}").exists():
            command = ["graspaug", "lifelong-start"] if k == 0 else ["graspaug", "lifelong", "--round", f"r{k}"]
            subprocess.run(command, cwd=folder, env=env, check=True)


def combine(folders: dict[int, Path], params, n_resamples: int, results: Path, meta: dict) -> dict:
    """Every round's arms and contrasts over the draws (``folders``: data seed → draw folder); the networks' test
    predictions, with ``meta`` (command, commit, date), go to ``results`` (``results/lifelong/``: `graspaug results`
    recomputes every figure from them)."""
    cfg, seeds = params.lifelong, params.gqcnn.seeds
    first = next(iter(folders.values()))
    index = read_table(first / "data/gqcnn/original/index.parquet")
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--draws", type=int, nargs="+", default=[0, 1, 2], help="data seeds, one loop each")
    parser.add_argument("--workdir", type=Path, default=ROOT.parent / "lifelong")
    parser.add_argument("--profile", default="lifelong")
    parser.add_argument("--reuse", type=Path, default=None, help="a study's workdir whose draws hold the inputs")
    parser.add_argument("--resamples", type=int, default=2000)
    parser.add_argument("--combine-only", action="store_true", help="combine finished draws, run nothing")
    parser.add_argument("--results", default="lifelong", help="results/<this>/: the networks' test predictions")
    args = parser.parse_args()
    start = time.perf_counter()
    params = {k: draw_params(args.profile, k) for k in args.draws}
    folders = {k: args.workdir.resolve() / f"draw{k}" for k in args.draws}
    for k in args.draws:
        if not args.combine_only:
            reuse = args.reuse.resolve() / f"draw{k}" if args.reuse else None
            run_draw(folders[k], params[k], args.profile, reuse)
        print(f"draw {k}: done ({time.perf_counter() - start:.0f} s)", flush=True)
    p = params[args.draws[0]]
    command = "python studies/lifelong.py " + " ".join(sys.argv[1:])
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    meta = {"command": command, "commit": commit, "date": time.strftime("%Y-%m-%d"), "draws": args.draws}
    result = combine(folders, p, args.resamples, ROOT / "results" / args.results, meta)
    (args.workdir / "summary.json").write_text(json.dumps({str(k): r for k, r in result.items()}, indent=1) + "\n")
    follow = followed(folders, p.lifelong.round_numbers())
    follow.to_csv(args.workdir / "followed.csv", index=False)
    (args.workdir / "lifelong.md").write_text(markdown(result, p, command, time.perf_counter() - start, follow))
    curve = pd.concat([curve_rows(k, r) for k, r in result.items()])
    design = f"{len(args.draws)} draws × {len(p.gqcnn.seeds)} seeds × test objects, 95% intervals"
    for figure, label, name in (("ap", "test AP", "curve.png"), ("gain", "test AP − round 0's", "gain.png")):
        rounds, series, bands = curve_series(curve, ARMS, figure)
        what = "Test AP per round" if figure == "ap" else "Gain over round 0, paired"
        lines(rounds, series, args.workdir / name, "round", label, f"{what} ({design})", bands)
    print((args.workdir / "lifelong.md").read_text())


if __name__ == "__main__":
    main()
