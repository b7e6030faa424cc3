"""The shapes a profile's settings need of a corpus (issue #84: 12 own meshes on the tiny profile stopped at
`generate@6` with exit 3, "rarity needs at least 2 reference shapes", after the AutoEncoder, the grasps and the renders
had run): the count, worked out per setting, is the least that every consumer of the split can run on."""

import dataclasses
from pathlib import Path

import pandas as pd
import pytest

from graspaug.augment.candidates import draw_base_sets
from graspaug.augment.corpus import assign_split
from graspaug.errors import DataError
from graspaug.pipeline.params.profiles import profile_params
from graspaug.pipeline.shape_needs import params_shape_needs, real_pool_ids
from graspaug.training.gqcnn_data import experiment_split, training_shapes
from graspaug.training.shape_counts import ShapeNeeds, n_test_shapes, shape_count_problem, shape_needs
from graspaug.training.variants import Variant, seed_variants

PROFILES = Path(__file__).resolve().parents[2] / "profiles"


@pytest.mark.parametrize(
    "profile, needs, kept",
    [  # base + validation + real pool (its most demanding user) = train; test; the fewest shapes that split so
        ("tiny", ShapeNeeds(6, 2, 6, "real/6-1", 2), 19),  # 14 train at 0.2663: 19 shapes (18: 13 train)
        ("default", ShapeNeeds(200, 100, 50, "real/50-1", 2), 477),
        ("paper", ShapeNeeds(200, 100, 400, "real/200-2", 2), 954),  # random_urdfs: 979 kept
        ("real_objects", ShapeNeeds(150, 15, 100, "real/100-1", 2), 331),  # 400 real objects
        ("why", ShapeNeeds(200, 50, 0, "", 2), 312),  # no real or recon pool
        ("lifelong", ShapeNeeds(200, 100, 100, "real/100-1", 2), 545),  # 2 rounds × 25: 50 < 100
    ],
)
def test_each_profile_needs_its_base_sets_validation_and_real_pool(profile, needs, kept):
    params = profile_params(profile, PROFILES)
    found = params_shape_needs(params.generate, params.gqcnn, params.lifelong)
    assert found == needs and found.kept(params.ingest.test_fraction) == kept


@pytest.mark.parametrize(
    "variants, pools, augment, lifelong_real, real, real_for, test",
    [
        (
            [Variant("recon", 6, 0.5), Variant("real", 4, 1.0)],
            ("targeted", "real", "recon"),
            (4, 6),
            0,
            4,
            "real/4-1",
            2,
        ),
        ([Variant("real", 6, 0.1)], ("targeted", "real"), (6,), 0, 2, "fidelity of real", 2),  # fidelity needs 2
        ([Variant("targeted", 6, 1.0)], ("targeted", "recon"), (6,), 15, 15, "lifelong's real arm", 2),
        ([Variant("targeted", 6, 1.0)], ("targeted", "random"), (6,), 0, 0, "", 2),
        ([Variant("targeted", 6, 0.0)], ("targeted", "real"), (), 0, 0, "", 1),  # no fidelity: one test shape
    ],
)
def test_the_real_pool_is_what_its_most_demanding_user_takes(
    variants, pools, augment, lifelong_real, real, real_for, test
):
    assert shape_needs((4, 6), 3, variants, pools, augment, lifelong_real) == ShapeNeeds(6, 3, real, real_for, test)


@pytest.mark.parametrize("test_fraction", [0.1, 0.2, 0.2663, 0.5, 0.9])
def test_the_test_count_is_the_one_the_split_draws(test_fraction):
    for n in range(1, 60):
        split = assign_split([f"s{i}" for i in range(n)], test_fraction, 0)
        assert list(split.values()).count("test") == n_test_shapes(n, test_fraction)


def consumer_problems(n: int, params) -> list[str]:
    """What fails when ``n`` shapes (none a duplicate, all rendered) go through the split, the base sets, the
    validation and real pool draw, every network of a training seed and fidelity's real pool and reference."""
    gen, gq = params.generate, params.gqcnn
    ids = [f"s{i:03d}" for i in range(n)]
    split = assign_split(ids, params.ingest.test_fraction, params.seed)
    shapes = pd.DataFrame({"shape_id": ids, "split": [split[i] for i in ids]})
    train = list(shapes.shape_id[shapes.split == "train"])
    try:
        base = {b: list(s) for b, s in draw_base_sets(shapes, gen.base_sizes, params.data_seed).items()}
        drawn = experiment_split(train, base, gq.val_shapes, params.data_seed)
    except DataError as exc:
        return [str(exc)]
    variants = seed_variants(gen.base_sizes, gen.ratios, gq.augment_base_sizes, gq.ceiling, gq.pools, gq.control_ratios)
    problems = []
    for v in variants:
        try:
            training_shapes(v, drawn)
        except DataError as exc:
            problems.append(str(exc))
    if {"real", "recon"} & set(gq.pools) and len(drawn.real_pool) < 2:
        problems.append(f"fidelity: the real pool holds {len(drawn.real_pool)} shapes")
    if (shapes.split == "test").sum() < 2:
        problems.append("fidelity: fewer than 2 test shapes")
    return problems


@pytest.mark.parametrize("profile", ["tiny", "real_objects"])
def test_the_count_is_the_least_every_consumer_runs_on(profile):
    """At the count every network, the recon pool and fidelity find their shapes; one shape fewer and something
    downstream fails, which the check now says at the split."""
    params = profile_params(profile, PROFILES)
    needs = params_shape_needs(params.generate, params.gqcnn, params.lifelong)
    least, fraction = needs.kept(params.ingest.test_fraction), params.ingest.test_fraction
    assert consumer_problems(least, params) == []
    assert consumer_problems(least - 1, params)
    for n, refused in ((least, False), (least - 1, True)):
        n_test = n_test_shapes(n, fraction)
        assert (shape_count_problem(n - n_test, n_test, needs, fraction) is not None) == refused


def test_too_few_shapes_is_one_line_with_the_counts_the_keys_and_the_remedy():
    """The issue's 12 meshes on the tiny profile: 9 train, 3 test."""
    params = profile_params("tiny", PROFILES)
    needs = params_shape_needs(params.generate, params.gqcnn, params.lifelong)
    line = shape_count_problem(9, 3, needs, params.ingest.test_fraction)
    assert line == (
        "too few shapes: 12 kept by ingest (9 train, 3 test at ingest.test_fraction 0.2663), but these settings need "
        "14 train (generate.base_sizes up to 6 + gqcnn.val_shapes 2 + 6 for the real pool (real/6-1)) and 2 test "
        "shapes, at least 19 in all: add 7 or more shapes, or lower generate.base_sizes, gqcnn.val_shapes or what the "
        "real pool must give (generate.ratios, gqcnn.pools, gqcnn.augment_base_sizes)"
    )
    assert shape_count_problem(14, 5, needs, params.ingest.test_fraction) is None
    assert "1 test" in shape_count_problem(14, 1, needs, params.ingest.test_fraction)  # enough train, too few test


def test_generate_refuses_a_real_pool_that_render_left_too_small():
    """19 shapes pass the split (14 train); render@original skipping one train shape leaves the real pool 5 shapes,
    short of real/6-1: generate says so in one line (it had stopped with exit 3 where the pool held 1 shape)."""
    params = profile_params("tiny", PROFILES)
    gen, gq = params.generate, params.gqcnn
    train, test = [f"s{i:02d}" for i in range(14)], ("t0", "t1", "t2", "t3", "t4")
    shapes = pd.DataFrame({"shape_id": train + list(test), "split": ["train"] * 14 + ["test"] * 5})
    base = {b: list(s) for b, s in draw_base_sets(shapes, gen.base_sizes, params.data_seed).items()}
    full = dataclasses.replace(experiment_split(train, base, gq.val_shapes, params.data_seed), test=test)
    assert list(real_pool_ids(full, params.ingest, gen, gq)) == list(full.real_pool)
    skipped = full.real_pool[0]
    rendered = [s for s in train if s != skipped]
    short = dataclasses.replace(experiment_split(rendered, base, gq.val_shapes, params.data_seed), test=test)
    with pytest.raises(DataError, match=r"^too few shapes: 18 with datapoints from render@original \(13 train, 5 test"):
        real_pool_ids(short, params.ingest, gen, gq)


def test_generate_counts_the_base_sets_as_rendered():
    """A base shape render@original skipped leaves the base set smaller and the real pool as large: 13 rendered train
    shapes, the largest base set 5 of its nominal 6, validation 2, a real pool of 6, so real/6-1 is served and generate
    goes on (counting the nominal base set it would have asked for 14)."""
    params = profile_params("tiny", PROFILES)
    gen, gq = params.generate, params.gqcnn
    train, test = [f"s{i:02d}" for i in range(14)], ("t0", "t1", "t2", "t3", "t4")
    shapes = pd.DataFrame({"shape_id": train + list(test), "split": ["train"] * 14 + ["test"] * 5})
    drawn = {b: list(s) for b, s in draw_base_sets(shapes, gen.base_sizes, params.data_seed).items()}
    skipped = drawn[max(drawn)][0]  # a shape of every base set it lies in (nested)
    base = {b: [s for s in ids if s != skipped] for b, ids in drawn.items()}
    rendered = [s for s in train if s != skipped]
    split = dataclasses.replace(experiment_split(rendered, base, gq.val_shapes, params.data_seed), test=test)
    assert len(split.base[max(base)]) == 5 and len(split.real_pool) == 6
    assert list(real_pool_ids(split, params.ingest, gen, gq)) == list(split.real_pool)
