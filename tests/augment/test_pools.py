"""The generate stage's pool assembly (graspaug.augment.pools) with a stand-in decoder."""

import numpy as np
import pandas as pd
import pytest
import trimesh

from graspaug.augment.candidates import Decoded, pool_size
from graspaug.augment.pools import REJECT_COLUMNS, BaseSet, ReconSource, base_ids, generate_pools, tsne_groups
from graspaug.augment.scores import rarity
from graspaug.errors import DataError
from graspaug.pipeline.params.generate import GenerateParams

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


def test_the_recon_pool_decodes_the_real_pools_first_shapes_once_and_drops_a_failed_decode():
    """Shape k of the recon pool is shape k of the real pool: a failed decode is a gap (order k missing), never
    replaced by the next real shape, so the recon networks of ratio R train on the real networks' shapes less
    the failures (like with like), and the pool never runs out (the gso300 case: 85 of 100 meshed)."""
    base, cfg = make_base(), GenerateParams(base_sizes=(10,), ratios=(0.0, 0.5), n_examples=2)
    real = make_base(8, seed=1)
    real = BaseSet(np.array([f"real{i}" for i in range(8)]), real.z, real.rarity, real.graspness, real.pitch)

    def second_fails(batch):
        return [
            Decoded(c, np.zeros(1, np.uint8), None, "tiny") if c.a == 1 else Decoded(c, None, BOX, None) for c in batch
        ]

    out = generate_pools(base, cfg, 0, some_rejected, 3, ("targeted", "recon"), ReconSource(real, second_fails))
    recon = out.index[out.index.pool == "recon"]
    assert list(out.index.pool.unique()) == ["targeted", "recon"]  # random was not asked for
    assert list(recon.parent_a) == list(recon.parent_b) == ["real0", "real2", "real3", "real4"]
    assert (recon.alpha == 0).all() and (recon.selected_by == "recon").all()
    assert list(recon.order) == [0, 2, 3, 4] and list(recon.shape_id) == [f"gen_10_c{k:04d}" for k in (0, 2, 3, 4)]
    np.testing.assert_array_equal(np.stack(recon.z.to_numpy()), real.z[[0, 2, 3, 4]])
    assert out.summary["recon"]["tried"] == 5 and out.summary["recon"]["kept"] == 4
    assert list(out.rejects.parent_a[out.rejects.pool == "recon"]) == ["real1"]
    every_one_fails = ReconSource(real, lambda batch: [Decoded(c, None, None, "tiny") for c in batch])
    out = generate_pools(base, cfg, 0, some_rejected, 3, ("targeted", "recon"), every_one_fails)
    assert out.summary["recon"] == out.summary["recon"] | {"kept": 0, "tried": 5}  # no "pool exhausted"
    with pytest.raises(DataError, match="the recon pool needs the real pool's shapes"):
        generate_pools(base, cfg, 0, some_rejected, 3, ("targeted", "recon"))


def test_a_recon_shape_is_the_autoencoders_reconstruction_meshed_at_its_own_scale():
    """The recon pool's grid of a shape is decode(encode(its voxels)), cleaned as every decode is."""
    import torch

    from graspaug.augment.candidates import ReconStream
    from graspaug.augment.decode import mesh_batches
    from graspaug.geometry.from_voxels import clean_occupancy
    from graspaug.geometry.settings import DecodeSettings
    from graspaug.nets.ae_critic import AEConfig, AutoEncoder, decode, encode

    torch.manual_seed(0)
    ae = AutoEncoder(AEConfig(resolution=16, z_dim=8, base_width=4, top_width=16, output="occupancy"))
    with torch.no_grad():  # untrained: a bias that leaves most of the grid occupied, varying with the latent
        ae.decoder.net[-1].bias.fill_(1.0)
    grids = torch.zeros(3, 1, 16, 16, 16)
    grids[:, :, 4:12, 5:11, 6:10] = 1
    z = encode(ae, grids, torch.device("cpu"))
    pitch = np.array([0.002, 0.003, 0.004])
    real = BaseSet(np.array(["a", "b", "c"]), z, np.zeros(3), np.zeros(3), pitch)
    settings = DecodeSettings(threshold=0.5, min_voxels=1, min_main_share=0.01, smoothing_iterations=0)
    run_batch = mesh_batches(ae, torch.device("cpu"), real, settings, 1, "test")
    decoded = run_batch(ReconStream(3).take(0, 3))
    probability = decode(ae, z, torch.device("cpu"))
    for k, d in enumerate(decoded):
        grid = clean_occupancy(probability[k], 0.5, settings.opening, 1, 0.01)
        np.testing.assert_array_equal(d.packed_grid, np.packbits(grid.occupancy))
        assert d.mesh is not None and d.reason is None  # meshed at its own pitch: extent in voxels × pitch
        filled = np.argwhere(grid.occupancy)
        voxels_across = filled.max(0) - filled.min(0) + 1
        np.testing.assert_allclose(np.sort(d.mesh.extents), np.sort(voxels_across * pitch[k]), rtol=0.2)


def test_the_blend_pool_takes_the_targeted_pools_pairs_and_weights_and_replaces_a_failure():
    base, cfg = make_base(), GenerateParams(base_sizes=(10,), ratios=(0.0, 1.0))

    def first_fails(batch):  # the blend of the targeted pool's first kept pair fails
        first = out_targeted[0]
        return [
            Decoded(c, np.zeros(0, np.uint8), None if c == first else BOX, "empty" if c == first else None)
            for c in batch
        ]

    plain = generate_pools(base, cfg, 0, some_rejected, 3, ("targeted",))
    out_targeted = [d.candidate for d in plain.kept]
    out = generate_pools(base, cfg, 0, some_rejected, 3, ("targeted", "blend"), controls={"blend": first_fails})
    targeted, blend = (out.index[out.index.pool == p] for p in ("targeted", "blend"))
    key = lambda rows: list(zip(rows.parent_a, rows.parent_b, rows.alpha))  # noqa: E731
    assert key(blend)[: len(blend) - 1] == key(targeted)[1:]  # the same pairs and weights, in order
    assert key(blend)[-1] not in key(targeted)  # the failure replaced by the targeted stream's next candidate
    assert list(blend.shape_id) == [f"gen_10_b{k:04d}" for k in range(len(blend))]
    assert (
        len(blend) == len(targeted) == out.summary["blend"]["kept"] and out.summary["blend"]["tried"] == len(blend) + 1
    )
    with pytest.raises(DataError, match="the blend pool needs its runner"):
        generate_pools(base, cfg, 0, some_rejected, 3, ("targeted", "blend"))


def test_blend_batches_mix_the_parents_meshes_at_each_weight():
    from graspaug.augment.candidates import Candidate
    from graspaug.augment.decode import blend_batches
    from graspaug.geometry.voxelize import fit_grid, iou, voxelize_solid

    meshes = [trimesh.creation.capsule(height=0.03, radius=0.01), trimesh.creation.icosphere(radius=0.02)]
    run_batch = blend_batches(meshes, 96, 3, 1, "test")  # the default: the ingest surface resolution
    ends = run_batch([Candidate(0, 1, 0.0, "rarity"), Candidate(0, 1, 1.0, "rarity"), Candidate(0, 1, 0.5, "rarity")])
    for d, parent in zip(ends[:2], meshes):  # voxel IoU in the parent's 32³ grid, the child placed as it
        grid, child = fit_grid(parent.bounds, 32, 1), d.mesh.vertices + parent.bounds.mean(0) - d.mesh.bounds.mean(0)
        grids = [voxelize_solid(v, m.faces, grid) for v, m in ((child, d.mesh), (parent.vertices, parent))]
        assert d.reason is None and iou(*grids) >= 0.95
    assert ends[2].reason is None and ends[2].mesh.is_watertight


def test_the_warp_and_primitives_pools_are_the_data_seeds_and_warp_only_base_shapes():
    """A warp's parent is a targeted candidate's nearer parent, a base (train) shape, never a held-out one; an
    assembly has no real parent; neither has a latent; both pools are the same for one data seed, another for the
    next."""
    from graspaug.augment.decode import control_runners
    from graspaug.geometry.settings import SurfaceSettings

    base, cfg = make_base(4), GenerateParams(base_sizes=(4,), ratios=(0.0, 1.0), primitives={"resolution": 24})
    meshes = [trimesh.creation.box(extents=(0.02 + 0.01 * i, 0.03, 0.05)) for i in range(4)]
    pools = ("targeted", "warp", "primitives")

    def made(seed):
        controls = control_runners(pools, meshes, cfg, SurfaceSettings(), seed, 4, 1)
        return generate_pools(base, cfg, seed, some_rejected, 2, pools, controls=controls)

    out, again, other = made(0), made(0), made(1)
    targeted, warp, prims = (out.index[out.index.pool == p] for p in pools)
    assert len(warp) == len(prims) == len(targeted) == 4
    assert list(warp.parent_a) == list(warp.parent_b) and set(warp.parent_a) <= set(base.ids)
    assert list(warp.parent_a) == [base.ids[d.candidate.a] for d in out.kept[:4]]  # the targeted pool's order
    assert prims.parent_a.str.startswith("assembly_").all() and prims.rarity_vs_base.isna().all()
    assert warp.rarity_vs_base.isna().all() and targeted.rarity_vs_base.notna().all()  # a warp has no latent
    assert (out.index.watertight & out.index.one_piece).all()
    for a, b in zip(out.kept, again.kept):
        assert np.array_equal(a.mesh.vertices, b.mesh.vertices)
    assert not np.allclose(out.kept[-1].mesh.extents, other.kept[-1].mesh.extents)
    assert np.isclose(np.sort(out.kept[-1].mesh.extents)[1], SurfaceSettings().size_m)  # the ingest size rule
    xy, groups = tsne_groups(base, out.index, 5.0, 0)
    assert len(xy) == 4 + 4 and set(groups[4:]) <= {"generated (rarity)", "generated (graspness)"}  # latents only


def test_the_procedural_pool_adds_procedural_objects_outside_the_corpus_and_refuses_its_own():
    """The procedural pool holds pybullet's random_urdfs objects made solid by ingest's rule, none of the experiment's
    own sources, in an order the data seed fixes; with the procedural corpus as the experiment's own corpus it has
    nothing to add and says so."""
    from graspaug.augment.decode import control_runners, procedural_sources
    from graspaug.errors import DataError
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.io.sources import pybullet_sources

    every = pybullet_sources()
    own = [s.name for s in every[:-12]]  # this experiment's corpus: all but 12 procedural objects
    sources = procedural_sources(own, key=[0, 1, 4])
    assert {s.name for s in sources} == {s.name for s in every[-12:]}
    assert [s.name for s in sources] == [s.name for s in procedural_sources(own, key=[0, 1, 4])]
    assert [s.name for s in sources] != [s.name for s in procedural_sources(own, key=[1, 1, 4])]

    base, cfg = make_base(4), GenerateParams(base_sizes=(4,), ratios=(0.0, 1.0))
    pools = ("targeted", "procedural")
    real_size = SurfaceSettings(size="real")  # a corpus kept at real size: procedural objects still normalized
    controls = control_runners(pools, [], cfg, real_size, 0, 4, 1, procedural=sources)
    ids = [s.shape_id for s in sources]
    out = generate_pools(base, cfg, 0, some_rejected, 2, pools, controls=controls, procedural_ids=ids)
    procedural = out.index[out.index.pool == "procedural"]
    assert len(procedural) == 4 and procedural.parent_a.isin(ids).all()
    assert procedural.rarity_vs_base.isna().all() and (procedural.watertight & procedural.one_piece).all()
    assert not set(procedural.parent_a) & {s.shape_id for s in every[:-12]}
    middle = [sorted(d.mesh.extents)[1] for d in out.kept if d.candidate.selected_by == "procedural"]
    assert np.allclose(middle, SurfaceSettings().size_m, rtol=1e-3)

    with pytest.raises(DataError, match="procedural pool: 4 shapes needed, the procedural corpus holds 0"):
        generate_pools(base, cfg, 0, some_rejected, 2, pools, controls=controls, procedural_ids=[])


def test_control_ratios_size_the_other_pools_by_their_own_ratios():
    """With targeted at 1:0.5, 1:1 and 1:2 and the other pools at 1:1 only (gqcnn.control_ratios), targeted holds
    2 B shapes and the random pool B."""
    base, cfg = make_base(4), GenerateParams(base_sizes=(4,), ratios=(0.0, 0.5, 1.0, 2.0))
    out = generate_pools(base, cfg, 0, some_rejected, 2, ("targeted", "random"), control_ratios=(1.0,))
    counts = out.index.pool.value_counts().to_dict()
    assert counts == {"targeted": 8, "random": 4}
