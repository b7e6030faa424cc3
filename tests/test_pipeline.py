"""Real ``dvc repro`` in a temporary copy of the repository, on the tiny profile (``profiles/tiny.yaml``)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from graspaug.io.checkpoints import read_gqcnn
from graspaug.io.voxels import read_voxels
from graspaug.nets.gqcnn import GQCNN, GQCNNEnsemble
from graspaug.training.gqcnn_data import with_split
from tests.clones import run, tiny_clone

pytestmark = pytest.mark.slow

SHAPES = "data/shapes.parquet"
GRASPAUG = [sys.executable, "-m", "graspaug.pipeline.cli"]  # the CLI of the package under test


@pytest.fixture(scope="module")
def tiny_repo(repo_root, tmp_path_factory):
    """A user's clone on the tiny profile, its stages built by the tests in file order; the cell's decompositions
    cached for this module alone (every stage and experiment of the clone shares them)."""
    work = tmp_path_factory.mktemp("repo")
    env = tiny_clone(repo_root, work, tmp_path_factory.mktemp("sim-cache"))
    return work, env


def test_dvc_repro_voxelize_then_nothing_to_do(tiny_repo):
    work, env = tiny_repo
    run(["dvc", "repro", "voxelize", "split"], work, env)

    shapes = pd.read_parquet(work / "data/shapes.parquet")
    assert len(shapes) == 20 and shapes.watertight.all()
    assert set(shapes.split) == {"train", "test"}
    vox = read_voxels(work / "data/voxels.npz")
    assert vox.occupancy.shape == (20, 16, 16, 16)
    assert list(vox.shape_id) == list(shapes.shape_id)
    assert np.all(vox.occupancy.any(axis=(1, 2, 3)))
    assert (work / "dvc.lock").exists()

    again = run(["dvc", "repro", "voxelize"], work, env)
    assert "didn't change, skipping" in again.stdout
    assert "Running stage" not in again.stdout
    status = run(["dvc", "status", "voxelize"], work, env)
    assert "up to date" in status.stdout


def test_dvc_repro_critic_eval_and_embed(tiny_repo):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "critic_eval", "embed"], work, env)
    for path in (
        "models/ae.pt",
        "models/ae_critic.pt",
        "reports/critic_eval/interpolations.png",
        "reports/critic_eval/outliers.png",
        "reports/embed/tsne.png",
        "metrics/train_ae/ae/metrics.json",
    ):
        assert (work / path).stat().st_size > 0, path
    result = json.loads((work / "reports/critic_eval/study.json").read_text())
    assert result["n_pairs"] == 3 and result["n_decoded_per_model"] == 18
    assert set(result["outlier_pct"]) == {"ae", "ae_extra", "ae_critic"}
    assert list(result["outlier_pct"]["ae"]) == ["0.00", "0.10", "0.20", "0.30", "0.40", "0.50"]
    assert result["contrast"]["critic_vs_control"]["0.50"]["over"] == "objects"  # the pairs, resampled
    assert result["critic_auc"] is None or 0 <= result["critic_auc"] <= 1
    headline = json.loads((work / "metrics/critic_eval.json").read_text())
    assert set(headline) == {"mean", "lo", "hi", "auc"}  # the study's headline; its tables are in the report
    assert (work / "models/ae_extra.pt").stat().st_size > 0
    summary = json.loads((work / "reports/train_ae/summary.json").read_text())
    assert (
        0 <= summary["ae_iou_test"] <= 1 and "ae_shapes_per_s" not in summary
    )  # results only: timings go to reports/timing
    assert json.loads((work / "metrics/train_ae.json").read_text())["iou_ae"] == summary["ae_iou_test"]
    assert json.loads((work / "reports/timing/train_ae.json").read_text())["ae_shapes_per_s"] > 0
    latents = pd.read_parquet(work / "data/latents.parquet")
    assert len(latents) == 20 and len(latents.z[0]) == 32  # the tiny profile's z_dim
    assert set(latents.split) == {"train", "test"}
    shown = run(["dvc", "metrics", "show", "--json"], work, env)
    assert "iou_critic" in shown.stdout


def test_dvc_repro_score(tiny_repo):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "score"], work, env)
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    grasps = pd.read_parquet(work / "data/grasps/original.parquet")
    assert set(grasps.shape_id) <= set(shapes.shape_id) and len(grasps) > 0
    assert grasps.groupby("shape_id").size().max() <= 8
    scores = pd.read_parquet(work / "data/scores.parquet")
    assert list(scores.columns[:5]) == ["shape_id", "split", "rarity", "graspness", "n_grasps"]
    assert list(scores.shape_id) == list(shapes.shape_id)
    assert scores.rarity.gt(0).all() and scores.graspness.between(0, 1).all()
    per_shape = grasps.groupby("shape_id").success.mean().reindex(scores.shape_id).fillna(0).to_numpy()
    np.testing.assert_allclose(scores.graspness, per_shape)
    for name in ("graspness_hist", "rarity_hist", "grasp_examples"):
        assert (work / f"reports/score/{name}.png").stat().st_size > 0
    hist = pd.read_csv(work / "reports/score/graspness_hist.csv")
    assert hist.shapes.sum() == (scores.split == "train").sum()
    summary = json.loads((work / "reports/score/summary.json").read_text())
    assert summary["n_train"] == (scores.split == "train").sum()
    assert json.loads((work / "metrics/score.json").read_text())["shapes"] == summary["n_train"]
    shown = run(["dvc", "metrics", "show", "--json"], work, env)
    assert "positive" in shown.stdout and "graspness" in shown.stdout


def nearest_train_shapes(work: Path, folder: Path, train: set, count: int) -> dict[str, set[str]]:
    """Each mesh of ``folder`` (closed and scaled as the corpus, encoded by the tiny run's AE) → its ``count`` nearest
    train shapes in latent space, computed here from the library's parts."""
    import torch

    from graspaug.io.checkpoints import load_autoencoder
    from graspaug.pipeline.params.model import load_params
    from graspaug.sim.objects import folder_meshes
    from graspaug.training.autoencoder import encode_meshes

    params = load_params(work / "params.yaml")
    meshes, _ = folder_meshes(folder, params.ingest.surface)
    ae, _, _ = load_autoencoder(work / "models/ae_critic.pt", params.ae.net)
    grid = params.voxelize
    z = encode_meshes(ae, [m for _, m in meshes], grid.resolution, grid.margin, torch.device("cpu"))
    latents = pd.read_parquet(work / "data/latents.parquet")
    latents = latents[latents.shape_id.isin(train)]
    pool = np.stack(latents.z.to_numpy())
    return {
        name: set(latents.shape_id.iloc[np.argsort(np.linalg.norm(pool - zi, axis=1))[:count]])
        for (name, _), zi in zip(meshes, z)
    }


def test_from_failures_generates_from_train_shapes_near_a_users_failure_meshes(tiny_repo, tmp_path):
    import trimesh

    work, env = tiny_repo
    run(["dvc", "repro", "score"], work, env)
    failures = tmp_path / "failures"
    failures.mkdir()
    trimesh.creation.box((0.02, 0.05, 0.08)).export(failures / "box.obj")
    trimesh.creation.capsule(height=0.06, radius=0.015).export(failures / "capsule.stl")
    (failures / "broken.obj").write_text("not a mesh\n")
    (failures / "empty.stl").write_bytes(b"")
    command = ["graspaug", "from-failures", str(failures), "--count", "3", "--per-failure", "2"]
    first = run([*command, "-o", str(tmp_path / "out")], work, env)
    assert "from-failures: skipping" in first.stderr and "sim: skipping" not in first.stderr, first.stderr
    index = pd.read_csv(tmp_path / "out/index.csv")
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    train = set(shapes.shape_id[shapes.split == "train"])
    # the failure objects are the anchors' seeds, never parents: every parent is a train shape
    assert len(index) == 3 and set(index.failure) <= {"box", "capsule"}
    assert set(index.parent_a) | set(index.parent_b) <= train and index.parent_a.nunique() <= 2 * 2
    assert all((tmp_path / "out/meshes" / f"{s}.obj").stat().st_size > 0 for s in index.shape_id)
    skipped = pd.read_csv(tmp_path / "out/skipped.csv")
    assert list(skipped.file) == ["broken.obj", "empty.stl"] and skipped.reason.all()
    assert list(pd.read_csv(tmp_path / "out/failures.csv").object) == ["box", "capsule"]
    # the user's meshes are the anchors' seeds: each anchor is among the 2 train shapes nearest a failure mesh
    anchors = nearest_train_shapes(work, failures, train, 2)
    assert set(index.parent_a) <= anchors["box"] | anchors["capsule"]
    run([*command, "-o", str(tmp_path / "again")], work, env)  # the same shapes for the same params
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "again/index.csv"), index)
    # per failure object: its shapes and rejected decodes, and why none; each reject names the failure it served
    table = pd.read_csv(tmp_path / "out/failures.csv").set_index("object")
    assert table.shapes.to_dict() == index.failure.value_counts().reindex(table.index, fill_value=0).to_dict()
    assert (table.why_none.isna() == (table.shapes > 0)).all() and (table.anchors <= 2).all()
    rejects = pd.read_csv(tmp_path / "out/rejects.csv")
    assert "failure" in rejects and set(rejects.failure) <= {"box", "capsule"}
    # nothing a user has is lost: a folder of theirs, and the input folder itself, are refused with one line
    mine = tmp_path / "myproject"
    mine.mkdir()
    (mine / "notes.txt").write_text("my notes")
    for out in (mine, failures / "out"):  # a folder of the user's; one inside the input (tests/io: the rest)
        refused = subprocess.run([*command, "-o", str(out)], cwd=work, env=env, capture_output=True, text=True)
        assert refused.returncode == 2 and refused.stderr.strip().count("\n") == 0, refused.stderr
        assert str(out) in refused.stderr
    assert (mine / "notes.txt").read_text() == "my notes" and len(list(mine.iterdir())) == 1
    assert sorted(p.name for p in failures.iterdir()) == ["box.obj", "broken.obj", "capsule.stl", "empty.stl"]
    # a rerun into its own folder refuses a file the user added there since, and keeps it (and the last answer)
    (tmp_path / "out/my_analysis.txt").write_text("x")
    rerun = subprocess.run([*command, "-o", str(tmp_path / "out")], cwd=work, env=env, capture_output=True, text=True)
    assert rerun.returncode == 2 and "my_analysis.txt" in rerun.stderr.strip().splitlines()[-1], rerun.stderr
    assert (tmp_path / "out/my_analysis.txt").read_text() == "x"
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "out/index.csv"), index)
    # a symlinked -o is refused before any work: no mesh of the folder was read (no skipping warning)
    (tmp_path / "link").symlink_to(tmp_path / "again")
    linked = subprocess.run([*command, "-o", str(tmp_path / "link")], cwd=work, env=env, capture_output=True, text=True)
    assert linked.returncode == 2 and "is a symbolic link" in linked.stderr and "skipping" not in linked.stderr
    missing = subprocess.run(
        [*command[:2], str(tmp_path / "nowhere")], cwd=work, env=env, capture_output=True, text=True
    )
    assert missing.returncode == 2 and "the failure folder" in missing.stderr and "nowhere" in missing.stderr


def summary_rejects(work, base_size: int, pool: str) -> int:
    rejects = pd.read_parquet(work / f"data/generated/{base_size}/rejects.parquet")
    return int((rejects.pool == pool).sum())


def test_dvc_repro_generate_and_its_grasps(tiny_repo):
    import json

    import trimesh

    from graspaug.augment.candidates import draw_base_sets
    from graspaug.training.gqcnn_data import load_split

    work, env = tiny_repo
    run(["dvc", "repro", "grasps_generated"], work, env)
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    # shapes are generated for gqcnn.augment_base_sizes (6) only; base set 4 (its 1:0 network) is drawn, not augmented
    assert not (work / "data/generated/4").exists()
    drawn = draw_base_sets(shapes, (4, 6), seed=0)
    base = {6: pd.read_parquet(work / "data/generated/6/base.parquet")}
    assert set(drawn[6]) == set(base[6].shape_id)  # generate draws the base sets the experiment trains on
    assert set(drawn[4]) < set(base[6].shape_id) <= set(shapes.shape_id[shapes.split == "train"])
    for b in (6,):
        index = pd.read_parquet(work / f"data/generated/{b}/index.parquet")
        for pool in ("targeted", "random", "recon", "blend"):  # the tiny profile asks for every pool
            part = index[index.pool == pool]
            assert list(part.order) == list(range(b))  # max ratio 1 -> B shapes, in order
        mixed = index[index.pool != "recon"]  # blend: the targeted pairs with no network
        assert set(mixed.parent_a) | set(mixed.parent_b) <= set(base[b].shape_id)
        # recon: the real pool's shapes in the experiment's order, each decoded alone (a failed decode is skipped)
        recon = index[index.pool == "recon"]
        real_pool = load_split(work / "data/gqcnn/original", shapes, [4, 6], 2, 0).real_pool
        assert (recon.parent_a == recon.parent_b).all() and (recon.alpha == 0).all()
        assert list(recon.parent_a) == [s for s in real_pool if s in set(recon.parent_a)]
        assert real_pool.index(recon.parent_a.iloc[-1]) < b + summary_rejects(work, b, "recon")
        pairs = index.apply(lambda r: (r.pool, frozenset((r.parent_a, r.parent_b)), r.alpha), axis=1)
        assert pairs.is_unique  # no shape generated twice
        assert index.alpha.between(0, 0.5).all() and index.watertight.all()
        assert set(index.selected_by) <= {"rarity", "graspness", "random", "recon"}
        for shape_id in index.shape_id[:3]:
            mesh = trimesh.load(work / f"data/generated/{b}/meshes/{shape_id}.obj", force="mesh")
            assert mesh.is_watertight
        summary = json.loads((work / f"reports/generate/{b}/summary.json").read_text())
        pools = ("targeted", "random", "recon", "blend")
        assert [summary[p]["kept"] for p in pools] == [b] * 4
        assert json.loads((work / f"metrics/generate/{b}.json").read_text())["shapes"] == 4 * b
        rejects = pd.read_parquet(work / f"data/generated/{b}/rejects.parquet")
        assert sum(summary[p]["tried"] for p in pools) == 4 * b + len(rejects)
        blend, targeted = (index[index.pool == p] for p in ("blend", "targeted"))
        shared = set(zip(blend.parent_a, blend.parent_b, blend.alpha)) & set(
            zip(targeted.parent_a, targeted.parent_b, targeted.alpha)
        )
        assert len(shared) >= b - summary_rejects(work, b, "blend")  # the targeted pairs and weights
        assert sum(summary["rejects"].values()) == len(rejects)
        grasps = pd.read_parquet(work / f"data/grasps/gen_{b}.parquet")
        assert set(grasps.shape_id) <= set(index.shape_id)
        assert (work / f"reports/generate/{b}/pairs.png").stat().st_size > 0
    again = run(["dvc", "repro", "grasps_generated"], work, env)
    assert "Running stage" not in again.stdout
    # determinism: regenerating gives the same table and the same mesh files
    before = pd.read_parquet(work / "data/generated/6/index.parquet")
    mesh_bytes = (work / f"data/generated/6/meshes/{before.shape_id[0]}.obj").read_bytes()
    run(["dvc", "repro", "-f", "-s", "generate@6"], work, env)
    pd.testing.assert_frame_equal(pd.read_parquet(work / "data/generated/6/index.parquet"), before)
    assert (work / f"data/generated/6/meshes/{before.shape_id[0]}.obj").read_bytes() == mesh_bytes


def test_dvc_repro_render(tiny_repo):
    import json

    from graspaug.io.gqcnn import GraspImages

    work, env = tiny_repo
    run(["dvc", "repro", "render", "render_generated"], work, env)
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    assert not (work / "data/gqcnn/gen_4").exists()
    for corpus in ("original", "gen_6"):
        data = GraspImages.open(work / f"data/gqcnn/{corpus}")
        summary = json.loads((work / f"reports/render/{corpus}/summary.json").read_text())
        assert len(data) == summary["n_datapoints"] > 0
        assert json.loads((work / f"metrics/render/{corpus}.json").read_text())["datapoints"] == len(data)
        assert data.images().shape == (len(data), 32, 32)
        index = data.index
        if corpus == "original":
            assert set(index.shape_id) <= set(shapes.shape_id) and index.split.isna().all()  # the split stage's
            assert set(with_split(index, shapes).split) == {"train", "test"}
        else:
            generated = pd.read_parquet(work / f"data/generated/{corpus[4:]}/index.parquet")
            assert set(index.shape_id) <= set(generated.shape_id) and (index.base_size == int(corpus[4:])).all()
            assert (
                set(index.pool) <= {"targeted", "random", "recon", "blend"}
                and index.order.notna().all()
                and (index.split == "train").all()
            )
        assert (work / f"reports/render/{corpus}/examples.png").stat().st_size > 0
    again = run(["dvc", "repro", "render", "render_generated"], work, env)
    assert "Running stage" not in again.stdout


def test_a_second_clone_takes_every_stage_no_data_seed_reaches_from_the_run_cache(tiny_repo, tmp_path):
    """A study's second draw (a clone of the same commit sharing the DVC cache) runs nothing before `generate`: DVC
    keeps no run cache for a stage with an uncached plain output, so every stage's outs are cached (metrics and
    plots may stay uncached)."""
    work, env = tiny_repo
    run(["dvc", "repro", "render@original", "score"], work, env)
    clone = tmp_path / "draw1"
    run(["git", "clone", "-q", str(work), str(clone)], tmp_path, env)
    run(["dvc", "cache", "dir", "--local", str(work / ".dvc" / "cache")], clone, env)
    again = run(["dvc", "repro", "render@original", "score"], clone, env).stdout
    assert "Running stage" not in again, again
    for stage in ("ingest", "split", "voxelize", "train_ae", "embed", "grasps@original", "score", "render@original"):
        assert f"Stage '{stage}' is cached - skipping run" in again, stage
    assert (clone / "reports/train_ae/summary.json").is_file() and (clone / "metrics/score.json").is_file()
    # an independent draw (its own split) shares every per-object stage and redraws the split alone before them
    params = yaml.safe_load((clone / "params.yaml").read_text()) | {"data_seed": 1, "independent_draws": True}
    (clone / "params.yaml").write_text(yaml.safe_dump(params, sort_keys=False))
    redrawn = run(["dvc", "repro", "render@original", "split"], clone, env).stdout
    assert "Running stage 'split'" in redrawn, redrawn
    for stage in ("ingest", "voxelize", "grasps@original", "render@original"):
        assert f"Running stage '{stage}'" not in redrawn, stage
    before = pd.read_parquet(work / "data/shapes.parquet")
    assert (pd.read_parquet(clone / "data/shapes.parquet").split != before.split).any()


def test_dvc_repro_fidelity(tiny_repo):
    import json

    from graspaug.experiments.fidelity.numbers import HEADLINE

    work, env = tiny_repo
    run(["dvc", "repro", "fidelity"], work, env)
    pools = yaml.safe_load((work / "params.yaml").read_text())["gqcnn"]["pools"]
    files = {p.stem: json.loads(p.read_text()) for p in (work / "metrics/fidelity/6").glob("*.json")}
    no_parent = {f"{p}_{f}" for p in ("real", "primitives") for f in ("graspness_kept", "datapoints_kept")}
    assert set(files) == {f"{p}_{f}" for p in pools for f in HEADLINE} - no_parent
    assert 0 < files["recon_datapoints_kept"]["mean"] and 0 < files["targeted_graspness_kept"]["mean"]
    for pool in pools:
        one_nna = files[f"{pool}_one_nna"]
        assert 0 <= one_nna["lo"] <= one_nna["mean"] <= one_nna["hi"] <= 1, pool
        assert files[f"{pool}_datapoints_per_shape"]["mean"] > 0, pool
    table = pd.read_csv(work / "reports/fidelity/6/fidelity.csv").set_index("pool")
    assert table.loc["real", "shapes"] == 6 and table.loc["blend", "distinct_parents"] >= 2 and (table.mmd > 0).all()
    assert "| recon | " in (work / "reports/fidelity/6/fidelity.md").read_text()
    assert not (work / "metrics/fidelity/4").exists()  # only the augmented base sizes
    again = run(["dvc", "repro", "fidelity"], work, env)
    assert "Running stage" not in again.stdout


def test_heldout_fidelity_study_labels_the_originals_as_the_stages_do(tiny_repo, tmp_path):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "embed", "render@original"], work, env)
    out = tmp_path / "heldout"
    cmd = [*GRASPAUG, "study", "heldout-fidelity", "--project", str(work), "--shapes", "3", "--workers", "1"]
    run([*cmd, "--out", str(out)], work, env)
    per_shape = pd.read_csv(out / "per_shape.csv").set_index("shape_id")
    summary = json.loads((out / "summary.json").read_text())
    shapes = pd.read_parquet(work / "data/shapes.parquet").set_index("shape_id")
    assert len(per_shape) == summary["shapes"] == 3 and (shapes.loc[per_shape.index, "split"] == "test").all()
    assert 0 < summary["meshed"] == per_shape.meshed.sum() <= 3
    # the originals' datapoints and positives are the render stage's own, shape by shape
    index = pd.read_parquet(work / "data/gqcnn/original/index.parquet")
    stage = index[index.shape_id.isin(per_shape.index)].groupby("shape_id").label.agg(["size", "sum"])
    stage = stage.reindex(per_shape.index, fill_value=0)
    assert per_shape.datapoints_before.tolist() == stage["size"].tolist()
    assert per_shape.positives_before.tolist() == stage["sum"].tolist()
    grasps = pd.read_parquet(work / "data/grasps/original.parquet")
    expected = grasps[grasps.shape_id.isin(per_shape.index)].groupby("shape_id").success.mean()
    assert np.allclose(per_shape.graspness_before, expected.reindex(per_shape.index, fill_value=0))
    meshed = per_shape[per_shape.meshed]
    assert np.isclose(summary["graspness_before"], meshed.graspness_before.mean())


def test_precision_study_of_a_run_against_itself_keeps_bfloat16_and_is_recomputed_from_results(tiny_repo, tmp_path):
    """`graspaug study precision` on one finished tiny run as both arms: every paired difference is zero, both rules
    keep, the AutoEncoder's held-out IoU is the train_ae stage's own, and `graspaug results` recomputes the same
    figures from the tables it kept in results/."""
    import json

    from graspaug.experiments.stats import interval_text

    work, env = tiny_repo
    run(["dvc", "repro", "report"], work, env)
    out = tmp_path / "precision"
    cmd = [*GRASPAUG, "study", "precision", "--float32", str(work), "--bfloat16", str(work), "--out", str(out)]
    run([*cmd, "--results", "precision-tiny"], tmp_path, env)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["gqcnn_keeps_bfloat16"] and summary["ae_keeps_bfloat16"]
    assert all(c["mean"] == 0 for c in summary["gqcnn"].values()) and "pooled" in summary["gqcnn"]
    stage = json.loads((work / "reports/train_ae/summary.json").read_text())
    assert summary["ae"]["ae"]["float32"]["mean"] == pytest.approx(stage["ae_iou_test"], abs=1e-5)
    assert summary["ae"]["ae_critic"]["difference"]["mean"] == 0
    networks = pd.read_csv(out / "networks.csv")
    for seed in (0, 1):  # one row per arm and trained network
        assert (networks.seed == seed).sum() == 2 * len(list((work / f"models/gqcnn/s{seed}").rglob("model.pt")))
    run([*GRASPAUG, "results", "--root", str(tmp_path), "--out", "recomputed"], tmp_path, env)
    recomputed = json.loads((tmp_path / "recomputed/precision-tiny/figures.json").read_text())
    assert recomputed["precision-tiny/gqcnn/pooled"] == interval_text(summary["gqcnn"]["pooled"])
    assert recomputed["precision-tiny/gqcnn/rule"] == recomputed["precision-tiny/ae/rule"] == "keep"


def test_dvc_repro_gqcnn_matrix_and_report(tiny_repo):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "report"], work, env)
    names = (
        ["targeted/4-0"]
        + [f"{p}/6-{r:g}" for p in ("targeted", "random", "real", "recon", "blend") for r in (0.5, 1.0)]
        + ["targeted/6-0", "ceiling"]
    )
    digests, validation = {}, {}
    for seed in (0, 1):
        assert set(json.loads((work / f"metrics/gqcnn/s{seed}.json").read_text())) == {"test_ap", "val_ap"}
        metrics = json.loads((work / f"reports/gqcnn/networks/s{seed}.json").read_text())["networks"]
        assert set(metrics) == {"targeted", "random", "real", "recon", "blend", "ceiling"} and set(
            metrics["targeted"]["6"]
        ) == {
            "0",
            "0.5",
            "1",
        }
        assert set(metrics["targeted"]["4"]) == {"0"} and set(metrics["real"]["6"]) == {"0.5", "1"}
        split = json.loads((work / f"models/gqcnn/s{seed}/split.json").read_text())
        for name in names:
            folder = work / f"models/gqcnn/s{seed}/{name}"
            summary = json.loads((folder / "summary.json").read_text())
            assert set(summary["test"]) == {"ap", "accuracy", "roc_auc", "positive_share", "datapoints"}
            # the tiny profile's networks are ensembles of 2 members, each with its own kept step
            assert 4 <= summary["train"]["steps"] <= 6 and summary["train"]["members"] == 2
            assert len(summary["train"]["best_step"]) == 2 and all(
                1 <= b <= summary["train"]["steps"] for b in summary["train"]["best_step"]
            )
            test_p, members_p = (
                np.load(folder / "test_predictions.npy"),
                np.load(folder / "test_predictions_members.npy"),
            )
            assert test_p.shape == (summary["test"]["datapoints"],) and members_p.shape == (2, len(test_p))
            assert np.allclose(test_p, members_p.mean(axis=0)) and not np.allclose(members_p[0], members_p[1])
            assert sorted(pd.read_csv(folder / "history.csv").member) == [0, 0, 1, 1]  # evals: 2 per member
            digests.setdefault(seed, set()).add(summary["init_digest"])
            net, card = read_gqcnn(folder / "model.pt")  # the model and card planning reads
            assert isinstance(net, GQCNNEnsemble) and len(net.members) == 2
            assert (
                card["crop_size"] == 96 and card["intrinsics"]["fx"] == 525 and card["camera_distance"] == [0.65, 0.75]
            )
            assert card["training_set"]["seed"] == seed and card["test_ap"] == summary["test"]["ap"]
            assert (
                card["training_set"]["precision"] == summary["train"]["precision"] == "bfloat16"
            )  # the tiny profile's
            validation.setdefault(seed, set()).add(summary["validation"]["datapoints"])
        assert (
            len(split["validation"]) == 2
            and not set(split["validation"]) & set(split["base"]["6"])
            and not set(split["validation"]) & set(split["real_pool"])
        )
        assert (work / f"reports/gqcnn/validation/s{seed}.png").stat().st_size > 0
    # paired: every network of a seed starts from the same weights, seeds from different ones; one validation set
    assert len(digests[0]) == len(digests[1]) == 1 and digests[0] != digests[1]
    assert len(validation[0] | validation[1]) == 1
    real = json.loads((work / "models/gqcnn/s0/real/6-1/summary.json").read_text())["train"]
    assert real["original_shapes"] == 12 and real["generated_shapes_asked"] == 0
    recon = json.loads((work / "models/gqcnn/s0/recon/6-1/summary.json").read_text())["train"]
    assert recon["original_shapes"] == recon["generated_shapes_asked"] == 6 and 1 <= recon["generated_shapes"] <= 6
    targeted = json.loads((work / "models/gqcnn/s0/targeted/6-1/summary.json").read_text())["train"]
    assert (
        targeted["generated_shapes_asked"] == 6
        and targeted["original_shapes"] == 6
        and 0 < targeted["positive_share"] < 1
    )
    ap = json.loads((work / "reports/gqcnn/ap.json").read_text())
    report = (work / "reports/gqcnn/report.md").read_text()
    # the tiny test set holds both labels: every network's pooled test AP (over all its test datapoints, mean over
    # seeds; ap.json writes an undefined one as null) is a number, so the report's AP column and contrasts have values
    pooled = {
        f"{pool}/{b}-{r}": net["test_ap"]
        for pool, by_b in ap["networks"].items()
        for b, by_r in by_b.items()
        for r, net in by_r.items()
    }
    assert len(pooled) == len(names), sorted(pooled)
    assert all(v is not None and np.isfinite(v) for v in pooled.values()), pooled
    no_ratio = {n for n, c in ap["contrasts"].items() if "mean over ratios none" in c["meaning"]}  # said, not dropped
    assert all((c["mean"] is None) == (n in no_ratio) for n, c in ap["contrasts"].items()), ap["contrasts"]
    recon_line = next(line for line in report.splitlines() if line.startswith("- `recon_vs_real@6`"))
    assert re.search(r"\d of 6 recon shapes meshed \(\d dropped\) at 1:1\.$", recon_line), recon_line
    # one metrics file per declared contrast: its mean and t-interval ends
    assert {p.stem for p in (work / "metrics/ap").glob("*.json")} == set(ap["contrasts"])
    matched = {n for n in ap["contrasts"] if n.endswith("_vs_real_datapoints@6")}  # every one declared, never dropped
    assert matched == {f"{p}_vs_real_datapoints@6" for p in ("targeted", "random", "recon", "blend")}
    assert set(ap["contrasts"]) - {"targeted_vs_none_chosen@6"} - matched == {
        "real_data",
        "targeted_vs_none@6",
        "targeted_vs_random@6",
        "targeted_vs_real@6",
        "recon_vs_real@6",
        "targeted_vs_recon@6",
        "blend_vs_recon@6",
        "targeted_vs_blend@6",
    }
    assert ("targeted_vs_none_chosen@6" in ap["contrasts"]) == ("6" in ap["chosen_ratio"])
    for c in ap["contrasts"].values():
        assert c["over"] == "draws" and c["n_draws"] == 1  # judged by the one interval over seeds × objects
        if c["mean"] is not None:
            assert c["n_seeds"] == 2 and c["draws_low"] <= c["mean"] <= c["draws_high"]
            assert c["seeds_low"] is None or -1 <= c["seeds_low"] <= c["mean"] <= c["seeds_high"] <= 1
    assert set(ap["networks"]["targeted"]["6"]) == {"0", "0.5", "1"} and ap["seeds"] == [0, 1]
    assert (
        "| targeted | 4 | 1:0 |" in report
        and "| real | 6 | 1:0.5 |" in report
        and "## Contrasts" in report
        and "## What the numbers say" in report
    )
    for picture in ("ap_vs_ratio", "improvement_by_score", "tsne_graspness"):
        assert (work / f"reports/gqcnn/{picture}.png").stat().st_size > 0
    # the decomposition real → recon → blend → targeted / random on this run's one draw, its step named in the report
    steps = json.loads((work / "reports/gqcnn/decomposition.json").read_text())
    assert steps["draws"] == [0] and steps["seeds"] == [0, 1]
    step = steps["contrasts"]["blend_vs_recon@6"]
    assert step["n_draws"] == 1 and step["n_seeds"] == 2
    assert (
        step["draws_low"] is None or step["draws_low"] <= step["draws_high"]
    )  # None: a resample of the few tiny objects lacks a class
    same = ap["contrasts"]["blend_vs_recon@6"]["mean"]  # None: a network of the few tiny shapes had no test AP
    assert step["mean"] == pytest.approx(same, abs=1e-4) if same is not None else step["mean"] is None
    assert "One draw of the data" in (work / "reports/gqcnn/decomposition.md").read_text()
    assert "At B = 6 " in report
    shown = run(["dvc", "metrics", "show", "--json"], work, env)
    assert "metrics/gqcnn/s1.json" in shown.stdout and "metrics/ap/real_data.json" in shown.stdout
    again = run(["dvc", "repro", "report"], work, env)
    assert "Running stage" not in again.stdout


def test_from_failures_of_a_networks_worst_validation_objects(tiny_repo, tmp_path):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "train_gqcnn"], work, env)
    command = ["graspaug", "from-failures", "--network", "targeted/6-0", "--worst", "2", "--count", "3"]
    run([*command, "-o", str(tmp_path / "out")], work, env)
    failures = pd.read_csv(tmp_path / "out/failures.csv")
    validation = json.loads((work / "models/gqcnn/s0/split.json").read_text())["validation"]
    # every validation object with datapoints is scored, worst first; the two worst are the failures
    assert set(failures.object) <= set(validation) and len(failures) >= 2
    assert failures.log_loss.is_monotonic_decreasing and failures.failure.tolist()[:2] == [True, True]
    assert not failures.failure.iloc[2:].any()
    index = pd.read_csv(tmp_path / "out/index.csv")
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    train = set(shapes.shape_id[shapes.split == "train"]) - set(validation)  # no validation object is a parent
    assert len(index) == 3 and set(index.parent_a) | set(index.parent_b) <= train
    assert set(index.failure) <= set(failures.object[:2])
    both = subprocess.run(
        [*command, str(tmp_path)], cwd=work, env=env, capture_output=True, text=True
    )  # a folder and a network: refused
    assert both.returncode == 2 and "either a folder" in both.stderr


def test_dvc_repro_lifelong_rounds(tiny_repo):
    import json

    import yaml

    work, env = tiny_repo
    run(["dvc", "repro", "lifelong@r2"], work, env)  # the tiny profile's two rounds, after round 0
    shapes = pd.read_parquet(work / "data/shapes.parquet")
    split = json.loads((work / "models/gqcnn/s0/split.json").read_text())
    held_out = set(split["validation"]) | set(shapes.shape_id[shapes.split == "test"])
    base = set(split["base"]["6"])
    for k in (1, 2):
        data = work / f"data/lifelong/r{k}"
        made = pd.read_parquet(data / "shapes.parquet")
        # no validation or test object ever enters a training set: parents are base shapes, the real arm's shapes
        # are train shapes outside validation, and the datapoints are the generated shapes' own
        assert set(made.parent_a) | set(made.parent_b) <= base and len(made) == 2 * 2 * k
        assert list(made.groupby("arm").size()) == [2 * k, 2 * k] and set(made["round"]) == set(range(1, k + 1))
        real = set(pd.read_csv(data / "real.csv").shape_id)
        assert len(real) == 2 * k and not real & (held_out | base)
        trained = set(pd.read_parquet(data / "dataset/index.parquet").shape_id)
        assert trained <= set(made.shape_id)
        for s in (0, 1):
            for arm in ("failure", "random", "real"):
                folder = work / f"models/lifelong/r{k}/s{s}/{arm}/6-{k * 2 / 6:g}"
                summary = json.loads((folder / "summary.json").read_text())
                assert summary["train"]["original_shapes"] == 6 + (2 * k if arm == "real" else 0)
        failures = pd.read_csv(data / "failures.csv")
        assert set(failures.object) <= set(split["validation"]) and failures.chosen.sum() == 1
        for name in ("failure_vs_random", "failure_vs_real", "real_data", "ap_failure"):
            assert set(json.loads((work / f"metrics/lifelong/r{k}/{name}.json").read_text())) == {"mean", "lo", "hi"}
        report = (work / f"reports/lifelong/r{k}/report.md").read_text()
        assert f"`failure_vs_random@r{k}`" in report and "before_log_loss" in report
        assert all((work / f"reports/lifelong/r{k}/{p}.png").stat().st_size > 0 for p in ("curve", "gain", "failures"))
    curve = pd.read_csv(work / "data/lifelong/r2/curve.csv")
    assert list(curve["round"][curve.figure == "ap"]) == [0, 1, 1, 1, 1, 2, 2, 2, 2]
    assert list(curve.arm[(curve.figure == "gain") & (curve["round"] == 2)]) == ["failure", "random", "real"]
    assert list(pd.read_csv(work / "data/lifelong/r2/history.csv")["round"]) == [0, 1, 2]
    # round k + 1 reads round k's outputs, not round k - 1's
    lock = yaml.safe_load((work / "dvc.lock").read_text())["stages"]
    for k in (1, 2):
        paths = {d["path"] for d in lock[f"lifelong@r{k}"]["deps"]}
        assert f"data/lifelong/r{k - 1}" in paths and not {f"data/lifelong/r{j}" for j in range(k - 1)} & paths
    # a round is deterministic for a seed: run again, round 1's outputs are byte for byte the same (round 2 stays
    # up to date), and its shapes too
    before = (work / "data/lifelong/r1/shapes.parquet").read_bytes()
    run(["dvc", "repro", "-f", "-s", "lifelong@r1"], work, env)
    assert (work / "data/lifelong/r1/shapes.parquet").read_bytes() == before
    status = subprocess.run(["dvc", "status", "lifelong@r2"], cwd=work, env=env, capture_output=True, text=True)
    assert "up to date" in status.stdout, status.stdout


def test_a_one_member_network_is_a_plain_gqcnn(tiny_repo, tmp_path):
    """gqcnn.members = 1 (the study and paper profiles) writes one GQ-CNN, as before ensembles existed."""
    from graspaug.io.tables import read_table
    from graspaug.pipeline.params.model import load_params
    from graspaug.training.gqcnn_data import Corpora, load_split
    from graspaug.training.networks import NetworkJob, seed_members, train_network, weights_digest
    from graspaug.training.variants import Variant

    work, env = tiny_repo
    run(["dvc", "repro", "render@original"], work, env)
    params = load_params(work / "params.yaml")
    cfg = params.gqcnn
    corpora = Corpora(work / "data/gqcnn/original")
    shapes = read_table(work / "data/shapes.parquet")
    split = load_split(corpora.original, shapes, list(params.generate.base_sizes), cfg.val_shapes, params.seed)
    inits, noise_seeds = seed_members(cfg.net, params.seed, 0, 1)
    assert weights_digest(inits[0]) == weights_digest(
        seed_members(cfg.net, params.seed, 0, 2)[0][0]
    )  # member 0 whatever K
    job = NetworkJob(
        Variant("targeted", 6, 0.0), split, cfg.net, cfg.train, inits, noise_seeds, 0, "cpu", tmp_path, corpora
    )
    summary = train_network(job)
    folder = tmp_path / "targeted" / "6-0"
    assert (
        isinstance(summary["train"]["best_step"], int)
        and isinstance(summary["noise_seed"], int)
        and "members" not in summary["train"]
    )
    assert summary["init_digest"] == weights_digest(inits[0]) and not list(folder.glob("*_members.npy"))
    from graspaug.io.checkpoints import finish_gqcnn_card

    assert summary["train"]["precision"] == cfg.train.precision == "bfloat16"  # recorded for the model card
    before = {**summary, "train": {k: v for k, v in summary["train"].items() if k != "precision"}}
    assert finish_gqcnn_card({}, before)["training_set"]["precision"] is None  # a network from before it was recorded
    assert "member" not in pd.read_csv(folder / "history.csv").columns
    net, card = read_gqcnn(folder / "model.pt")
    assert type(net) is GQCNN and card is None


def test_dvc_repro_sim(tiny_repo):
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "sim"], work, env)
    metrics = json.loads((work / "reports/sim/summary.json").read_text())
    ap = json.loads((work / "reports/gqcnn/ap.json").read_text())
    after_ratio = (
        ap["summary"]["6"]["best_ratio"] if "6" in ap["summary"] else 1.0
    )  # no validation AP: the largest ratio
    assert metrics["arms"]["before"]["ratio"] == 0.0 and metrics["arms"]["after"]["ratio"] == after_ratio
    assert metrics["setup"]["after_ratio_from_report"] == ("6" in ap["summary"]) and metrics["setup"][
        "model_seeds"
    ] == [0, 1]
    assert metrics["per_seed"]["0"]["before"]["attempts"] == metrics["per_seed"]["1"]["before"]["attempts"] == 4
    network_arms = ["before", "after"] + (["real"] if after_ratio > 0 else [])
    assert list(metrics["arms"]) == [*network_arms, "antipodal", "oracle"]  # the tiny run trains the real pool at B = 6
    assert metrics["arms"]["oracle"]["attempts"] == 4  # the ceiling, once per drop as the floor (issue #83)
    span = metrics["contrasts"]["oracle_vs_antipodal"]  # the cell's span: 4 drops, no training seed
    assert span["n_trials"] == 4 and span["n_seeds"] == 1 and span["objects_low"] <= span["mean"]
    assert json.loads((work / "metrics/sim/oracle_vs_antipodal.json").read_text())["mean"] == round(span["mean"], 5)
    for arm in network_arms:
        a = metrics["arms"][arm]
        assert a["attempts"] == 8 and 0 <= a["successes"] <= 8  # two training seeds, the same 4 drops each
        assert a["wilson_low"] <= a["success_rate"] <= a["wilson_high"]
    assert metrics["arms"]["antipodal"]["attempts"] == 4  # the reference arm without a network runs once
    for name in ("after_vs_before", "network_vs_antipodal") + (("after_vs_real",) if after_ratio > 0 else ()):
        c = metrics["contrasts"][name]
        # against the antipodal arm (one run per drop) each of the 4 drops counts once; network arms: 2 seeds × 4 drops
        assert (
            c["n_trials"] == (4 if name == "network_vs_antipodal" else 8)
            and c["objects_low"] <= c["mean"] <= c["objects_high"]
        )
        assert c["n_seeds"] == 2  # a t-interval over 2 seeds only where it stays within [-1, 1]
        assert c["seeds_low"] is None or -1 <= c["seeds_low"] <= c["mean"] <= c["seeds_high"] <= 1
        headline = json.loads((work / f"metrics/sim/{name}.json").read_text())
        assert headline == {"mean": round(c["mean"], 5), "lo": c["objects_low"], "hi": c["objects_high"]}
    ranking, executed = metrics["ranking"], pd.read_csv(work / "reports/grasp_calibration/grasps.csv")
    assert ranking["n_grasps"] == len(executed) == 6  # every arm's networks rank the executed calibration grasps
    assert list(ranking["arms"]) == (network_arms if executed.executed_success.nunique() == 2 else [])
    for name, c in ranking["contrasts"].items():
        headline = json.loads((work / f"metrics/sim/ranking_{name}.json").read_text())
        assert headline == {"mean": c["mean"], "lo": c["objects_low"], "hi": c["objects_high"]}
    trials = pd.read_csv(work / "reports/sim/trials.csv")
    assert len(trials) == 4 * len(network_arms) * 2 + 4 + 4 and set(trials.object) == {
        "cube",
        metrics["setup"]["test_shapes"][0],
    }
    feasible = trials.groupby("object").feasible.agg(set)  # from geometry before any pick: one verdict an object
    assert all(len(f) == 1 and f <= {True, False} for f in feasible)
    assert all(metrics["per_object"][o]["feasible"] == f.pop() for o, f in feasible.items())
    once = trials[trials.arm.isin(["antipodal", "oracle"])].pivot(index=["object", "attempt"], columns="arm")
    assert len(once) == 4 and (once.drop_seed.oracle == once.drop_seed.antipodal).all()  # the drops every arm picks
    oracle_drops = trials[trials.arm == "oracle"].set_index(["object", "attempt"]).drop_seed
    for seed in (0, 1):
        before = trials[(trials.arm == "before") & (trials.seed == seed)].set_index(["object", "attempt"]).drop_seed
        assert before.sort_index().equals(oracle_drops.sort_index())
    planned = ~trials.arm.isin(["antipodal", "oracle"]) & (trials.outcome != "no_grasp")
    assert trials.quality[trials.arm == "antipodal"].isna().all() and trials.quality[planned].notna().all()
    trials = trials[~trials.arm.isin(["antipodal", "oracle"])]
    # the same seeded drops for every arm
    assert set(trials.seed) == {0, 1}  # both training seeds' networks, on the same drops
    drops = trials.pivot_table(index=["seed", "object", "attempt"], columns="arm", values="drop_seed")
    assert (drops["before"] == drops["after"]).all()
    from graspaug.sim.trials import OUTCOMES

    assert set(trials.outcome) <= set(OUTCOMES)
    assert (trials.success == (trials.outcome == "success")).all()
    timing = json.loads((work / "reports/sim/timing.json").read_text())
    assert timing["trials"] == len(trials) + 8 and timing["planning_time_max"] > 0
    report = (work / "reports/sim/report.md").read_text()
    assert "## Contrasts" in report and "## Calibration" in report and "network_vs_antipodal" in report
    lines, f = report.splitlines(), metrics["feasibility"]  # the oracle's verdict first, feasible objects beside all
    first = lines[lines.index("# Simulated robot trials") + 2]
    assert first.startswith("**The oracle picks" if f["oracle_rate"] is not None else "**No object is feasible"), first
    assert f"Feasible objects first: {f['feasible']['objects']} of 2 objects" in report and f["all"]["objects"] == 2
    head = next(i for i, line in enumerate(lines) if line.startswith("| arm | feasible objects ("))
    assert [line.split(" | ")[0] for line in lines[head + 2 : head + 2 + len(metrics["arms"])]] == [
        f"| {arm}" for arm in metrics["arms"]
    ]  # every arm, the oracle too
    calibration = pd.read_csv(work / "reports/sim/calibration.csv")
    assert (
        set(calibration.object) == {"cube", metrics["setup"]["test_shapes"][0]}
        and calibration.graspness.isna().sum() == 1
    )
    for picture in ("success.png", "trials/before-cube.png", "trials/after-cube.png", "trials/antipodal-cube.png"):
        assert (work / "reports/sim" / picture).stat().st_size > 0
    again = run(["dvc", "repro", "sim"], work, env)
    assert "Running stage" not in again.stdout


def test_dvc_repro_grasp_calibration(tiny_repo):
    """The tiny profile's 6 labelled test grasps executed in the cell: one row each, from the rendered test split,
    with an outcome; the headline files hold the summary's figures."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "grasp_calibration"], work, env)
    out = work / "reports/grasp_calibration"
    grasps = pd.read_csv(out / "grasps.csv")
    index = with_split(pd.read_parquet(work / "data/gqcnn/original/index.parquet"), pd.read_parquet(work / SHAPES))
    test = index[index.split == "test"].set_index(["shape_id", "pose_id", "grasp_id"])
    assert len(grasps) == 6 and grasps.set_index(["shape_id", "pose_id", "grasp_id"]).index.isin(test.index).all()
    assert (index.shape_id.to_numpy()[grasps.datapoint] == grasps.shape_id).all()  # its row in the index
    from graspaug.sim.trials import OUTCOMES

    assert set(grasps.outcome) <= set(OUTCOMES) and (grasps.executed_success == (grasps.outcome == "success")).all()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_grasps"] == 6 and summary["n_positive"] == int(grasps.label.sum())
    for name in (
        "success_positive",
        "success_negative",
        "auc_eps",
        "auc_eps_collision_free",
        "auc_quality",
        "auc_label",
    ):
        headline = json.loads((work / f"metrics/grasp_calibration/{name}.json").read_text())
        assert set(headline) == {"mean", "lo", "hi"}
        assert headline["mean"] == (None if summary[name]["mean"] is None else round(summary[name]["mean"], 5))
    assert (out / "calibration.png").stat().st_size > 0 and len(pd.read_csv(out / "by_eps.csv")) > 0
    again = run(["dvc", "repro", "grasp_calibration"], work, env)
    assert "Running stage" not in again.stdout


def test_roundtrip_ceiling_study_labels_the_originals_as_the_grasps_stage_does(tiny_repo, tmp_path):
    """`graspaug study roundtrip-ceiling` at its smallest: 2 train shapes, every variant a row, the originals'
    graspness the grasps stage's own."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "grasps@original"], work, env)
    out = tmp_path / "roundtrip"
    cmd = [*GRASPAUG, "study", "roundtrip-ceiling", "--project", str(work), "--shapes", "2", "--workers", "1"]
    printed = run([*cmd, "--out", str(out)], work, env).stdout
    per_shape = pd.read_csv(out / "per_shape.csv")
    shapes = pd.read_parquet(work / "data/shapes.parquet").set_index("shape_id")
    assert per_shape.shape_id.nunique() == 2 and (shapes.loc[per_shape.shape_id, "split"] == "train").all()
    assert sorted(per_shape.variant.unique()) == sorted(
        ["original", "occupancy 32", "occupancy 64", "tsdf 32", "tsdf 64"]
    )
    original = per_shape[per_shape.variant == "original"].set_index("shape_id")
    grasps = pd.read_parquet(work / "data/grasps/original.parquet")
    expected = grasps[grasps.shape_id.isin(original.index)].groupby("shape_id").success.mean()
    assert np.allclose(original.graspness, expected.reindex(original.index, fill_value=0))
    summary = json.loads((out / "summary.json").read_text())
    assert summary["settings"]["shapes"] == 2 and len(summary["rows"]) == 5 and "| original |" in printed
    assert set(json.loads((out / "timing.json").read_text())) == {"seconds", "per_shape_mean", "per_shape_median"}


def test_grasp_calibration_study_without_changes_is_the_stage(tiny_repo, tmp_path):
    """`graspaug study grasp-calibration` with no `--set` executes the stage's grasps with the stage's outcomes; a
    `--set` naming no sim key is one line and exit 2."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "grasp_calibration"], work, env)
    table = tmp_path / "grasps.csv"
    cmd = [*GRASPAUG, "study", "grasp-calibration", "--n", "6", "--workers", "1", "--table", str(table)]
    summary = json.loads(run(cmd, work, env).stdout.strip().splitlines()[-1])
    stage = pd.read_csv(work / "reports/grasp_calibration/grasps.csv")
    study = pd.read_csv(table)
    assert study.datapoint.tolist() == stage.datapoint.tolist()
    assert study.outcome.tolist() == stage.outcome.tolist()
    assert summary["n_grasps"] == 6 and summary["changes"] == []
    bad = subprocess.run([*cmd, "--set", "hand.no_such_key=1"], cwd=work, env=env, capture_output=True, text=True)
    assert bad.returncode == 2 and "no_such_key" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1


def test_cell_ranking_study_ranks_the_calibration_grasps_with_one_project(tiny_repo):
    """`graspaug study cell-ranking` on the tiny run's calibration grasps and its own networks (one draw): each arm's
    AUC per seed, the top picks per seed, no pooled interval over one draw."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "report", "grasp_calibration"], work, env)
    cmd = [*GRASPAUG, "study", "cell-ranking", "--grasps", "reports/grasp_calibration/grasps.csv", "--projects", "."]
    result = json.loads(run([*cmd, "--base-size", "6", "--seeds", "0", "1"], work, env).stdout.strip().splitlines()[-1])
    assert result["grasps"] == 6 and list(result["draws"]) == ["."]
    draw = result["draws"]["."]
    assert draw["arms_networks"]["before"] == ["targeted", 0.0, 6]
    assert all(len(picks) == 2 and all(0 <= p <= 1 for p in picks) for picks in draw["top_pick"].values())
    assert all(value is None for value in result["pooled"].values())


def test_attribution_study_records_a_finished_draw_then_combines_from_results_alone(tiny_repo, tmp_path):
    """`graspaug study attribution` over one finished draw (the tiny run, linked as draw0) adds its tables to
    results/ at once; `--combine-only` then combines from results/ alone, with the clone gone."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "report"], work, env)
    (tmp_path / "draw0").symlink_to(work)
    cmd = [*GRASPAUG, "study", "attribution", "--draws", "0", "--workdir", str(tmp_path), "--profile", "tiny"]
    printed = run([*cmd, "--resamples", "50", "--results", "tiny-study", "--keep-networks", "0/0"], work, env).stdout
    assert (tmp_path / "decomposition.md").read_text() in printed
    kept = sorted(p.parent.name for p in (work / "results/tiny-study/networks/d0-s0").glob("*/model.pt"))
    assert kept and all(k.split("-")[0] in ("targeted", "real") for k in kept) and any(k.endswith("-0") for k in kept)
    card = json.loads(next((work / "results/tiny-study/networks/d0-s0").glob("*/card.json")).read_text())
    assert card["label_threshold"] > 0
    meta = json.loads((work / "results/tiny-study/meta.json").read_text())
    assert meta["command"].startswith("graspaug study attribution --draws 0") and meta["n_resamples"] == 50
    assert meta["draws"]["0"]["seconds"] >= 0 and len(meta["draws"]["0"]["commit"]) == 40
    networks = pd.read_parquet(work / "results/tiny-study/networks.parquet")
    assert set(networks.seed) == {0, 1} and set(networks.draw) == {0} and networks.test_ap.between(0, 1).all()
    assert (work / "results/tiny-study/predictions-d0-s1.parquet").is_file()
    summary = json.loads((tmp_path / "summary.json").read_text())
    (tmp_path / "draw0").unlink()
    (tmp_path / "summary.json").unlink()
    again = run([*cmd, "--combine-only", "--resamples", "50", "--results", "tiny-study"], work, env).stdout
    assert json.loads((tmp_path / "summary.json").read_text()) == summary and "# Why generated shapes help" in again
    assert not (tmp_path / "draw0").exists()  # nothing was cloned
    two = [*GRASPAUG, "study", "attribution", "--draws", "0", "--draws", "1", "--workdir", str(tmp_path)]
    missing = subprocess.run(
        [*two, "--profile", "tiny", "--combine-only", "--results", "tiny-study"],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
    )
    assert missing.returncode != 0 and "no draw 1" in missing.stderr + missing.stdout


def test_attribution_study_runs_draws_on_a_dask_cluster_and_names_a_failed_one(tiny_repo, tmp_path):
    """`graspaug study attribution --scheduler`: each draw one task on a LocalCluster of two workers (draw 0 the
    finished tiny run, draw 1 a new clone whose data stages come from the run cache); draw 2, whose clone cannot be
    made, is named with its reason while the others finish and keep their tables."""
    distributed = pytest.importorskip("distributed")
    work, env = tiny_repo
    run(["dvc", "repro", "report"], work, env)
    (tmp_path / "draw0").symlink_to(work)
    (tmp_path / "draw2").write_text("not a folder")  # git cannot clone into it
    cmd = [*GRASPAUG, "study", "attribution", "--draws", "0", "1", "2", "--workdir", str(tmp_path), "--profile", "tiny"]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        done = subprocess.run(
            [*cmd, "--resamples", "20", "--results", "tiny-dask", "--scheduler", cluster.scheduler_address],
            cwd=work,
            env=env,
            capture_output=True,
            text=True,
        )
    assert done.returncode == 2, done.stderr
    assert "1 draw(s) failed, the others finished (draw 2: NotADirectoryError:" in done.stderr, done.stderr
    networks = pd.read_parquet(work / "results/tiny-dask/networks.parquet")
    assert set(networks.draw) == {0, 1}  # both finished draws kept their tables
    both = run(
        [*cmd[:6], "0", "1", *cmd[9:], "--combine-only", "--resamples", "20", "--results", "tiny-dask"], work, env
    )
    assert "targeted_vs_none" in both.stdout


def test_lifelong_study_combines_a_finished_draw(tiny_repo, tmp_path):
    """`graspaug study lifelong --combine-only` over one draw (the tiny run's rounds, linked as draw0): every
    round's arms, the curves, the predictions recorded with the command."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro", "lifelong@r2"], work, env)
    (tmp_path / "draw0").symlink_to(work)
    cmd = [*GRASPAUG, "study", "lifelong", "--draws", "0", "--workdir", str(tmp_path), "--profile", "tiny"]
    printed = run([*cmd, "--combine-only", "--resamples", "50", "--results", "tiny-lifelong"], work, env).stdout
    assert "# The lifelong loop over draws of the data" in printed and "| 2 |" in printed
    assert set(json.loads((tmp_path / "summary.json").read_text())) == {"0", "1", "2"}
    assert len(pd.read_csv(tmp_path / "followed.csv")) == 2
    assert (tmp_path / "curve.png").stat().st_size > 0 and (tmp_path / "gain.png").stat().st_size > 0
    meta = json.loads((work / "results/tiny-lifelong/meta.json").read_text())
    assert meta["command"].startswith("graspaug study lifelong --draws 0") and meta["draws"] == [0]


def test_metrics_hold_few_scalars_and_fit_a_terminal(tiny_repo):
    """Every metrics file of the finished tiny run holds numbers, strings, booleans or None (dicts of them), no
    lists; `dvc metrics show` prints one table whose columns are the union of every file's keys: its rows stay
    narrow enough for a terminal. Tables (per seed, per object, per network) are reports, not metrics."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # every stage (critic_eval is no dep of sim); a no-op after the tests above
    shown = json.loads(run(["dvc", "metrics", "show", "--json"], work, env).stdout)
    files = sorted(path for rev in shown.values() for path in rev["data"])
    assert "metrics/train_ae.json" in files and "metrics/ap/real_data.json" in files and len(files) >= 15

    def leaves(value, key=""):
        if isinstance(value, dict):
            return [leaf for k, v in value.items() for leaf in leaves(v, f"{key}.{k}".lstrip("."))]
        assert isinstance(value, (int, float, str, bool, type(None))), f"{key} is a {type(value).__name__}"
        return [key]

    keys = set()
    for path in files:  # the files as written: DVC itself would drop a list silently
        keys |= set(leaves(json.loads((work / path).read_text())))
    assert len(keys) <= 16, sorted(keys)  # shared names merge into one column
    table = run(["dvc", "metrics", "show"], work, env).stdout.splitlines()
    # 203 characters on the tiny run since its test APs are defined (a test_ap column, negative contrast means)
    assert len(table) == len(files) + 1 and max(map(len, table)) <= 210, max(table, key=len)


def test_every_contrast_has_one_set_of_interval_keys(tiny_repo):
    """One result type: in every report a contrast's intervals are keyed by what they cover (``seeds_*``,
    ``objects_*``, ``draws_*``) with the ``over`` its verdict reads, and every metrics file holds an interval as
    ``mean``, ``lo``, ``hi``; no file of the run uses another interval key (``ci_low``, ``boot_low``, ...)."""
    import json
    import re

    from graspaug.experiments.stats import INTERVALS

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # a no-op after the tests above
    contrast_keys = {f"{name}_{end}" for name in INTERVALS for end in ("low", "high")}
    other = re.compile(r"^(ci|boot|t_ci)_(low|high)$")
    seen = {"metrics": 0, "reports": 0}

    def walk(value, path, where):
        if isinstance(value, list):
            for v in value:
                walk(v, path, where)
        if not isinstance(value, dict):
            return
        assert not [k for k in value if other.match(str(k))], f"{path}: {sorted(value)}"
        assert not {"low", "high"} & set(value) or "share" in value, f"{path}: {sorted(value)}"  # a ratio's interval
        if where == "metrics" and {"lo", "hi"} & set(value):
            assert {"mean", "lo", "hi"} <= set(value), f"{path}: {sorted(value)}"
            seen[where] += 1
        if where == "reports" and contrast_keys & set(value):
            assert contrast_keys <= set(value) and value["over"] in INTERVALS, f"{path}: {sorted(value)}"
            seen[where] += 1
        for k, v in value.items():
            walk(v, f"{path}.{k}", where)

    for where in seen:
        for path in sorted((work / where).rglob("*.json")):
            walk(json.loads(path.read_text()), str(path.relative_to(work)), where)
    assert seen["metrics"] >= 50 and seen["reports"] >= 50, seen  # ap, sim, lifelong, critic, fidelity, calibration


DATA_PLOT_SUFFIXES = (".csv", ".tsv", ".json", ".yaml", ".yml")


def declared_plots(dvc_yaml: dict) -> tuple[dict[str, list[tuple[str, str]]], list[tuple[str, dict]]]:
    """dvc.yaml's top-level data plots (id → the (file, column) series its ``y`` names) and its stages'
    data-file plots ((path, properties)); images and paths left for DVC to infer are not in either."""
    top = {}
    for entry in dvc_yaml.get("plots", []):
        if not isinstance(entry, dict):
            continue
        ((name, props),) = entry.items()
        assert props and {"x", "y"} <= set(props), f"top-level plot {name!r} must name x and y"
        assert isinstance(props["y"], dict), f"top-level plot {name!r}: y must name its files"
        top[name] = [
            (file, column)
            for file, columns in props["y"].items()
            for column in ([columns] if isinstance(columns, str) else columns)
        ]
    staged = []
    for stage in dvc_yaml["stages"].values():
        for entry in stage.get("do", stage).get("plots", []):
            path, props = next(iter(entry.items())) if isinstance(entry, dict) else (entry, {})
            if path.endswith(DATA_PLOT_SUFFIXES):
                staged.append((path, props))
    return top, staged


def draws(datapoint: dict, file: str, column: str) -> bool:
    """Whether a datapoint of `dvc plots show --json` belongs to the series ``column`` of ``file``.
    DVC tags each datapoint with what varies between a plot's series: ``filename::field``, ``field``
    or ``filename`` (the file less the files' common prefix); with a single series, with nothing."""
    if "dvc_inferred_y_value" not in datapoint and column not in datapoint:
        return False
    if "filename::field" in datapoint:
        short, _, field = datapoint["filename::field"].rpartition("::")
        return field == column and file.endswith(short)
    if "field" in datapoint:
        return datapoint["field"] == column
    if "filename" in datapoint:
        return file.endswith(datapoint["filename"])
    return True


def test_every_declared_plot_renders(tiny_repo):
    """`dvc plots show` on the finished tiny run: every plot dvc.yaml declares (per stage, for
    whatever base sizes params name, and the top-level ones) has data or an image, no errors; every
    data plot names its x and y, and draws each series it names; the HTML page needs no network."""
    import json

    import yaml

    work, env = tiny_repo
    run(["dvc", "repro", "sim"], work, env)  # no-op after the tests above
    shown = json.loads(run(["dvc", "plots", "show", "--json", "--split"], work, env).stdout)
    assert shown, "dvc plots show returned nothing"
    errors = shown.get("errors") if isinstance(shown, dict) and "errors" in shown else None
    assert not errors, errors
    plots = shown.get("data", shown)
    for name, renders in plots.items():
        assert renders, f"plot {name} has nothing to render"
        for render in renders:
            assert render.get("type") in ("image", "vega"), (name, render.get("type"))
            if render["type"] == "image":
                assert (work / render["url"]).exists() if not render["url"].startswith("data:") else True, name
    generated = {name for name in plots if "reports/generate/" in name}
    assert "reports/generate/6/pairs.png" in generated and not any(
        "generate/4/" in n for n in generated
    )  # the tiny profile's augmented base size

    top, staged = declared_plots(yaml.safe_load((work / "dvc.yaml").read_text()))
    for path, props in staged:  # drawn against the row index otherwise
        assert {"x", "y"} <= set(props), f"stage plot {path} must name x and y (or be an out, not a plot)"
    for name, series in top.items():
        assert not set("'\"") & set(name), f"{name!r}: quotes break the HTML page's script"
        (render,) = plots[name]
        datapoints = render["anchor_definitions"]["<DVC_METRIC_DATA>"]
        for file, column in series:
            assert any(draws(d, file, column) for d in datapoints), f"{name!r} does not draw {column} of {file}"
        if "ap_table.csv" in series[0][0]:  # long format: one line per pool
            assert {d["pool"] for d in datapoints} >= {"targeted", "random", "real", "recon"}, name

    run(["dvc", "plots", "show"], work, env)
    page = (work / "dvc_plots/index.html").read_text()
    assert "<script src=" not in page and "vegaEmbed(" in page  # Vega inline: draws with no network
    assert "dvc_plots" not in run(["git", "status", "--porcelain"], work, env).stdout  # ignored


def test_queued_two_point_sweep_lines_up_metrics(tiny_repo):
    """`dvc exp run --queue -S` twice, `dvc queue start`, then `dvc exp show` / `dvc params diff` / `dvc metrics diff
    --all`. The points sweep a key of `critic_eval`, a stage of seconds that no other stage reads: each point re-runs
    it alone and carries the committed run's other metrics, the cell's and the AP contrasts' among them, which only
    ``--all`` lines up (unchanged)."""
    import json
    import time

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # the baseline is complete (no-op after the tests above)
    run(["git", "add", "-A"], work, env)
    run(["git", "commit", "-q", "-m", "baseline"], work, env)
    for pairs in (2, 4):
        run(
            ["dvc", "exp", "run", "--queue", "-S", f"critic_eval.n_pairs={pairs}", "--name", f"pairs-{pairs}"],
            work,
            env,
        )
    run(["dvc", "queue", "start", "-j", "2"], work, env)  # both points at once: the suite's other tests are done
    deadline = time.time() + 600
    while time.time() < deadline:
        status = run(["dvc", "queue", "status"], work, env).stdout
        if "Queued" not in status and "Running" not in status:
            break
        time.sleep(3)
    assert status.count("Success") == 2, status
    shown = json.loads(run(["dvc", "exp", "show", "--json"], work, env).stdout)
    experiments = {}
    for commit in shown:
        for exp in commit.get("experiments") or []:
            for rev in exp.get("revs") or []:
                data = rev["data"]
                experiments[rev.get("name") or data.get("name")] = data
    assert {"pairs-2", "pairs-4"} <= set(experiments), list(experiments)
    for name, pairs in (("pairs-2", 2), ("pairs-4", 4)):
        data = experiments[name]
        assert data["params"]["params.yaml"]["data"]["critic_eval"]["n_pairs"] == pairs
        critic = data["metrics"]["metrics/critic_eval.json"]["data"]
        sim = data["metrics"]["metrics/sim/after_vs_before.json"]["data"]
        ap = data["metrics"]["metrics/ap/real_data.json"]["data"]
        assert (
            {"mean", "lo", "hi"} <= set(critic) and set(sim) == {"mean", "lo", "hi"} and set(ap) <= {"mean", "lo", "hi"}
        )
    changed = json.loads(run(["dvc", "params", "diff", "pairs-2", "pairs-4", "--json"], work, env).stdout)
    assert list(changed["params.yaml"]) == ["critic_eval.n_pairs"]
    assert (
        changed["params.yaml"]["critic_eval.n_pairs"]["old"],
        changed["params.yaml"]["critic_eval.n_pairs"]["new"],
    ) == (2, 4)
    diff = json.loads(run(["dvc", "metrics", "diff", "pairs-2", "pairs-4", "--json", "--all"], work, env).stdout)
    assert {"mean", "lo", "hi"} <= set(diff["metrics/critic_eval.json"])  # the swept stage's, re-run at each point
    assert set(diff["metrics/sim/after_vs_before.json"]) == {"mean", "lo", "hi"}  # --all lines up every metric
    assert all(v["diff"] == 0 for v in diff["metrics/sim/after_vs_before.json"].values())  # the key reaches no cell
    for key in ("test_ap", "val_ap"):  # the tiny run's test AP is defined, as its validation AP
        assert set(diff["metrics/gqcnn/s0.json"][key]) == {"old", "new", "diff"}, key
    run(["dvc", "queue", "stop"], work, env)


def test_killed_stage_leaves_no_output_and_repro_completes(tiny_repo):
    """SIGKILL `dvc repro ingest` while it writes meshes: no half-written output is taken as valid,
    and the next `dvc repro` writes the same outputs as before."""
    import signal
    import time

    work, env = tiny_repo
    before = pd.read_parquet(work / "data/shapes.parquet")
    process = subprocess.Popen(
        ["dvc", "repro", "-f", "-s", "ingest"],
        cwd=work,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    partial = []
    deadline = time.time() + 120
    while time.time() < deadline and process.poll() is None:
        partial = [p for p in (work / "data").glob(".shapes.tmp-*") if p.is_dir() and len(list(p.iterdir())) >= 3]
        if partial:
            os.killpg(process.pid, signal.SIGKILL)
            break
        time.sleep(0.01)
    process.wait()
    assert partial, "the stage finished before any mesh was written; nothing was killed"
    assert not (
        work / "data/shapes"
    ).exists()  # DVC removed the old output; the half-written one is only a .tmp sibling
    assert "ingest" in run(["dvc", "status", "ingest"], work, env).stdout  # the stage is not taken as up to date
    run(["dvc", "repro", "sim"], work, env)  # DVC runs ingest again (or restores it from its run cache)
    pd.testing.assert_frame_equal(pd.read_parquet(work / "data/shapes.parquet"), before)
    again = run(["dvc", "repro", "sim"], work, env)
    assert "Running stage" not in again.stdout


def test_editing_a_sim_setting_reruns_only_sim(tiny_repo):
    """Exact code deps: a cell-only module's edit (a settings description) changes the stages that run the robot
    cell (`sim`, `grasp_calibration`) and the params check (it reads every section) alone."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # the pipeline is complete (after the tests above: check_params alone runs)
    settings = work / "src/graspaug/sim/settings.py"
    original = settings.read_text()
    edited = original.replace('description="', 'description="(edited) ', 1)
    assert edited != original
    settings.write_text(edited)
    try:
        changed = json.loads(run(["dvc", "status", "--json"], work, env).stdout)
    finally:
        settings.write_text(original)
    assert set(changed) == {"sim", "grasp_calibration", "check_params"}, f"changed stages: {sorted(changed)}"
    assert json.loads(run(["dvc", "status", "--json"], work, env).stdout) == {}


def test_editing_the_cli_or_a_stage_reruns_only_what_runs_it(tiny_repo):
    """Each stage runs its own module: an edit of cli.py (a help text, a user's command) leaves the finished run up
    to date, an edit of one stage's adapter changes that stage alone, and one of augment's pools not ingest."""
    import json

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # the pipeline is complete
    for rel, expected in [
        ("src/graspaug/pipeline/cli.py", set()),
        ("src/graspaug/pipeline/planner_cli.py", set()),
        ("src/graspaug/pipeline/stages/sim.py", {"sim"}),
        ("src/graspaug/augment/pools.py", None),
    ]:
        path = work / rel
        original = path.read_text()
        path.write_text(original + "# edited\n")
        try:
            changed = set(json.loads(run(["dvc", "status", "--json"], work, env).stdout))
        finally:
            path.write_text(original)
        if expected is None:
            assert changed and "ingest" not in changed, (rel, changed)
        else:
            assert changed == expected, (rel, changed)
    assert json.loads(run(["dvc", "status", "--json"], work, env).stdout) == {}


def test_a_bad_params_file_stops_dvc_repro_before_any_stage_deletes_outputs(tiny_repo):
    """A mistyped top-level key, and a bad value, stop `dvc repro` in `check_params` (the first stage) with one line
    naming the key: no other stage runs and every output stays, even when nothing else would have run."""
    import yaml

    work, env = tiny_repo
    run(["dvc", "repro"], work, env)  # up to date
    params = work / "params.yaml"
    original = params.read_text()
    outputs = sorted((work / "models").rglob("*")) + sorted((work / "data").rglob("*"))
    bad_value = yaml.safe_load(original)
    bad_value["gqcnn"]["train"]["lr"] = -1.0
    try:
        for text, key in ((original + "sede: 3\n", "sede"), (yaml.safe_dump(bad_value), "gqcnn.train.lr")):
            params.write_text(text)
            result = subprocess.run(["dvc", "repro"], cwd=work, env=env, capture_output=True, text=True)
            said = result.stdout + result.stderr
            assert result.returncode != 0 and key in said, said
            assert said.count("Running stage") == 1 and "Running stage 'check_params'" in said, said
            assert all(p.exists() for p in outputs), "an output was deleted"
    finally:
        params.write_text(original)
    assert "Running stage" not in run(["dvc", "repro"], work, env).stdout
