import numpy as np
import pytest
import torch
import trimesh

from graspaug.geometry.voxelize import fit_grid, voxelize_solid
from graspaug.io.checkpoints import CheckpointMismatch, load_autoencoder, save_autoencoder
from graspaug.nets.ae_critic import AEConfig, AutoEncoder, Critic, decode, encode
from graspaug.training.autoencoder import (
    AETrainConfig,
    critic_separation,
    phase_1_schedule,
    reconstruction_iou,
    train_ae_critic,
    train_autoencoder,
)

CPU = torch.device("cpu")


def train_settings(**overrides) -> AETrainConfig:
    """The default ``ae`` params' training settings with a few changed."""
    from dataclasses import replace

    from graspaug.pipeline.params.model import Params

    return replace(Params().ae.train, **overrides)


def primitive_meshes() -> list[trimesh.Trimesh]:
    """Eight real solid shapes (trimesh primitives), m."""
    c = trimesh.creation
    return [
        c.box(extents=(0.1, 0.06, 0.03)),
        c.icosphere(radius=0.05),
        c.cylinder(radius=0.03, height=0.1),
        c.capsule(height=0.06, radius=0.02),
        c.torus(major_radius=0.04, minor_radius=0.015),
        c.cone(radius=0.04, height=0.09),
        c.box(extents=(0.05, 0.05, 0.05)),
        c.annulus(r_min=0.02, r_max=0.045, height=0.03),
    ]


def primitive_grids(resolution: int) -> torch.Tensor:
    """The eight :func:`primitive_meshes` voxelized with the project's voxelizer: (8, 1, R, R, R) uint8 occupancy
    (the grids of ``output="occupancy"``, which the tests here set: the default decoder is ``sdf``)."""
    grids = [voxelize_solid(m.vertices, m.faces, fit_grid(m.bounds, resolution)) for m in primitive_meshes()]
    return torch.from_numpy(np.stack(grids)[:, None].astype(np.uint8))


def test_a_tiny_model_overfits_eight_shapes():
    torch.manual_seed(0)
    x = primitive_grids(16)
    ae = AutoEncoder(AEConfig(resolution=16, z_dim=32, base_width=8, top_width=32, output="occupancy"))
    cfg = train_settings(batch_size=8, epochs_ae=150, epochs_critic=0, lr_ae=3e-3, flips=False)
    train_autoencoder(ae, x, cfg, CPU, torch.Generator().manual_seed(0))
    assert reconstruction_iou(ae, x, CPU) > 0.9

    # the decoded sphere latent, and a sphere-box interpolation, mesh to closed one-piece surfaces
    from graspaug.geometry.from_voxels import clean_occupancy, mesh_from_occupancy

    z = encode(ae, x, CPU)
    for latent in (z[1], 0.5 * z[1] + 0.5 * z[0]):
        grid = clean_occupancy(decode(ae, latent[None], CPU)[0], 0.5, 1, 20, 0.9)
        assert grid.reason is None
        mesh = mesh_from_occupancy(grid.occupancy, 0.01, 10)
        assert mesh.is_watertight and len(mesh.split()) == 1 and mesh.volume > 0


def _train_twice_state(seed: int) -> dict[str, torch.Tensor]:
    torch.manual_seed(seed)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    tcfg = train_settings(batch_size=4, epochs_ae=2, epochs_critic=2)
    gen = torch.Generator().manual_seed(seed)
    train_autoencoder(ae, x, tcfg, CPU, gen)
    train_ae_critic(ae, critic, x, tcfg, CPU, gen)
    return {
        **{f"ae.{k}": v for k, v in ae.state_dict().items()},
        **{f"c.{k}": v for k, v in critic.state_dict().items()},
    }


def _phase_1_rates(**settings) -> list[float]:
    """The learning rate of each of phase 1's epochs under :func:`phase_1_schedule`."""
    cfg = train_settings(**settings)
    opt = torch.optim.Adam([torch.zeros(1, requires_grad=True)], lr=cfg.lr_ae)
    schedule, rates = phase_1_schedule(opt, cfg), []
    for _ in range(cfg.epochs_ae):
        rates.append(opt.param_groups[0]["lr"])
        opt.step()
        schedule.step()
    return rates


def test_the_cosine_schedule_falls_from_lr_ae_to_half_at_mid_training_and_constant_stays():
    cosine = _phase_1_rates(epochs_ae=10, lr_ae=1e-3, lr_schedule="cosine")
    assert [cosine[0], cosine[5]] == pytest.approx([1e-3, 5e-4])
    assert cosine == pytest.approx([1e-3 * 0.5 * (1 + np.cos(np.pi * e / 10)) for e in range(10)])
    assert set(_phase_1_rates(epochs_ae=10, lr_ae=1e-3)) == {1e-3}


def _phase_1_weights(epochs: int, schedule: str) -> dict[str, torch.Tensor]:
    torch.manual_seed(0)
    ae = AutoEncoder(AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy"))
    tcfg = train_settings(batch_size=4, epochs_ae=epochs, lr_schedule=schedule)
    train_autoencoder(ae, primitive_grids(16), tcfg, CPU, torch.Generator().manual_seed(0))
    return ae.state_dict()


def test_training_follows_the_schedule():
    """Epoch 0 runs at lr_ae under both schedules (the same weights after one epoch); later epochs differ."""
    one = _phase_1_weights(1, "constant"), _phase_1_weights(1, "cosine")
    assert all(torch.equal(one[0][k], one[1][k]) for k in one[0])
    three = _phase_1_weights(3, "constant"), _phase_1_weights(3, "cosine")
    assert not all(torch.equal(three[0][k], three[1][k]) for k in three[0])


def test_same_seed_gives_identical_weights():
    a, b = _train_twice_state(7), _train_twice_state(7)
    assert a.keys() == b.keys()
    assert all(torch.equal(a[k], b[k]) for k in a)
    c = _train_twice_state(8)
    assert not all(torch.equal(a[k], c[k]) for k in a)


def test_ae_critic_phase_reports_its_losses_and_trains_the_critic():
    torch.manual_seed(0)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    seen = []
    before = {k: v.clone() for k, v in critic.state_dict().items()}
    ae_before = {k: v.clone() for k, v in ae.state_dict().items()}
    tcfg = train_settings(batch_size=8, epochs_ae=0, epochs_critic=3, critic_warmup=1)
    rate = train_ae_critic(ae, critic, x, tcfg, CPU, torch.Generator().manual_seed(0), lambda e, m: seen.append(m))
    assert rate > 0 and len(seen) == 3
    assert not torch.equal(before["head.weight"], critic.state_dict()["head.weight"])
    assert not torch.equal(ae_before["encoder.fc.weight"], ae.state_dict()["encoder.fc.weight"])
    assert set(seen[0]) == {"loss_recon", "loss_reg", "loss_critic"}
    assert all(np.isfinite(v) for m in seen for v in m.values())


def _normalization_buffers(module: torch.nn.Module) -> dict[str, torch.Tensor]:
    return {k: v.clone() for k, v in module.state_dict().items() if "running_" in k or "num_batches_tracked" in k}


def test_phase_2_leaves_the_decoders_normalization_statistics_unchanged():
    """Interpolated latents (and phase 2 at all) never enter the decoder's BatchNorm statistics;
    its weights still learn."""
    torch.manual_seed(0)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    train_autoencoder(ae, x, train_settings(batch_size=4, epochs_ae=1), CPU, torch.Generator().manual_seed(0))
    stats_before = _normalization_buffers(ae.decoder)
    weights_before = ae.decoder.fc.weight.clone()
    encoder_stats_before = _normalization_buffers(ae.encoder)
    assert stats_before and encoder_stats_before
    train_ae_critic(
        ae,
        critic,
        x,
        train_settings(batch_size=4, epochs_critic=2, critic_warmup=0),
        CPU,
        torch.Generator().manual_seed(0),
    )
    stats_after = _normalization_buffers(ae.decoder)
    assert all(torch.equal(stats_before[k], stats_after[k]) for k in stats_before)
    assert not torch.equal(weights_before, ae.decoder.fc.weight)
    # the encoder sees real grids only: its statistics go on learning
    assert not all(torch.equal(encoder_stats_before[k], v) for k, v in _normalization_buffers(ae.encoder).items())


def _phase_2_weights(critic: Critic | None, lam: float) -> dict[str, torch.Tensor]:
    torch.manual_seed(3)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae = AutoEncoder(cfg)
    if critic is not None:
        critic = Critic(cfg)
    train_ae_critic(
        ae,
        critic,
        x,
        train_settings(batch_size=4, epochs_critic=2, critic_warmup=1, lam=lam),
        CPU,
        torch.Generator().manual_seed(3),
    )
    return ae.state_dict()


def test_the_control_arm_is_the_ae_critic_with_lambda_zero():
    """A critic trained beside the AE with λ = 0 changes nothing in the AE: the same weights as the
    critic-free control arm, bit for bit (same batches, flips, α draws); with λ > 0 it does."""
    control = _phase_2_weights(None, lam=0.5)  # critic=None ignores λ
    lam_zero = _phase_2_weights(
        Critic(AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")), lam=0.0
    )
    lam_half = _phase_2_weights(
        Critic(AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")), lam=0.5
    )
    assert all(torch.equal(control[k], lam_zero[k]) for k in control)
    assert not all(torch.equal(control[k], lam_half[k]) for k in control)


def test_critic_separation_puts_interpolants_on_the_positive_side():
    """A stand-in critic that scores how far a grid is from binary: real 0/1 grids score 0, the soft
    decodes of an untrained AE score high, so the AUC is 1 and the mean outputs are ordered."""
    torch.manual_seed(0)
    x = primitive_grids(16)
    ae = AutoEncoder(AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy"))

    class Softness(torch.nn.Module):
        def forward(self, v):
            return (0.5 - (v - 0.5).abs()).mean(dim=(1, 2, 3, 4))

    result = critic_separation(ae, Softness(), x, CPU)
    assert result["auc"] == 1.0
    assert result["real_mean"] == 0.0 < result["interp_mean"]
    assert 0.0 <= result["auc_vs_reconstructions"] <= 1.0


def test_checkpoint_roundtrip_and_mismatch(tmp_path):
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg).eval(), Critic(cfg)
    save_autoencoder(tmp_path / "m.pt", ae, critic, {"lr_ae": 1e-3})
    back, back_critic, params = load_autoencoder(tmp_path / "m.pt", cfg)
    assert params == {"lr_ae": 1e-3} and back_critic is not None
    for mine, theirs in ((ae, back), (critic, back_critic)):
        a, b = mine.state_dict(), theirs.state_dict()
        assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    x = primitive_grids(16)
    assert np.array_equal(encode(ae, x, CPU), encode(back, x, CPU))
    save_autoencoder(tmp_path / "again.pt", ae, critic, {"lr_ae": 1e-3})
    assert (tmp_path / "m.pt").read_bytes() == (tmp_path / "again.pt").read_bytes()  # same weights, same bytes
    with pytest.raises(CheckpointMismatch, match=r"trained with resolution=16 \(params: 32\)"):
        load_autoencoder(
            tmp_path / "m.pt", AEConfig(resolution=32, z_dim=16, base_width=4, top_width=16, output="occupancy")
        )


def primitive_fields(resolution: int, truncation: float = 3.0) -> torch.Tensor:
    """The eight :func:`primitive_meshes` as the voxelize stage grids them for a decoder of signed distances:
    (8, 1, R, R, R) float32 truncated signed distance / truncation."""
    from graspaug.geometry.sdf import truncated_distance_grid

    grid = lambda m: truncated_distance_grid(m.vertices, m.faces, fit_grid(m.bounds, resolution), truncation)  # noqa: E731
    return torch.from_numpy(np.stack([grid(m) for m in primitive_meshes()])[:, None] / np.float32(truncation))


def test_a_decoder_of_signed_distances_learns_eight_shapes_and_meshes_them():
    """``output: sdf``: the same network learns signed distances (tanh out, L1 near the surface) to within half a voxel
    near the surfaces; its decodes mesh by marching cubes at 0 with no opening or smoothing."""
    from graspaug.geometry.sdf import mesh_decoded_field
    from graspaug.geometry.settings import DecodeSettings

    torch.manual_seed(0)
    x = primitive_fields(16)
    assert x.dtype == torch.float32 and x.min() >= -1 and x.max() <= 1
    cfg = AEConfig(resolution=16, z_dim=32, base_width=8, top_width=32, output="sdf")
    ae = AutoEncoder(cfg)
    losses = []
    tcfg = train_settings(batch_size=8, epochs_ae=150, epochs_critic=0, lr_ae=3e-3, flips=False)
    train_autoencoder(ae, x, tcfg, CPU, torch.Generator().manual_seed(0), lambda e, m: losses.append(m["loss_recon"]))
    assert losses[-1] < 0.25 * losses[0]
    assert reconstruction_iou(ae, x, CPU) > 0.85  # the inside: a negative distance
    z = encode(ae, x, CPU)
    fields = decode(ae, z, CPU)
    assert fields.shape == (8, 16, 16, 16) and np.abs(fields).max() <= 1
    grid, mesh, reason = mesh_decoded_field(fields[0], 0.01, cfg.truncation, DecodeSettings())
    assert reason is None and mesh.is_watertight and mesh.volume > 0
    assert np.array_equal(grid.occupancy, fields[0] < 0)
    near = np.abs(x[:, 0].numpy()) < 1  # within the truncation of a surface
    error = np.abs(fields - x[:, 0].numpy())[near].mean() * cfg.truncation  # voxels
    assert error < 0.5, error  # the surface placed between voxel centres, not on them

    # generate's batch runner meshes interpolated decodes of distances the same way
    from graspaug.augment.candidates import Candidate
    from graspaug.augment.decode import mesh_batches
    from graspaug.augment.pools import BaseSet

    base = BaseSet(np.arange(8).astype(str), z, np.zeros(8), np.zeros(8), np.full(8, 0.01))
    run_batch = mesh_batches(ae, CPU, base, DecodeSettings(), 1, "test")
    decoded = run_batch([Candidate(1, 6, 0.3, "random"), Candidate(0, 6, 0.5, "random")])
    meshes = [d for d in decoded if d.mesh is not None]
    assert meshes and all(d.mesh.is_watertight for d in meshes), [d.reason for d in decoded]

    # the phase-2 losses take the same grids (the critic sees tanh decodes and normalized distances)
    seen = []
    tcfg = train_settings(batch_size=8, epochs_ae=0, epochs_critic=2, critic_warmup=1)
    train_ae_critic(ae, Critic(cfg), x, tcfg, CPU, torch.Generator().manual_seed(0), lambda e, m: seen.append(m))
    assert all(np.isfinite(v) for m in seen for v in m.values())


def test_an_occupancy_checkpoint_keeps_its_old_layout_and_a_decoder_of_distances_says_what_it_is(tmp_path):
    from graspaug.io.checkpoints import SDF_KEYS

    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    save_autoencoder(tmp_path / "occupancy.pt", AutoEncoder(cfg), None, {})
    state = torch.load(tmp_path / "occupancy.pt", weights_only=True)
    assert not set(SDF_KEYS) & set(state["config"])  # the file as before signed distances existed
    sdf = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="sdf")
    save_autoencoder(tmp_path / "sdf.pt", AutoEncoder(sdf), None, {})
    assert load_autoencoder(tmp_path / "sdf.pt", sdf)[0].cfg.output == "sdf"
    with pytest.raises(CheckpointMismatch, match=r"output=occupancy \(params: sdf\)"):
        load_autoencoder(tmp_path / "occupancy.pt", sdf)


def test_the_paper_profiles_critic_does_not_diverge_at_64():
    """The paper profile's AE-Critic warm-up at its own sizes (64³, widths 64…512), three critic steps on the CPU
    through the training loop: the critic loss stays finite and within 10× of its first step. With a critic learning
    rate of 1e-3 it went 0.06 → 555 → 1.7e6: Adam moves every weight by about the learning rate on its first steps,
    and a unit summing 32,768 inputs (the paper's 512 × 4³ map) moves by thousands of times that."""
    import dataclasses

    import trimesh

    from graspaug.geometry.voxelize import fit_grid, voxelize_solid
    from graspaug.nets.ae_critic import AutoEncoder, Critic
    from graspaug.pipeline.params.profiles import profile_params
    from graspaug.training.autoencoder import train_ae_critic

    params = profile_params("paper")
    net = params.ae.net
    assert (net.resolution, net.widths[-1]) == (64, 512)
    meshes = [trimesh.creation.box((0.03, 0.05, 0.08)), trimesh.creation.capsule(height=0.05, radius=0.02)]
    grids = [voxelize_solid(m.vertices, m.faces, fit_grid(m.bounds, 64, 1)) for m in meshes]
    voxels = torch.from_numpy(np.stack(grids)[:, None])
    train = dataclasses.replace(params.ae.train, epochs_critic=3, critic_warmup=3, batch_size=2)  # 3 critic steps
    torch.manual_seed(0)
    losses = []
    train_ae_critic(
        AutoEncoder(net),
        Critic(net),
        voxels,
        train,
        torch.device("cpu"),
        torch.Generator().manual_seed(0),
        lambda epoch, logs: losses.append(logs["loss_critic"]),
    )
    assert len(losses) == 3 and np.isfinite(losses).all() and max(losses) <= 10 * losses[0], losses


def _bfloat16_run(tmp_path, name: str) -> tuple[dict, bytes]:
    """Two steps of each phase (batches of 4 of the 8 primitives) under bfloat16: the checkpoint's
    train_params and its bytes."""
    from graspaug.training.autoencoder import checkpoint_params

    torch.manual_seed(0)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    tcfg = train_settings(batch_size=4, epochs_ae=1, epochs_critic=1, critic_warmup=0, precision="bfloat16")
    gen = torch.Generator().manual_seed(0)
    train_autoencoder(ae, x, tcfg, CPU, gen)
    train_ae_critic(ae, critic, x, tcfg, CPU, gen)
    assert all(p.dtype == torch.float32 for p in [*ae.parameters(), *critic.parameters()])  # weights stay float32
    assert encode(ae, x, CPU).dtype == np.float32
    path = tmp_path / f"{name}.pt"
    save_autoencoder(path, ae, critic, checkpoint_params(tcfg, CPU))
    return load_autoencoder(path, cfg)[2], path.read_bytes()


def test_an_autoencoder_trains_under_bfloat16_and_its_checkpoint_says_so(tmp_path):
    """Both phases under bfloat16 autocast: float32 weights, the checkpoint's train_params name bfloat16, and the
    same seed gives the same bytes; the weights differ from float32 training (the setting acts)."""
    params, data = _bfloat16_run(tmp_path, "a")
    assert params["precision"] == "bfloat16"
    assert _bfloat16_run(tmp_path, "b")[1] == data  # same precision, same bytes

    torch.manual_seed(0)
    x = primitive_grids(16)
    cfg = AEConfig(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    tcfg = train_settings(batch_size=4, epochs_ae=1, epochs_critic=1, critic_warmup=0, precision="float32")
    gen = torch.Generator().manual_seed(0)
    train_autoencoder(ae, x, tcfg, CPU, gen)
    train_ae_critic(ae, critic, x, tcfg, CPU, gen)
    half = torch.load(tmp_path / "a.pt", weights_only=True)["autoencoder"]
    assert any(not torch.equal(half[k], v) for k, v in ae.state_dict().items())


def test_checkpoints_record_precision_as_resolved_on_the_device():
    """``auto`` (the default) is written as what it became here, with the reason; float32 as written."""
    from graspaug.device import has_native_bfloat16
    from graspaug.training.autoencoder import checkpoint_params

    auto = checkpoint_params(train_settings(precision="auto"), CPU)["precision"]
    native = has_native_bfloat16(CPU)
    assert auto == (
        "bfloat16 (auto: native on this CPU)" if native else "float32 (auto: no native bfloat16 on this CPU)"
    )
    assert checkpoint_params(train_settings(), CPU)["precision"] == auto  # the default is auto
    assert checkpoint_params(train_settings(precision="float32"), CPU)["precision"] == "float32"
