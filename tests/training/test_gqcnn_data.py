"""The GQ-CNN experiment's datasets: object-wise validation, the same for every variant."""

import pytest

from graspaug.training.gqcnn_data import experiment_split, training_shapes
from graspaug.training.variants import seed_variants

TRAIN = [f"rnd_{i:03d}" for i in range(60)]
BASE = {10: TRAIN[:10], 20: TRAIN[:20]}  # nested, as generate draws them


def test_validation_is_disjoint_from_every_training_set_and_the_same_for_every_variant():
    split = experiment_split(TRAIN, BASE, n_validation=8, seed=3)
    assert split == experiment_split(TRAIN, BASE, n_validation=8, seed=3)  # no training seed, variant or pool enters
    assert len(split.validation) == 8 and not set(split.validation) & set(BASE[20])
    assert set(split.real_pool) == set(TRAIN) - set(BASE[20]) - set(split.validation)
    assert set(split.ceiling) == set(TRAIN) - set(split.validation)
    for variant in seed_variants([10, 20], [0.0, 0.5, 1.0], [10, 20], ceiling=True):
        shapes, generated = training_shapes(variant, split)
        assert not set(shapes) & set(split.validation), variant
        assert set(BASE[variant.base_size]) <= set(shapes) if variant.pool != "ceiling" else len(shapes) == 52
        if variant.pool == "real":
            assert len(shapes) == variant.base_size + round(variant.ratio * variant.base_size) and generated == 0
        elif variant.pool in ("targeted", "random"):
            assert generated == round(variant.ratio * variant.base_size)
    assert experiment_split(TRAIN, BASE, 8, seed=4).validation != split.validation  # the global seed draws it


def test_a_real_pool_too_small_names_the_keys_to_change():
    split = experiment_split(TRAIN, BASE, n_validation=30, seed=0)  # 10 shapes left for the real pool
    variant = next(v for v in seed_variants([20], [1.0], [20], False) if v.pool == "real")
    with pytest.raises(ValueError, match="needs 20 more train shapes; 10 lie outside.*gqcnn.val_shapes"):
        training_shapes(variant, split)
    with pytest.raises(ValueError, match="gqcnn.val_shapes = 41, but only 40"):
        experiment_split(TRAIN, BASE, n_validation=41, seed=0)


def test_split_ids_are_plain_data_by_role():
    from graspaug.training.gqcnn_data import split_ids

    split = experiment_split(TRAIN, BASE, n_validation=8, seed=3)
    ids = split_ids(split)
    assert ids == {
        "validation": split.validation,
        "real_pool": split.real_pool,
        "base": {"10": split.base[10], "20": split.base[20]},
    }


def test_a_new_data_seed_redraws_base_sets_validation_and_real_pool_but_not_the_test_split(tmp_path, repo_root):
    import pandas as pd
    import yaml

    from graspaug.training.gqcnn_data import load_split

    shapes = pd.DataFrame({"shape_id": TRAIN + ["tst_0", "tst_1"], "split": ["train"] * 60 + ["test"] * 2})
    (tmp_path / "original").mkdir()
    shapes.assign(label=0).to_parquet(tmp_path / "original" / "index.parquet", index=False)
    draws = [load_split(tmp_path / "original", shapes, [10, 20], 8, data_seed) for data_seed in (0, 1)]
    assert draws[0] == load_split(tmp_path / "original", shapes, [10, 20], 8, 0)  # the data seed alone decides
    for role in ("validation", "real_pool"):
        assert getattr(draws[0], role) != getattr(draws[1], role), role
    assert draws[0].base[20] != draws[1].base[20] and all(set(d.base[10]) < set(d.base[20]) for d in draws)
    assert all(not {"tst_0", "tst_1"} & (set(d.ceiling) | set(d.real_pool)) for d in draws)
    # the test split is the split stage's, drawn from `seed` (and data_seed with independent_draws): only it and the
    # stages that draw the experiment's data read data_seed
    # (fidelity takes the real pool as they do; the report names the draw its decomposition comes from; the lifelong
    # loop's rounds draw their random parents from it and name the draw in their reports; sim names the draw its
    # contrasts cover; train_ae_own trains the own pool's AE-Critic on the base set alone, which it draws with
    # data_seed as generate does: base_ids(..., params.data_seed))
    stages = yaml.safe_load((repo_root / "dvc.yaml").read_text())["stages"]
    readers = {name for name, stage in stages.items() if "data_seed" in (stage.get("do") or stage).get("params", [])}
    assert readers == {
        "split",
        "generate",
        "train_ae_own",
        "fidelity",
        "train_gqcnn",
        "report",
        "lifelong_start",
        "lifelong",
        "sim",
    }
