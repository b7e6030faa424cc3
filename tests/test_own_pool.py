"""The own pool through real ``dvc repro`` on the tiny profile: an AE-Critic trained on the base set alone
(``train_ae_own@6``), the targeted recipe decoded by it (``generate@6``), rendered, and a GQ-CNN trained on
[own, 6, 1.0]; and the library parts it adds (the step-matched schedule, the check that the AE trained on the base
set alone)."""

import json

import numpy as np
import pandas as pd
import pytest
import trimesh
import yaml

from graspaug.augment.candidates import draw_base_sets
from graspaug.augment.decode import own_source
from graspaug.augment.pools import BaseSet
from graspaug.errors import DataError
from graspaug.io.checkpoints import load_autoencoder
from graspaug.nets.settings import AEConfig
from graspaug.training.autoencoder import batches_per_epoch, step_matched
from graspaug.training.settings import AETrainConfig
from tests.clones import run, tiny_clone


def test_step_matched_takes_the_main_aes_sgd_steps_on_fewer_shapes():
    cfg = AETrainConfig(batch_size=16, epochs_ae=90, epochs_critic=6, critic_warmup=2)
    assert batches_per_epoch(309, 16) == 20 and batches_per_epoch(50, 16) == 4 and batches_per_epoch(17, 16) == 1
    own = step_matched(cfg, 309, 50)  # the confirm profile's sizes: 20 batches an epoch there, 4 here
    assert (own.epochs_ae, own.epochs_critic, own.critic_warmup) == (450, 30, 10)
    assert own.epochs_ae * 4 == cfg.epochs_ae * 20 and own.lr_ae == cfg.lr_ae and own.batch_size == 16
    named = step_matched(cfg, 309, 50, epochs_ae=200, epochs_critic=12)  # generate.own names them
    assert (named.epochs_ae, named.epochs_critic, named.critic_warmup) == (200, 12, 4)


def test_own_source_refuses_an_ae_trained_on_other_shapes():
    ids = np.array(["a", "b", "c"])
    base = BaseSet(ids, np.zeros((3, 2), np.float32), np.zeros(3), np.ones(3), np.ones(3))
    latents = pd.DataFrame({"shape_id": ids, "z": list(np.eye(3, 2, dtype=np.float32))})
    for trained in ({"train_ids": ["a", "b", "c", "d"]}, {"train_ids": ["a", "b"]}, {}):
        with pytest.raises(DataError, match="not trained on that base set alone"):
            own_source(None, trained, latents, base, 1, lambda ae, base, label: None)
    own = own_source("the own AE", {"train_ids": ["a", "b", "c"]}, latents, base, 1, lambda ae, base, label: ae)
    assert own.run_batch == "the own AE" and (own.shapes.z == np.eye(3, 2)).all()  # its own latents, base's ids
    assert (own.shapes.graspness == base.graspness).all() and own.shapes.rarity.shape == (3,)


@pytest.mark.slow
def test_dvc_repro_own_pool_from_an_ae_of_the_base_set_alone(repo_root, tmp_path):
    def own_pool_only(params: dict) -> None:
        params["gqcnn"] |= {"pools": ["targeted", "own"], "control_ratios": [1.0], "members": 1, "ceiling": False}
        params["gqcnn"]["seeds"] = [0]
        params["gqcnn"]["networks"] = [["targeted", 6, 0.5], ["own", 6, 1.0]]  # generate makes only what they train on
        params["generate"]["own"] = {"epochs_ae": 150, "epochs_critic": 1}  # the main AE's epochs (half its SGD steps)

    work = tmp_path / "repo"
    env = tiny_clone(repo_root, work, tmp_path / "sim-cache", edit=own_pool_only)
    run(["dvc", "repro", "train_gqcnn@0"], work, env)
    params = yaml.safe_load((work / "params.yaml").read_text())

    shapes = pd.read_parquet(work / "data/shapes.parquet")
    base = list(draw_base_sets(shapes, (4, 6), seed=0)[6])  # the base set of B = 6 that generate and the GQ-CNN use
    summary = json.loads((work / "models/ae_own/6/summary.json").read_text())
    assert summary["trained"] and summary["train_ids"] == base
    _, critic, trained = load_autoencoder(work / "models/ae_own/6/ae_critic.pt", AEConfig(**params["ae"]["net"]))
    assert trained["train_ids"] == base and critic is not None  # an AE-Critic that saw the base set and nothing else
    assert summary["n_train"] == 6 and (summary["epochs_ae"], summary["epochs_critic"]) == (150, 1)
    assert all(summary[k] is not None and 0 <= summary[k] <= 1 for k in ("iou_base", "main_iou_base"))
    metrics = json.loads((work / "metrics/train_ae_own/6.json").read_text())
    assert metrics == {k: summary[k] for k in ("shapes", "iou_base", "main_iou_base")} and metrics["shapes"] == 6
    own_z = pd.read_parquet(work / "models/ae_own/6/latents.parquet")
    main_z = pd.read_parquet(work / "data/latents.parquet").set_index("shape_id").z
    assert list(own_z.shape_id) == base and not np.allclose(np.stack(own_z.z), np.stack(main_z.loc[base]))

    index = pd.read_parquet(work / "data/generated/6/index.parquet")
    own, targeted = (index[index.pool == p] for p in ("own", "targeted"))
    assert list(own.order) == list(range(6)) and list(targeted.order) == list(range(3))  # 1:1 and 1:0.5 of B = 6
    assert set(own.parent_a) | set(own.parent_b) <= set(base) and set(own.selected_by) <= {"rarity", "graspness"}
    assert own.shape_id.str.startswith("gen_6_o").all() and own.rarity_vs_base.notna().all()
    assert set(index.pool) == {"targeted", "own"}  # random and the rest: not asked for
    for shape_id in own.shape_id:
        assert trimesh.load(work / f"data/generated/6/meshes/{shape_id}.obj", force="mesh").is_watertight
    gen_summary = json.loads((work / "reports/generate/6/summary.json").read_text())
    assert gen_summary["own"]["kept"] == 6 and "k_used" in gen_summary["own"]
    rendered = pd.read_parquet(work / "data/gqcnn/gen_6/index.parquet")
    assert set(rendered.shape_id) & set(own.shape_id)  # rendered like any generated shape

    networks = json.loads((work / "reports/gqcnn/networks/s0.json").read_text())["networks"]
    assert set(networks) == {"targeted", "own"} and set(networks["own"]["6"]) == {"1"}
    net = json.loads((work / "models/gqcnn/s0/own/6-1/summary.json").read_text())
    assert (
        (work / "models/gqcnn/s0/own/6-1/model.pt").is_file()
        and net["pool"] == "own"
        and net["train"]["generated_shapes"] >= 1
    )
