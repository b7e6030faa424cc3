"""The why study's arms (issue #82): an explicit list of networks, `balanced` (the base shapes alone, batches drawn at
targeted's positive share) and `views` (the base shapes plus as many datapoints of their own extra camera views as
targeted adds), read from real dataset folders and trained for a few real steps."""

import json
import math

import numpy as np
import pandas as pd
import pytest
import torch

from graspaug.errors import DataError
from graspaug.io.checkpoints import read_gqcnn
from graspaug.io.gqcnn import write_grasp_images
from graspaug.pipeline.params.model import ParamsError, params_dict, parse_params
from graspaug.pipeline.params.profiles import merge, profile_params, read_overlay
from graspaug.training.gqcnn import BatchSampler
from graspaug.training.gqcnn_data import Corpora, ExperimentSplit, training_set
from graspaug.training.networks import NetworkJob, seed_members, seed_table, train_jobs
from graspaug.training.variants import Variant, check_networks, seed_networks

# ---------------------------------------------------------------- the explicit list of networks


def test_an_explicit_list_trains_exactly_its_networks_and_an_empty_one_the_matrix():
    listed = [["targeted", 50, 0.0], ["balanced", 50, 1.0], ["targeted", 200, 2.0], ["views", 50, 1.0]]
    got = seed_networks(listed, (50, 200), (0.0, 1.0, 2.0), (50, 200), True, ("targeted", "random"))
    assert [v.name for v in got] == ["targeted/50-0", "balanced/50-1", "targeted/200-2", "views/50-1", "ceiling"]
    matrix = seed_networks((), (50,), (0.0, 1.0), (50,), False, ("targeted", "random"))
    assert [v.name for v in matrix] == ["targeted/50-0", "targeted/50-1", "random/50-1"]


@pytest.mark.parametrize(
    "entry, words",
    [
        (["mystery", 50, 1.0], "unknown pool"),
        (["targeted", 100, 0.0], "generate.base_sizes"),
        (["targeted", 200, 1.0], "gqcnn.augment_base_sizes"),
        (["recon", 50, 1.0], "gqcnn.pools"),
        (["balanced", 50, 2.0], "ratio 2"),
    ],
)
def test_a_network_generate_does_not_make_is_refused_naming_the_key(entry, words):
    problem = check_networks([entry], (50, 200), (0.0, 1.0), (50,), ("targeted", "random"))
    assert problem.startswith("gqcnn.networks: [") and words in problem
    with pytest.raises(DataError, match="gqcnn.networks"):
        seed_networks([entry], (50, 200), (0.0, 1.0), (50,), False, ("targeted", "random"))
    raw = merge(params_dict(), {"generate": {"base_sizes": [50, 200], "ratios": [0.0, 1.0]}})
    with pytest.raises(ParamsError, match="gqcnn.networks"):
        gqcnn = {"augment_base_sizes": [50], "pools": ["targeted", "random"], "networks": [entry]}
        parse_params(merge(raw, {"gqcnn": gqcnn}))


def test_a_views_network_needs_extra_views_and_a_duplicate_is_refused():
    with pytest.raises(ParamsError, match="gqcnn.extra_views"):
        parse_params(merge(params_dict(), {"gqcnn": {"networks": [["views", 50, 1.0]]}}))
    twice = check_networks([["targeted", 50, 0.0], ["random", 50, 0.0]], (50,), (0.0, 1.0), (50,), ("targeted",))
    assert "listed twice" in twice


def test_the_why_profile_trains_exactly_its_plans_arms(repo_root):
    why = profile_params("why", repo_root / "profiles")
    confirm = profile_params("confirm", repo_root / "profiles")
    names = [v.name for v in seed_networks(why.gqcnn.networks, why.generate.base_sizes, why.generate.ratios,
                                           why.gqcnn.augment_base_sizes, why.gqcnn.ceiling, why.gqcnn.pools,
                                           why.gqcnn.control_ratios)]  # fmt: skip
    expected = ["targeted/50-0", "targeted/50-1", "random/50-1", "balanced/50-1", "views/50-1"]
    expected += ["own/50-1"] if "own" in why.gqcnn.pools else []
    assert names == expected + ["targeted/200-0", "targeted/200-2"]
    for key in ("independent_draws", "data", "ingest", "render"):
        assert getattr(why, key) == getattr(confirm, key), key
    assert why.gqcnn.train == confirm.gqcnn.train and why.gqcnn.train.min_steps == why.gqcnn.train.max_steps == 8000
    assert (why.gqcnn.val_shapes, why.gqcnn.seeds, why.gqcnn.extra_views) == (50, (0,), 6)
    # generate makes 400 targeted shapes for B = 200 at 1:2 (the paper's robot networks: 200 + 409)
    from graspaug.augment.candidates import pool_size, ratio_count

    assert pool_size(why.generate.ratios, 200) == ratio_count(2.0, 200) == 400
    assert "networks" in read_overlay("why", repo_root / "profiles")["gqcnn"]


# ---------------------------------------------------------------- the balanced sampler


def test_the_balanced_sampler_draws_the_target_share_and_the_plain_one_is_the_epoch_stream():
    labels = torch.zeros(200, dtype=torch.int64)
    labels[::7] = 1  # 29 positives: 14.5%
    steps, batch, share = 300, 32, 0.4321
    sampler = BatchSampler(labels, batch, torch.Generator().manual_seed(3), share)
    seen = torch.cat([sampler() for _ in range(steps)])
    assert len(seen) == steps * batch
    assert abs(sampler.drawn_share - share) <= 0.5 / (steps * batch)
    assert sampler.positives == int(labels[seen].sum())
    counts = torch.bincount(seen, minlength=200)
    positives, negatives = counts[labels == 1], counts[labels == 0]
    assert positives.max() - positives.min() <= 1 and negatives.max() - negatives.min() <= 1  # pass by pass
    # without a share: the epoch-by-epoch stream of before (one randperm per pass, a pass's remainder left out)
    gen, plain = torch.Generator().manual_seed(4), BatchSampler(labels, 64, torch.Generator().manual_seed(4))
    order, cursor = torch.randperm(200, generator=gen), 0
    for _ in range(10):
        if cursor + 64 > len(order):
            order, cursor = torch.randperm(200, generator=gen), 0
        assert torch.equal(plain(), order[cursor : cursor + 64])
        cursor += 64
    assert plain.drawn_share == pytest.approx(float(labels.float().mean()), abs=0.05)
    with pytest.raises(ValueError, match="positive"):
        BatchSampler(torch.zeros(10, dtype=torch.int64), 4, torch.Generator(), 0.2)


# ---------------------------------------------------------------- real dataset folders: targeted, balanced, views

BASE = ("a0", "a1", "a2", "a3")


def _corpus(folder, rows: list[tuple[str, int]], extra: dict | None = None, seed: int = 0):
    """A GQ-CNN dataset folder with ``rows`` (shape id, label) of random 32 × 32 crops."""
    folder.mkdir(parents=True)
    rng = np.random.default_rng(seed)
    labels = np.array([lab for _, lab in rows], dtype=np.int64)
    images = (0.7 + 0.01 * rng.standard_normal((len(rows), 32, 32)) - 0.02 * labels[:, None, None]).astype(np.float32)
    index = pd.DataFrame(
        {"shape_id": [s for s, _ in rows], "z": rng.uniform(0.68, 0.72, len(rows)), "label": labels, "eps": 0.0}
    )
    for key, values in (extra or {}).items():
        index[key] = values
    write_grasp_images(folder, images, index, shard_rows=50)
    return folder


@pytest.fixture
def corpora(tmp_path):
    """Original: 4 base shapes (10 datapoints each, 2 positive), 2 validation and 2 test shapes; generated for B = 4:
    a targeted pool of 4 shapes (order 0-3, 6 datapoints each, 4 positive) and a random one; extra views of every
    original shape (12 datapoints each, 3 positive)."""
    ids = list(BASE) + ["v0", "v1", "t0", "t1"]
    original = _corpus(tmp_path / "original", [(s, int(i < 2 or s[0] != "a")) for s in ids for i in range(10)])
    gen_rows = [(f"{p}{k}", int(i < 4)) for p in ("g", "r") for k in range(4) for i in range(6)]
    pools = ["targeted" if s[0] == "g" else "random" for s, _ in gen_rows]
    order = [int(s[1]) for s, _ in gen_rows]
    generated = _corpus(tmp_path / "gen_4", gen_rows, {"pool": pools, "order": order}, seed=1)
    views = _corpus(tmp_path / "views", [(s, int(i < 3)) for s in ids for i in range(12)], seed=2)
    split = ExperimentSplit({4: BASE}, ("v0", "v1"), (), (), test=("t0", "t1"))
    return split, Corpora(original, {4: generated}, views)


def test_balanced_targets_targeteds_share_and_views_adds_exactly_what_targeted_adds(corpora):
    split, corp = corpora
    targeted, t_info = training_set(Variant("targeted", 4, 1.0), split, corp)
    assert (t_info["datapoints"], len(targeted)) == (40 + 24, 64)  # 4 base shapes + 4 targeted shapes
    share = (8 + 16) / 64
    balanced, b_info = training_set(Variant("balanced", 4, 1.0), split, corp)
    assert len(balanced) == 40 and b_info["positive_share"] == 0.2 and b_info["generated_shapes"] == 0
    assert b_info["target_positive_share"] == round(share, 6) == round(t_info["positive_share"], 6)
    views, v_info = training_set(Variant("views", 4, 1.0), split, corp)
    assert v_info["views_datapoints"] == 24 and v_info["datapoints"] == t_info["datapoints"] == len(views) == 64
    half = training_set(Variant("views", 4, 0.5), split, corp)[1]
    assert half["views_datapoints"] == 12  # targeted@4 at 1:0.5: 2 shapes of 6 datapoints
    # only the base shapes' extra views, and a smaller ratio's rows a prefix of a larger one's
    from graspaug.training.gqcnn_data import views_rows

    rows_1, _ = views_rows(Variant("views", 4, 1.0), split, corp)
    rows_h, _ = views_rows(Variant("views", 4, 0.5), split, corp)
    index = pd.read_parquet(corp.views / "index.parquet")
    assert set(index.shape_id.iloc[rows_1]) <= set(BASE) and set(rows_h) <= set(rows_1)


def test_too_few_extra_views_or_none_rendered_name_the_key(corpora, tmp_path):
    split, corp = corpora
    few = _corpus(tmp_path / "few", [(s, 0) for s in BASE for _ in range(2)])
    with pytest.raises(DataError, match="gqcnn.extra_views"):
        training_set(Variant("views", 4, 1.0), split, Corpora(corp.original, corp.generated, few))
    with pytest.raises(DataError, match="gqcnn.extra_views"):
        training_set(Variant("views", 4, 1.0), split, Corpora(corp.original, corp.generated))


def test_balanced_and_views_train_for_real_and_report_their_shares_and_counts(corpora, tmp_path, repo_root):
    split, corp = corpora
    gq = profile_params("tiny", repo_root / "profiles").gqcnn
    train = type(gq.train)(**{**gq.train.__dict__, "min_steps": 6, "max_steps": 6, "batch_size": 16})
    inits, noise = seed_members(gq.net, 7, 0, 1)
    out = tmp_path / "s0"
    variants = [Variant("targeted", 4, 1.0), Variant("balanced", 4, 1.0), Variant("views", 4, 1.0)]
    jobs = [NetworkJob(v, split, gq.net, train, inits, noise, 0, "cpu", out, corp, {"data_seed": 1}) for v in variants]
    val = training_set(Variant("targeted", 4, 0.0), ExperimentSplit({4: split.validation}, (), (), ()), corp)[0]
    test = training_set(Variant("targeted", 4, 0.0), ExperimentSplit({4: split.test}, (), (), ()), corp)[0]
    targeted, balanced, views = train_jobs(jobs, val, test, "why arms")
    assert targeted["train"]["steps"] == balanced["train"]["steps"] == views["train"]["steps"] == 6
    target = balanced["train"]["target_positive_share"]
    assert target == round(24 / 64, 6)
    drawn = balanced["train"]["drawn_positive_share"]
    assert abs(drawn - target) <= 0.5 / (6 * 16) + 1e-6 and math.floor(6 * 16 * target + 0.5) == round(drawn * 96)
    assert views["train"]["views_datapoints"] == 24 and views["train"]["datapoints"] == 64
    card = read_gqcnn(out / "balanced/4-1/model.pt")[1]["training_set"]
    assert (card["target_positive_share"], card["drawn_positive_share"]) == (target, drawn)
    assert read_gqcnn(out / "views/4-1/model.pt")[1]["training_set"]["views_datapoints"] == 24
    assert json.loads((out / "balanced/4-1/summary.json").read_text())["train"]["drawn_positive_share"] == drawn
    table = seed_table([targeted, balanced, views])
    assert table["balanced"]["4"]["1"]["target_positive_share"] == target
    assert table["views"]["4"]["1"]["views_datapoints"] == 24


def test_an_explicit_list_of_networks_makes_only_the_shapes_its_networks_train_on():
    """``networks_at``: generate and train_ae_own read which pools, at which ratios, a base size needs; balanced and
    views need targeted's shapes at their (B, R); without a list, None (every pool of gqcnn.pools)."""
    from graspaug.training.settings import networks_at

    networks = [["targeted", 50, 0.0], ["balanced", 50, 1.0], ["random", 50, 1.0], ["targeted", 200, 2.0]]
    assert networks_at(networks, 50) == {"targeted": {1.0}, "random": {1.0}}
    assert networks_at(networks, 200) == {"targeted": {2.0}}
    assert networks_at(networks, 100) == {} and networks_at([], 50) is None


def test_generate_makes_only_the_pools_and_ratios_its_listed_networks_train_on():
    from graspaug.augment.settings import GenerateSettings
    from graspaug.training.settings import listed_pools

    cfg = GenerateSettings(base_sizes=(50, 200), ratios=(0.0, 1.0, 2.0))
    networks = [["targeted", 50, 1.0], ["own", 50, 1.0], ["targeted", 200, 2.0]]
    assert listed_pools(cfg, ["targeted", "random", "own"], networks, 50)[1] == ["targeted", "own"]
    assert listed_pools(cfg, ["targeted", "random", "own"], networks, 50)[0].ratios == (0.0, 1.0)
    assert listed_pools(cfg, ["targeted", "random"], networks, 200) == (
        GenerateSettings(**{**vars(cfg)} | {"ratios": (0.0, 2.0)}),
        ["targeted"],
    )
    assert listed_pools(cfg, ["targeted", "random"], [], 200) == (cfg, ["targeted", "random"])
