"""Why generated shapes add nothing, over several draws of the data (issue #33): run the
``attribution`` profile once per data seed and give every contrast one interval over draws,
training seeds and test objects.

Each draw k is a clone of this repository's HEAD in ``--workdir``/draw<k> that shares this
repository's DVC cache (so the stages no data seed reaches, ingest to ``render@original``, come
from the run cache), with params.yaml written from the profile plus ``data_seed: k`` and any
``--set key=value``; it runs ``dvc repro report`` (the GQ-CNN experiment, not the robot cell).
Then :func:`graspaug.experiments.ap.attribution.combine_draws` combines the draws' networks (a
hierarchical bootstrap over draws, seeds within draws and test objects) and writes
``summary.json`` and ``decomposition.md`` into ``--workdir``, and the per-network, per-test-datapoint tables with
the command and commit that made them into this repository's ``results/<--results>/`` (commit them: ``graspaug
results`` recomputes every quoted figure from them). A finished draw is not run again.

    python studies/attribution.py [--draws 0 1 2] [--workdir ../attribution] [--profile attribution]
        [--set 'gqcnn.augment_base_sizes=[50]'] [--resamples 2000] [--combine-only] [--results attribution]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import yaml

from graspaug.experiments.ap.attribution import combine_draws, decomposition_markdown
from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.results import write_attribution
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import params_dict, parse_params
from graspaug.pipeline.params.profiles import merge, params_yaml, read_overlay

ROOT = Path(__file__).resolve().parents[1]


def draw_params(profile: str, data_seed: int, changes: list[str]):
    """The validated params of ``profile`` with ``data_seed`` and ``changes`` (``key.path=yaml value``)."""
    overlay = read_overlay(profile, ROOT / "profiles") | {"data_seed": data_seed}
    for change in changes:
        key, _, value = change.partition("=")
        *path, last = key.split(".")
        node = overlay
        for part in path:
            node = node.setdefault(part, {})
        node[last] = yaml.safe_load(value)
    return parse_params(merge(params_dict(), overlay))


def run_draw(folder: Path, params, profile: str) -> None:
    """Clone HEAD into ``folder`` (once), share the DVC cache, write params.yaml, ``dvc repro report``."""
    if not folder.exists():
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(folder)], check=True)
    cache = subprocess.run(
        [sys.executable, "-m", "dvc", "cache", "dir"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout.strip()
    subprocess.run([sys.executable, "-m", "dvc", "cache", "dir", "--local", cache], cwd=folder, check=True)
    header = (
        f"graspaug params, profile `{profile}` with data_seed {params.data_seed}: written by studies/attribution.py"
    )
    (folder / "params.yaml").write_text(params_yaml(params, header))
    subprocess.run([sys.executable, "-m", "dvc", "repro", "report"], cwd=folder, check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--draws", type=int, nargs="+", default=[0, 1, 2], help="data seeds, one experiment each")
    parser.add_argument("--workdir", type=Path, default=ROOT.parent / "attribution")
    parser.add_argument("--profile", default="attribution")
    parser.add_argument("--set", dest="changes", action="append", default=[], help="key.path=value (YAML)")
    parser.add_argument("--resamples", type=int, default=2000)
    parser.add_argument("--combine-only", action="store_true", help="combine finished draws, run nothing")
    parser.add_argument(
        "--results", default="attribution", help="results/<this>/: the per-network tables (`graspaug results`)"
    )
    args = parser.parse_args()
    start = time.perf_counter()
    params = {k: draw_params(args.profile, k, args.changes) for k in args.draws}
    folders = {k: args.workdir.resolve() / f"draw{k}" for k in args.draws}
    for k in args.draws:
        if not args.combine_only:
            run_draw(folders[k], params[k], args.profile)
        print(f"draw {k}: done ({time.perf_counter() - start:.0f} s)", flush=True)
    p = params[args.draws[0]]
    draws = {k: {s: folders[k] / f"models/gqcnn/s{s}" for s in p.gqcnn.seeds} for k in args.draws}
    tests = [
        test_labels(read_table(f / "data/gqcnn/original/index.parquet"), draws[k][p.gqcnn.seeds[0]])
        for k, f in folders.items()
    ]
    labels, objects = tests[0]
    if any((t[0] != labels).any() or (t[1] != objects).any() for t in tests):
        raise SystemExit("the draws were tested on different datapoints: they must share seed and the test split")
    result = combine_draws(draws, labels, objects, p.generate, p.gqcnn, args.resamples, p.seed)
    command = "python studies/attribution.py " + " ".join(sys.argv[1:])
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
    meta = {"command": command, "commit": commit, "date": time.strftime("%Y-%m-%d"), "profile": args.profile}
    meta |= {"draws": args.draws, "n_resamples": args.resamples, "seed": p.seed}
    results = ROOT / "results" / args.results  # the per-network tables every quoted figure is recomputed from
    write_attribution(results, draws, labels, objects, p.generate, p.gqcnn, meta)
    text = decomposition_markdown(result, p.gqcnn.augment_base_sizes, command)
    (args.workdir / "summary.json").write_text(json.dumps(result, indent=1))
    (args.workdir / "decomposition.md").write_text(text)
    print(text)
    print(f"{time.perf_counter() - start:.0f} s; written to {args.workdir}/summary.json and decomposition.md")


if __name__ == "__main__":
    main()
