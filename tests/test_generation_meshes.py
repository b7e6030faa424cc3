"""The generate stage's pool assembly (graspaug.generation_meshes) with a stand-in decoder."""

import numpy as np
import pandas as pd
import pytest
import trimesh

from graspaug.errors import DataError
from graspaug.generation import Decoded, pool_size
from graspaug.generation_meshes import REJECT_COLUMNS, BaseSet, base_ids, generate_pools, tsne_groups
from graspaug.params.generate import GenerateParams
from graspaug.scores import rarity

BOX = trimesh.creation.box(extents=(0.04, 0.03, 0.02))


def some_rejected(batch):
    """Rejects the candidates whose pair-and-weight hash says so; the others get a box."""
    out = []
    for c in batch:
        bad = (c.a * 7 + c.b * 3 + int(c.alpha * 10)) % 3 == 0
        out.append(Decoded(c, np.zeros(1, np.uint8), None if bad else BOX, "empty decode: no voxel" if bad else None))
    return out


def make_base(n=10, seed=0):
    rng = np.random.default_rng(seed)
    z = rng.normal(size=(n, 4)).astype(np.float32)
    ids = np.array([f"s{i}" for i in range(n)])
    return BaseSet(ids, z, rarity(z, 3), rng.random(n), np.full(n, 0.002))


def test_base_ids_checks_the_size_and_the_train_split():
    shapes = pd.DataFrame({"shape_id": [f"s{i}" for i in range(6)], "split": ["train"] * 4 + ["test"] * 2})
    assert len(base_ids(shapes, (2, 4), 4, 0)) == 4 and set(base_ids(shapes, (2, 4), 2, 0)) <= {"s0", "s1", "s2", "s3"}
    with pytest.raises(DataError, match="is not in generate.base_sizes"):
        base_ids(shapes, (2, 4), 3, 0)
    with pytest.raises(DataError, match="larger than the 4 train shapes"):
        base_ids(shapes, (2, 5), 2, 0)


def test_generate_pools_assembles_tables_in_pool_order():
    base, cfg = make_base(), GenerateParams(base_sizes=(10,), ratios=(0.0, 1.0), n_examples=2)
    out = generate_pools(base, cfg, 0, some_rejected, k=3)
    needed = pool_size(cfg.ratios, 10)
    assert len(out.index) == len(out.kept) == 2 * needed and list(out.rejects.columns) == REJECT_COLUMNS
    assert list(out.index.pool) == ["targeted"] * needed + ["random"] * needed
    assert [d.candidate.a for d in out.kept] == [list(base.ids).index(p) for p in out.index.parent_a]
    assert len(out.rejects) == sum(out.summary[p]["tried"] - out.summary[p]["kept"] for p in ("targeted", "random"))
    assert out.summary["rejects"] == {"empty decode": len(out.rejects)}
    assert [d.candidate for d in out.examples] == [d.candidate for d in out.kept[:2] + out.kept[needed : needed + 2]]
    assert out.warnings and len(out.warnings) == sum(share < 0.95 for share in out.kept_share.values())
    assert all(w.startswith("only ") and w.endswith("pool's decodes were usable meshes") for w in out.warnings)
    xy, groups = tsne_groups(base, out.index, 5.0, 0)
    assert xy.shape == (10 + 2 * needed, 2) and groups[:10] == ["base"] * 10 and groups[10].startswith("generated (")


def test_generate_pools_reports_an_exhausted_pool():
    base, cfg = make_base(3), GenerateParams(base_sizes=(3,), ratios=(1.0, 2.0), alphas=(0.5,))
    with pytest.raises(DataError, match=r"generate 3, \w+ pool: only"):
        generate_pools(base, cfg, 0, lambda batch: [Decoded(c, None, None, "bad") for c in batch], k=2)
