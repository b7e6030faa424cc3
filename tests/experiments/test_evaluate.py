"""`graspaug evaluate MODEL… --corpus DIR` on a folder of real-size trimesh primitives with two seeded GQ-CNNs: every
model's test AP with an interval over objects, the paired difference, the cached test set, bad input refused."""

from __future__ import annotations

import ast
import json
import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
import torch
import trimesh
from sklearn.metrics import average_precision_score
from typer.testing import CliRunner

from graspaug.experiments.evaluate.numbers import test_ap as ap_of_models
from graspaug.experiments.evaluate.words import printed_lines
from graspaug.experiments.stats import ObjectBootstrap, nested_t_interval, verdict
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.io.checkpoints import finish_gqcnn_card, gqcnn_card, save_gqcnn
from graspaug.nets.gqcnn import GQCNN, GQCNNConfig
from graspaug.pipeline.cli import app
from graspaug.pipeline.params.profiles import profile_yaml
from graspaug.render.settings import CropGeometry, Intrinsics, ViewpointRanges

REPO = Path(__file__).resolve().parents[2]
#: The real corpus beside the project (../shared from the main checkout, ../../shared from a worktree under wt/).
GSO300 = next(
    (p for p in (REPO.parent / "shared/corpora/gso300", REPO.parents[1] / "shared/corpora/gso300") if p.is_dir()),
    REPO / "absent",
)

#: The 78 YCB meshes (STL, metres) beside the project, where they are.
YCB78 = next(
    (p for p in (REPO.parent / "shared/external/ycb78", REPO.parents[1] / "shared/external/ycb78") if p.is_dir()),
    REPO / "absent",
)


def test_ap_and_paired_differences_over_objects():
    rng = np.random.default_rng(0)
    objects = np.repeat([f"o{i}" for i in range(12)], 20)
    labels = rng.random(len(objects)) < 0.3
    noisy = labels + rng.normal(0, 0.8, len(labels))
    out = ap_of_models(labels, objects, {"noisy": noisy, "same": noisy.copy(), "perfect": labels * 1.0}, 300, 0)
    assert out["objects"] == 12 and out["datapoints"] == 240
    assert out["models"]["noisy"]["mean"] == pytest.approx(average_precision_score(labels, noisy))
    assert out["models"]["perfect"]["mean"] == 1.0
    low, high = out["models"]["noisy"]["objects_low"], out["models"]["noisy"]["objects_high"]
    assert low < out["models"]["noisy"]["mean"] < high
    same = out["differences"]["same − noisy"]  # paired over the same resamples: exactly nothing
    assert same["mean"] == 0 and same["objects_low"] == 0 and same["objects_high"] == 0
    better = out["differences"]["perfect − noisy"]
    assert better["objects_low"] > 0 and better["over"] == "objects"


def test_models_as_seeds_of_networks_give_each_networks_mean_with_the_verdict_interval():
    rng = np.random.default_rng(1)
    objects = np.repeat([f"o{i}" for i in range(15)], 30)
    labels = rng.random(len(objects)) < 0.3
    weak = {f"weak{s}": labels + rng.normal(0, 1.2, len(labels)) for s in range(3)}
    strong = {f"strong{s}": labels + rng.normal(0, 0.6, len(labels)) for s in range(3)}
    out = ap_of_models(labels, objects, weak | strong, 300, 0, seeds=3)
    boot = ObjectBootstrap(objects, 300, 0)  # the resamples test_ap draws
    full = np.array([[average_precision_score(labels, p) for p in group.values()] for group in (weak, strong)])
    resampled = np.stack([[boot.average_precision(labels, p) for p in group.values()] for group in (weak, strong)])
    first, second = out["networks"]["weak0 (3 seeds)"], out["networks"]["strong0 (3 seeds)"]
    expected = nested_t_interval(full[:1], resampled[:1])
    assert first["mean"] == pytest.approx(full[0].mean()) and first["over"] == "draws" and first["n_seeds"] == 3
    assert (first["draws_low"], first["draws_high"]) == pytest.approx((expected["low"], expected["high"]))
    assert second["draws_low"] < second["mean"] < second["draws_high"]
    gain = out["network_differences"]["strong0 (3 seeds) − weak0 (3 seeds)"]  # seed k paired with seed k
    paired = nested_t_interval(full[1:] - full[:1], resampled[1:] - resampled[:1])
    assert gain["mean"] == pytest.approx(full[1].mean() - full[0].mean())
    assert (gain["draws_low"], gain["draws_high"]) == pytest.approx((paired["low"], paired["high"]))
    assert gain["draws_low"] > 0  # less noise ranks better on every seed
    assert verdict(gain) == "a gain in this draw of the data"  # seeds of one draw
    over_draws = ap_of_models(labels, objects, weak | strong, 300, 0, seeds=3, replicates="draws")
    across = over_draws["network_differences"]["strong0 (3 draws) − weak0 (3 draws)"]  # networks of 3 draws
    assert (across["draws_low"], across["draws_high"], across["n_draws"]) == pytest.approx(
        (paired["low"], paired["high"], 3)
    )
    assert verdict(across) == "a gain over 3 draws of the data"
    printed = printed_lines(over_draws, "report.md")  # what evaluate prints: a method verdict, over the 3 draws
    assert any(line.endswith("(a gain over 3 draws of the data)") for line in printed), printed
    assert "networks" not in ap_of_models(labels, objects, weak, 300, 0)
    with pytest.raises(ValueError, match="not networks of 2 seeds"):
        ap_of_models(labels, objects, weak, 300, 0, seeds=2)


def _model(path: Path, seed: int, pool: str = "targeted", rules: dict | None = None) -> Path:
    """A seeded, untrained GQ-CNN with the model card train_gqcnn writes (label threshold 0.0005, the tiny one; with
    ``rules``, the test-set rules its data were made by)."""
    torch.manual_seed(seed)
    card = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.0005, 0)
    card |= {} if rules is None else {"test_set_rules": rules}
    summary = {
        "pool": pool,
        "base_size": 4,
        "ratio": 0.0,
        "seed": seed,
        "train": {},
        "validation": {},
        "test": {},
    }
    save_gqcnn(path, GQCNN(GQCNNConfig(image_input="depth")), summary, finish_gqcnn_card(card, summary))
    return path


@pytest.fixture(scope="module")
def project(tmp_path_factory, repo_root):
    """A folder with the tiny params, two models and a corpus of real-size objects (metres), one too wide to grasp."""
    root = tmp_path_factory.mktemp("evaluate")
    (root / "params.yaml").write_text(profile_yaml("tiny", repo_root / "profiles"))
    corpus = root / "objects"
    corpus.mkdir()
    shapes = {
        "box.stl": trimesh.creation.box(extents=[0.05, 0.03, 0.08]),
        "can.obj": trimesh.creation.cylinder(radius=0.02, height=0.09),
        "bar.stl": trimesh.creation.capsule(radius=0.012, height=0.08),
        "block.stl": trimesh.creation.box(extents=[0.04, 0.04, 0.04]),
        "crate.stl": trimesh.creation.box(extents=[0.2, 0.15, 0.12]),  # wider than the Panda's 8 cm opening
    }
    for name, mesh in shapes.items():
        mesh.export(corpus / name)
    models = [_model(root / f"m{seed}.pt", seed) for seed in (0, 1)]
    return root, corpus, models


def _evaluate(root: Path, *args: str, params: str | None = "params.yaml"):
    cwd = os.getcwd()
    os.chdir(root)
    try:
        return CliRunner().invoke(app, ["evaluate", *args, *([] if params is None else ["--params", params])])
    finally:
        os.chdir(cwd)


def test_evaluate_prints_each_models_ap_and_the_paired_difference(project):
    root, corpus, models = project
    result = _evaluate(root, str(models[0]), str(models[1]), "--corpus", str(corpus), "--resamples", "200")
    assert result.exit_code == 0, result.output
    assert f"{models[0]}: test AP" in result.output and f"{models[1]} − {models[0]}:" in result.output
    report = json.loads((root / "reports/evaluate/evaluate.json").read_text())
    assert report["counts"]["files"] == 5 and report["counts"]["shapes"] == 4 and report["counts"]["rejected"] == 1
    assert 1 <= report["objects"] <= 4 and report["datapoints"] > 0
    first = report["models"][str(models[0])]
    assert first["over"] == "objects" and (first["mean"] is None or 0 <= first["mean"] <= 1)
    rejects = (root / "reports/evaluate/rejects.csv").read_text()
    assert "crate.stl" in rejects and "too large for the gripper" in rejects
    report_md = (root / "reports/evaluate/report.md").read_text()
    assert "Test AP on" in report_md and "Test set shaped by: params params.yaml (sha256" in report_md
    assert "label: robust ε > 0.0005; size rule `real` (max width 0.08 m" in report_md
    shaped_by = report["shaped_by"]
    assert shaped_by["params"] == "params.yaml" and shaped_by["label_threshold"] == 0.0005
    assert shaped_by["size"] == "real" and shaped_by["fitted"] == 0 and shaped_by["fit_scale"] is None

    cached = [p for p in (root / ".graspaug-cache/evaluate").iterdir() if p.is_dir()]
    assert len(cached) == 1
    made = cached[0].stat().st_mtime
    start = time.perf_counter()
    again = _evaluate(root, str(models[1]), "--corpus", str(corpus), "--resamples", "200")
    assert again.exit_code == 0, again.output
    assert time.perf_counter() - start < 20  # the cached test set: only the predictions
    assert [p for p in (root / ".graspaug-cache/evaluate").iterdir() if p.is_dir()] == cached
    assert cached[0].stat().st_mtime == made
    second = json.loads((root / "reports/evaluate/evaluate.json").read_text())["models"][str(models[1])]
    assert second == report["models"][str(models[1])]  # the same test set, the same resamples

    seeds = _evaluate(
        root, str(models[0]), str(models[1]), "--corpus", str(corpus), "--resamples", "200", "--seeds", "2"
    )
    assert seeds.exit_code == 0, seeds.output
    assert "none@4 (2 seeds): mean test AP" in seeds.output  # the arm named by its cards' training set
    as_networks = json.loads((root / "reports/evaluate/evaluate.json").read_text())
    assert as_networks["networks"]["none@4 (2 seeds)"]["n_seeds"] == 2
    assert as_networks["network_differences"] == {}
    report_md = (root / "reports/evaluate/report.md").read_text()
    assert "arms of 2 replicates each (`--seeds 2`; their cards say they are training seeds of one draw" in report_md


def test_a_single_network_difference_is_no_method_verdict_and_seeds_must_be_replicates(project):
    root, corpus, models = project
    single = _evaluate(root, str(models[0]), str(models[1]), "--corpus", str(corpus), "--resamples", "100")
    assert single.exit_code == 0, single.output
    assert "training seeds not covered: not evidence about the method" in single.output
    report_md = (root / "reports/evaluate/report.md").read_text()
    assert "not evidence about the method" in report_md and "a gain in this draw" not in report_md
    other = _model(root / "random.pt", 2, pool="random")
    mixed = _evaluate(root, str(models[0]), str(other), "--corpus", str(corpus), "--seeds", "2")
    assert mixed.exit_code == 2 and len(mixed.output.strip().splitlines()) == 1
    assert "is not a replicate of" in mixed.output and "card's pool is 'random', not 'targeted'" in mixed.output


def test_the_models_cards_make_their_test_set_unless_params_says_otherwise(project, repo_root):
    import dataclasses

    from graspaug.pipeline.params.profiles import profile_params
    from graspaug.training.networks import test_set_rules

    root, corpus, _ = project
    tiny = profile_params("tiny", repo_root / "profiles")
    ingest = dataclasses.replace(tiny.ingest, surface=dataclasses.replace(tiny.ingest.surface, size="fit"))
    rules = test_set_rules(ingest, tiny.grasps, tiny.render)
    fitted = [_model(root / f"fit{s}.pt", s, rules=rules) for s in (0, 1)]
    made = _evaluate(root, *map(str, fitted), "--corpus", str(corpus), "--resamples", "100", params=None)
    assert made.exit_code == 0, made.output
    shaped = json.loads((root / "reports/evaluate/evaluate.json").read_text())["shaped_by"]
    assert shaped["size"] == "fit" and shaped["rules"].startswith("the models' cards")
    assert "Test set shaped by: params the models' cards" in (root / "reports/evaluate/report.md").read_text()
    overridden = _evaluate(root, *map(str, fitted), "--corpus", str(corpus), "--resamples", "100")
    assert overridden.exit_code == 0, overridden.output
    shaped = json.loads((root / "reports/evaluate/evaluate.json").read_text())["shaped_by"]
    assert shaped["size"] == "real" and shaped["rules"] == "--params params.yaml"


def test_bad_folders_and_models_are_refused_in_one_line(project, tmp_path):
    root, corpus, models = project
    missing = _evaluate(root, str(models[0]), "--corpus", str(tmp_path / "nowhere"))
    assert missing.exit_code == 2 and "no such folder" in missing.output and len(missing.output.splitlines()) == 1
    (tmp_path / "notes.txt").write_text("no meshes here")
    empty = _evaluate(root, str(models[0]), "--corpus", str(tmp_path))
    assert empty.exit_code == 2 and "no mesh files" in empty.output
    (tmp_path / "broken.pt").write_text("not a checkpoint")
    broken = _evaluate(root, str(models[0]), str(tmp_path / "broken.pt"), "--corpus", str(corpus))
    assert broken.exit_code == 2 and "broken.pt" in broken.output and len(broken.output.splitlines()) == 1
    (tmp_path / "noise.pt").write_bytes(np.random.default_rng(0).bytes(3000))  # torch's advice was weights_only
    (tmp_path / "truncated.pt").write_bytes(models[0].read_bytes()[:5000])
    torch.save({"config": object.__new__(GQCNNConfig)}, tmp_path / "objects.pt")  # a save holding more than tensors
    for name, says in (("noise.pt", "not the zip archive"), ("truncated.pt", "not the zip archive"),
                       ("objects.pt", "objects other than tensors")):  # fmt: skip
        corrupt = _evaluate(root, str(tmp_path / name), "--corpus", str(corpus))
        line = corrupt.output.strip()
        assert corrupt.exit_code == 2 and f"model {tmp_path / name}: not a checkpoint (" in line and says in line, line
        assert "weights_only" not in line and "\n" not in line, line
    uneven = _evaluate(root, *map(str, models), str(root / "m2.pt"), "--corpus", str(corpus), "--seeds", "2")
    assert uneven.exit_code == 2 and "--seeds 2: 3 models are not arms of 2 replicates" in uneven.output


@pytest.mark.skipif(not GSO300.is_dir(), reason="the gso300 corpus is not on this machine")
def test_gso300_objects_keep_their_real_size(tmp_path):
    from graspaug.augment.corpus import ingest_source
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.io.sources import folder_sources

    rows = [
        ingest_source(s, 10**6, 100.0, SurfaceSettings(size="real"), tmp_path) for s in folder_sources(GSO300, 1.0, 3)
    ]
    for row in rows:
        if row["ok"]:
            assert (
                abs(row["scale"] - 1.0) < 1e-12 and 0.01 <= max(row["extent_x"], row["extent_y"], row["extent_z"]) < 1
            )


def test_the_test_set_keeps_real_size_or_fits_as_the_projects_ingest_does():
    """evaluate's objects keep their real size (too wide: rejected), or, where the project's ingest fits objects to
    the gripper (the real-objects profile), are fitted as ingest fits them; the card's gripper sets the width."""
    import dataclasses

    from graspaug.experiments.evaluate.testset import CARD_KEYS, recipe_for
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.grasping.settings import GraspsSettings
    from graspaug.planning.card import ModelCard
    from graspaug.render.settings import RenderSettings

    raw = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(max_width=0.07), 0.0005, 0)
    card = ModelCard.from_dict(raw, "depth")
    values = {k: getattr(card, k) for k in CARD_KEYS}
    for asked, used in (("normalize", "real"), ("real", "real"), ("fit", "fit")):
        surface = dataclasses.replace(SurfaceSettings(), size=asked)
        recipe = recipe_for(surface, 10**6, 100.0, GraspsSettings(), RenderSettings(), 0, values)
        assert recipe.surface.size == used and recipe.surface.max_width == pytest.approx(0.07)


def test_evaluate_never_deletes_a_users_file_nor_writes_over_its_inputs(project, tmp_path):
    """The issue's cases: `--out mine --force` deleted mine/notes.txt; `--out . --force` emptied the working folder;
    `--cache o/cache --out o` deleted the cache. Every refusal comes before any work, in one line."""
    root, corpus, models = project
    mine = root / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("my notes")
    refused = _evaluate(root, str(models[0]), "--corpus", str(corpus), "--out", "mine", "--resamples", "100")
    assert refused.exit_code == 2 and "holds notes.txt, which graspaug evaluate did not write" in refused.output
    forced = _evaluate(root, str(models[0]), "--corpus", str(corpus), "--out", "mine", "--force", "--resamples", "100")
    assert forced.exit_code == 0, forced.output
    assert (mine / "notes.txt").read_text() == "my notes" and (mine / "report.md").is_file()
    here = root / "here"
    here.mkdir()
    (here / "data.csv").write_text("mine")
    dot = _evaluate(here, str(models[0]), "--corpus", str(corpus), "--out", ".", "--force", params="../params.yaml")
    assert dot.exit_code == 2 and "output folder . is the working folder" in dot.output
    assert os.listdir(here) == ["data.csv"]
    cache = _evaluate(root, str(models[0]), "--corpus", str(corpus), "--cache", "o/cache", "--out", "o")
    assert cache.exit_code == 2 and "holds the input o/cache" in cache.output and not (root / "o").exists()
    shutil.copy(models[0], tmp_path / "m.pt")
    model = _evaluate(root, str(tmp_path / "m.pt"), "--corpus", str(corpus), "--out", str(tmp_path), "--force")
    assert model.exit_code == 2 and "holds the input" in model.output and "m.pt" in model.output
    inside = _evaluate(root, str(models[0]), "--corpus", str(corpus), "--out", str(corpus / "report"))
    assert inside.exit_code == 2 and "lies inside the input" in inside.output and not (corpus / "report").exists()


def test_one_object_twice_from_inside_its_folder_the_same_objects_ap_and_no_interval(project, tmp_path):
    """The issue's cases: run from inside the mesh folder, the default cache lies in the corpus and the second run
    read its cached meshes as objects (2 → 4); one object printed a "95% interval" [x, x]; a non-UTF-8 file name
    aborted the run; and the test set followed the params.yaml of the folder the command ran from."""
    _, _, models = project
    objects = tmp_path / "objects"
    objects.mkdir()
    trimesh.creation.box(extents=[0.05, 0.03, 0.08]).export(objects / "box.stl")
    with open(os.path.join(os.fsencode(objects), b"caf\xe9.stl"), "w") as f:  # a name that is not UTF-8
        f.write("not a mesh")
    (objects / "params.yaml").write_text("seed: 0\ngrasps:\n  threshold: 0.5\n")  # not read: no --params
    outputs = []
    for run in range(2):
        result = _evaluate(objects, str(models[0]), "--corpus", ".", "--out", str(tmp_path / f"r{run}"), params=None)
        assert result.exit_code == 0, result.output
        assert "test AP" in result.output and "(one object: no interval)" in result.output
        outputs.append(json.loads((tmp_path / f"r{run}/evaluate.json").read_text()))
    assert outputs[0]["counts"] == outputs[1]["counts"] and outputs[0]["counts"]["files"] == 2
    assert outputs[0]["models"] == outputs[1]["models"] and outputs[0]["objects"] == 1
    assert outputs[0]["models"][str(models[0])]["objects_low"] is None
    assert outputs[0]["shaped_by"]["params"] == "built-in defaults" and outputs[0]["shaped_by"]["label_threshold"] > 0
    assert (objects / ".graspaug-cache/evaluate/CACHEDIR.TAG").is_file()
    rejects = (tmp_path / "r0/rejects.csv").read_text()
    assert "folder:caf\\xe9.stl" in rejects
    assert "one object: no interval" in (tmp_path / "r1/report.md").read_text()


def test_the_test_set_key_holds_the_code_that_makes_it(tmp_path, monkeypatch):
    """A change to the sampler, the renderer or prepare.FIT_SHARE reused old cached test sets: the key now holds a
    digest of every source file of BUILDERS, which covers build_test_set's whole import closure."""
    from graspaug.experiments.evaluate.testset import BUILDERS, code_fingerprint, fingerprint
    from tests.test_dvc_deps import REPO, SRC, _is_inert, import_closure

    closure = import_closure("graspaug.experiments.evaluate.testset", SRC)
    covered = {m.replace(".", "/") for m in BUILDERS}
    missing = [f for f in closure if not any(f.removeprefix("src/").startswith(c) for c in covered)]
    code = [f for f in missing if not (f.endswith("__init__.py") and _is_inert(ast.parse((REPO / f).read_text())))]
    assert code == [], code  # a package's __init__.py that holds only its docstring makes nothing
    package = tmp_path / "somepkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "sampler.py").write_text("N = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    before = code_fingerprint(("somepkg",))
    assert code_fingerprint(("somepkg",)) == before and code_fingerprint(("somepkg.sampler",)) != before
    (package / "sampler.py").write_text("N = 2\n")
    assert code_fingerprint(("somepkg",)) != before
    assert code_fingerprint() == code_fingerprint() and len(code_fingerprint()) == 64
    recipe_and_files = ([], _recipe())
    assert fingerprint(*recipe_and_files, code="a") != fingerprint(*recipe_and_files, code="b")


def _recipe():
    from graspaug.experiments.evaluate.testset import CARD_KEYS, recipe_for
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.grasping.settings import GraspsSettings
    from graspaug.planning.card import ModelCard
    from graspaug.render.settings import RenderSettings

    card = ModelCard.from_dict(
        gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.0005, 0), "depth"
    )
    values = {k: getattr(card, k) for k in CARD_KEYS}
    return recipe_for(SurfaceSettings(), 10**6, 100.0, GraspsSettings(), RenderSettings(), 0, values)


def test_the_report_says_how_many_objects_were_fitted_and_by_what_scale():
    from graspaug.experiments.evaluate.words import shaped_by_text

    made = {
        "params": "params.yaml",
        "params_sha256": "ab" * 32,
        "recipe": "0123456789abcdef",
        "label_threshold": 0.002,
        "size": "fit",
        "max_width": 0.08,
        "unit_scale": 0.001,
        "fitted": 3,
        "fit_scale": [0.52, 0.91],
    }
    text = shaped_by_text(made, {"shapes": 12})
    assert "params params.yaml (sha256 abababababab), recipe 0123456789abcdef; label: robust ε > 0.002" in text
    assert "size rule `fit` (max width 0.08 m, unit scale 0.001 m per file unit); 3 of 12 objects fitted" in text
    assert text.endswith("scaled by 0.52–0.91.")


def test_two_evaluates_into_one_out_take_turns_and_both_finish(project):
    """Two `graspaug evaluate` at once into one --out: the second waits for the first (each staging folder is its
    own until it is moved in), and both end with their report written, not a half-removed folder."""
    import subprocess
    import sys

    root, corpus, models = project
    cmd = [sys.executable, "-m", "graspaug.pipeline.cli", "evaluate", "--corpus", str(corpus), "--out", "both"]
    runs = [
        subprocess.Popen([*cmd, str(m), "--params", "params.yaml"], cwd=root, stderr=subprocess.PIPE, text=True)
        for m in models
    ]
    outcomes = [(r.wait(timeout=600), r.stderr.read()) for r in runs]
    assert [code for code, _ in outcomes] == [0, 0], outcomes
    assert (root / "both/report.md").is_file() and not list(root.glob(".both.tmp-*"))


def test_the_confirmatory_networks_make_their_test_set_by_their_cards(repo_root, tmp_path):
    """The kept networks of the confirmatory study, with no --params: the test set is made as their training data
    were (size `fit`, 5 views per pose, from their cards), and evaluate.json says so."""
    import shutil

    corpus = repo_root.parent / "shared" / "corpora" / "gso100"
    kept = repo_root / "results/real-objects-confirm/networks/d10-s0"
    if not corpus.is_dir() or not kept.is_dir():
        pytest.skip("gso100 beside this clone and the confirmatory study's draw 10 are needed")
    objects = tmp_path / "objects"
    objects.mkdir()
    shutil.copy(corpus / "AllergenFree_JarroDophilus.obj", objects)
    models = [str(kept / name / "model.pt") for name in ("targeted-50-0", "targeted-50-1")]
    out = tmp_path / "out"
    done = _evaluate(tmp_path, *models, "--corpus", str(objects), "--out", str(out), "--cache", str(tmp_path / "c"),
                     params=None)  # fmt: skip
    assert done.exit_code == 0, done.output
    shaped = json.loads((out / "evaluate.json").read_text())["shaped_by"]
    assert shaped["size"] == "fit" and shaped["rules"].startswith("the models' cards")
    assert "not evidence about the method" in done.output  # two single networks: no method verdict

    nets = repo_root / "results/real-objects-confirm/networks"  # none@50 of draws 10-12, then targeted@50 of them
    none = [str(nets / f"d{d}-s0/targeted-50-0/model.pt") for d in (10, 11, 12)]
    targeted = [str(nets / f"d{d}-s0/targeted-50-1/model.pt") for d in (10, 11, 12)]
    figures = []
    for arm in (targeted, targeted[::-1]):  # the second arm's draws in order, then reversed
        again = _evaluate(tmp_path, *none, *arm, "--corpus", str(objects), "--out", str(out), "--cache",
                          str(tmp_path / "c"), "--seeds", "3", "--force", params=None)  # fmt: skip
        assert again.exit_code == 0, again.output
        report = json.loads((out / "evaluate.json").read_text())
        figures.append({k: report[k] for k in ("differences", "networks", "network_differences")})
    assert figures[0] == figures[1]  # replicate k paired with replicate k: the same draw, the same seed
    assert list(figures[0]["networks"]) == ["none@50 (3 draws)", "targeted@50 (3 draws)"]
    assert list(figures[0]["differences"]) == [f"targeted@50 − none@50 (d{d} s0)" for d in (10, 11, 12)]
    report_md = (out / "report.md").read_text()
    assert "/model.pt (3" not in report_md and "training seeds not covered" not in report_md
    odd = [*none, *targeted[:2], str(nets / "d13-s0/targeted-50-1/model.pt")]
    odd = _evaluate(tmp_path, *odd, "--corpus", str(objects), "--out", str(out), "--cache", str(tmp_path / "c"),
                    "--seeds", "3", params=None)  # fmt: skip
    assert odd.exit_code == 2 and len(odd.output.strip().splitlines()) == 1, odd.output
    assert "d13-s0/targeted-50-1/model.pt (data_seed 13, training seed 0) has no partner" in odd.output


def test_arms_are_paired_by_the_cards_draw_and_seed_and_named_by_their_training_set(repo_root):
    """The kept confirmatory networks' cards: the second arm's draws in any order are paired with the first's by
    draw and training seed, so test_ap gives the same figures; arms are named none@50, targeted@50, random@50,
    none@150; what cannot be paired is refused naming the field and the files."""
    from graspaug.errors import DataError
    from graspaug.experiments.evaluate.testset import arrange_arms, replicate_name

    nets = repo_root / "results/real-objects-confirm/networks"
    if not nets.is_dir():
        pytest.skip("the confirmatory study's kept networks are needed")
    card = {
        f"d{d}/{v}": json.loads((nets / f"d{d}-s0/{v}/card.json").read_text())
        for d in (10, 11, 12)
        for v in ("targeted-50-0", "targeted-50-1", "random-50-1", "targeted-150-0")
    }
    rng = np.random.default_rng(3)
    objects = np.repeat([f"o{i}" for i in range(10)], 30)
    labels = rng.random(len(objects)) < 0.3
    noise = {name: rng.normal(0, 1 + i / 10, len(labels)) for i, name in enumerate(card)}

    def figures(names: list[str]) -> dict:
        order, kind, arms = arrange_arms({n: card[n] for n in names}, 3)
        assert kind == "draws"
        pairs = [replicate_name(card[n]) for n in order[:3]]
        probabilities = {n: labels + noise[n] for n in order}
        return ap_of_models(labels, objects, probabilities, 200, 0, 3, kind, arms, pairs)

    arms = ("targeted-50-0", "targeted-50-1", "random-50-1", "targeted-150-0")
    given = [f"d{d}/{v}" for v in arms for d in (10, 11, 12)]
    mixed = [f"d{d}/{v}" for v in arms for d in ((10, 11, 12) if v == "targeted-50-0" else (12, 10, 11))]
    in_order, shuffled = figures(given), figures(mixed)
    assert in_order == shuffled
    assert list(in_order["networks"]) == [f"{a} (3 draws)" for a in ("none@50", "targeted@50", "random@50", "none@150")]
    assert "targeted@50 − none@50 (d11 s0)" in in_order["differences"]
    within = in_order["differences"]["targeted@50 − none@50 (d11 s0)"]["mean"]
    assert within == pytest.approx(
        in_order["models"]["d11/targeted-50-1"]["mean"] - in_order["models"]["d11/targeted-50-0"]["mean"]
    )
    with pytest.raises(DataError, match=r"d13/targeted-50-1 \(data_seed 13, training seed 0\) has no partner"):
        card["d13/targeted-50-1"] = json.loads((nets / "d13-s0/targeted-50-1/card.json").read_text())
        arrange_arms(
            {n: card[n] for n in ["d10/targeted-50-0", "d11/targeted-50-0", "d11/targeted-50-1", "d13/targeted-50-1"]},
            2,
        )
    seedless = {"a": card["d10/targeted-50-0"], "b": {**card["d11/targeted-50-0"], "training_set": {}}}
    with pytest.raises(DataError, match="model b's card has no training_set.seed"):
        arrange_arms(seedless, 2)


def test_a_mean_aps_interval_stays_inside_aps_range():
    """Two seeds (t on 1 degree of freedom: a wide interval) of a near-perfect arm: the arm's mean-AP interval is
    clipped to [0, 1] and says so; a difference's to [-1, 1]; an interval inside the range is left as it is."""
    rng = np.random.default_rng(5)
    objects = np.repeat([f"o{i}" for i in range(12)], 25)
    labels = rng.random(len(objects)) < 0.3
    perfect = {"p0": labels * 1.0, "p1": labels + rng.normal(0, 0.8, len(labels))}
    weak = {"w0": rng.random(len(labels)), "w1": labels + rng.normal(0, 0.9, len(labels))}
    out = ap_of_models(labels, objects, perfect | weak, 200, 0, seeds=2, arms=["good@50", "bad@50"])
    good = out["networks"]["good@50 (2 seeds)"]
    assert good["clipped"] and good["draws_high"] == 1.0 and 0 <= good["draws_low"] < good["mean"] < 1
    raw = nested_t_interval(np.array([[out["models"][n]["mean"] for n in perfect]]),
                            np.stack([ObjectBootstrap(objects, 200, 0).average_precision(labels, p)
                                      for p in perfect.values()])[None])  # fmt: skip
    assert raw["high"] > 1 and good["draws_low"] == pytest.approx(max(raw["low"], 0))
    for c in [*out["networks"].values(), *out["network_differences"].values()]:
        assert 0 <= c["draws_low"] <= c["draws_high"] <= 1 or c in out["network_differences"].values()
        assert -1 <= c["draws_low"] <= c["draws_high"] <= 1
    assert any(line.endswith("(clipped to [0, 1])") for line in printed_lines(out, "report.md"))
    assert list(out["differences"]) == ["bad@50 − good@50 (replicate 1)", "bad@50 − good@50 (replicate 2)"]


def _tiny_test_set(corpus: Path, unit_scale: float, folder: Path, size: str = "real") -> dict:
    """The test set of the meshes in ``corpus`` (``unit_scale`` m per file unit) by the tiny profile's params and a
    tiny model's card, built into ``folder``: its counts."""
    import dataclasses

    from graspaug.experiments.evaluate.testset import CARD_KEYS, build_test_set, recipe_for
    from graspaug.io.sources import folder_sources
    from graspaug.pipeline.params.base import parse, parse_yaml
    from graspaug.pipeline.stages.evaluate import Params
    from graspaug.planning.card import ModelCard

    params = parse(parse_yaml(profile_yaml("tiny", REPO / "profiles")), Params)
    raw = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.0005, 0)
    card = ModelCard.from_dict(raw, "depth")
    i = params.ingest
    surface = dataclasses.replace(i.surface, size=size)
    values = {k: getattr(card, k) for k in CARD_KEYS}
    recipe = recipe_for(surface, i.max_faces, i.max_file_mb, params.grasps, params.render, params.seed, values)
    folder.mkdir()
    return build_test_set(folder_sources(corpus, unit_scale), recipe, folder, 1, 1000)


@pytest.mark.skipif(not YCB78.is_dir(), reason="the ycb78 meshes are not on this machine")
def test_ycb78_balls_get_datapoints(tmp_path):
    """The tennis ball, racquetball, golf ball and small marble rest in any orientation (no stable pose reaches
    Dex-Net's 0.01): they are rendered in drawn orientations, not skipped with '0 stable poses'."""
    corpus = tmp_path / "balls"
    corpus.mkdir()
    for name in ("056_tennis_ball", "057_racquetball", "058_golf_ball", "063-b_marbles"):
        shutil.copy(YCB78 / f"{name}.stl", corpus)
    counts = _tiny_test_set(corpus, 1.0, tmp_path / "set", size="fit")
    assert counts["shapes"] == 4 and counts["with_datapoints"] == 4, counts


@pytest.mark.skipif(not YCB78.is_dir(), reason="the ycb78 meshes are not on this machine")
def test_the_same_meshes_in_millimetres_give_the_same_test_set(tmp_path):
    """Ten ycb78 meshes (open scans among them) in metres, and copies of them in millimetres read with unit scale
    0.001: the same shapes, datapoints and positives (the files differ by float noise only)."""
    names = (
        "005_tomato_soup_can", "007_tuna_fish_can", "010_potted_meat_can", "011_banana", "012_strawberry",
        "013_apple", "014_lemon", "017_orange", "025_mug", "040_large_marker",
    )  # fmt: skip
    metres, millimetres = tmp_path / "m", tmp_path / "mm"
    metres.mkdir(), millimetres.mkdir()
    for name in names:
        shutil.copy(YCB78 / f"{name}.stl", metres)
        mesh = trimesh.load(YCB78 / f"{name}.stl", process=False)
        mesh.apply_scale(1000.0)
        mesh.export(millimetres / f"{name}.stl")
    in_m = _tiny_test_set(metres, 1.0, tmp_path / "set_m")
    in_mm = _tiny_test_set(millimetres, 0.001, tmp_path / "set_mm")
    assert in_m["datapoints"] > 100 and in_m["positives"] > 10, in_m
    for key in ("shapes", "rejected", "with_datapoints", "datapoints", "positives"):
        assert in_mm[key] == in_m[key], (key, in_m, in_mm)
