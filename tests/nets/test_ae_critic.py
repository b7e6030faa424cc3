import pytest
import torch

from graspaug.nets.ae_critic import (
    AEConfig,
    AutoEncoder,
    Critic,
    autoencoder_loss,
    critic_loss,
    folded_alpha,
    reversed_partners,
)


@pytest.mark.parametrize(("resolution", "base", "top"), [(16, 8, 32), (32, 8, 32), (64, 4, 32)])
def test_output_shapes(resolution, base, top):
    cfg = AEConfig(resolution=resolution, z_dim=128, base_width=base, top_width=top)
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    x = (torch.rand(2, 1, resolution, resolution, resolution) > 0.5).float()
    z = ae.encoder(x)
    assert z.shape == (2, 128)
    assert ae.decoder(z).shape == x.shape
    assert critic(x).shape == (2,)
    assert len(cfg.widths) == cfg.n_down + 1 and cfg.widths[-1] == top
    assert ae.encoder.fc.in_features == top * 4**3


def test_paper_profile_layout():
    """At 64³ with the paper's widths: five 4³ conv layers down to 512×4×4×4, flatten 32768 → 128."""
    cfg = AEConfig(resolution=64, z_dim=128, base_width=64, top_width=512)
    assert cfg.widths == [64, 128, 256, 512, 512]
    enc = AutoEncoder(cfg).encoder
    convs = [m for m in enc.features if isinstance(m, torch.nn.Conv3d)]
    assert len(convs) == 5 and all(c.kernel_size == (4, 4, 4) for c in convs)
    assert [c.stride[0] for c in convs] == [2, 2, 2, 2, 1]
    assert enc.fc.in_features == 32768 and enc.fc.out_features == 128


def test_bad_resolution():
    with pytest.raises(ValueError, match="power of two"):
        AEConfig(resolution=48)


def test_alpha_zero_and_one_decode_to_the_two_reconstructions():
    torch.manual_seed(0)
    ae = AutoEncoder(AEConfig(resolution=16, base_width=4, top_width=16)).eval()
    x = (torch.rand(2, 1, 16, 16, 16) > 0.5).float()
    with torch.no_grad():
        z = ae.encoder(x)
        recon = ae.decoder(z)
        a0 = ae.interpolate(z[:1], z[1:], torch.tensor([0.0]))
        a1 = ae.interpolate(z[:1], z[1:], torch.tensor([1.0]))
        half = ae.interpolate(z[:1], z[1:], torch.tensor([0.5]))
        midpoint = ae.decoder(0.5 * (z[:1] + z[1:]))
    assert torch.allclose(a0, recon[:1], atol=1e-6)
    assert torch.allclose(a1, recon[1:], atol=1e-6)
    assert torch.allclose(half, midpoint, atol=1e-6)


def constant_critic(value: float, cfg: AEConfig) -> Critic:
    """A real Critic whose weights make it output ``value`` for any input."""
    critic = Critic(cfg).eval()
    with torch.no_grad():
        for p in critic.parameters():
            p.zero_()
        critic.head.bias.fill_(value)
    return critic


def test_critic_loss_matches_eq_1_on_a_hand_made_batch():
    """C ≡ 0.3, α = (0.1, 0.4): ‖C − α‖² = ((0.2)² + (0.1)²)/2 = 0.025, ‖C(mix)‖² = 0.09, L_C = 0.115."""
    cfg = AEConfig(resolution=16, base_width=4, top_width=8)
    critic = constant_critic(0.3, cfg)
    x = torch.ones(2, 1, 16, 16, 16)
    loss = critic_loss(critic, x, x * 0.5, x * 0.25, torch.tensor([0.1, 0.4]), gamma=0.2)
    assert loss.item() == pytest.approx(0.115, abs=1e-7)


def test_critic_loss_feeds_the_gamma_mix_as_the_real_input():
    """A critic that reads the mean occupancy: C(γx + (1 − γ)x̂) = γ·1 + (1 − γ)·0 = γ."""
    cfg = AEConfig(resolution=16, base_width=4, top_width=8)

    class MeanCritic(torch.nn.Module):
        def forward(self, v):
            return v.mean(dim=(1, 2, 3, 4))

    x, x_hat = torch.ones(3, 1, 16, 16, 16), torch.zeros(3, 1, 16, 16, 16)
    alpha = torch.tensor([0.0, 0.25, 0.5])
    x_alpha = alpha.view(-1, 1, 1, 1, 1).expand(3, 1, 16, 16, 16)  # C(x̂_α) = α exactly
    loss = critic_loss(MeanCritic(), x, x_hat, x_alpha, alpha, gamma=0.2)
    assert loss.item() == pytest.approx(0.2**2, abs=1e-7)
    del cfg


def test_autoencoder_loss_matches_eq_2():
    logits = torch.zeros(1, 1, 2, 2, 2)  # sigmoid 0.5 everywhere: BCE = ln 2
    x = torch.ones(1, 1, 2, 2, 2)
    total, bce, reg = autoencoder_loss(logits, x, torch.tensor([0.2, 0.4]), lam=0.5)
    assert bce.item() == pytest.approx(0.693147, abs=1e-6)
    assert reg.item() == pytest.approx((0.04 + 0.16) / 2)
    assert total.item() == pytest.approx(0.693147 + 0.5 * 0.1, abs=1e-6)


def test_critic_output_for_a_grid_does_not_depend_on_the_rest_of_the_batch():
    """No batch statistics: the same grid scores the same in an all-real, a mixed or a one-grid batch, in train mode."""
    torch.manual_seed(0)
    cfg = AEConfig(resolution=16, base_width=4, top_width=16)
    critic = Critic(cfg).train()
    real = (torch.rand(4, 1, 16, 16, 16) > 0.6).float()
    soft = torch.rand(4, 1, 16, 16, 16)  # interpolant-like: occupancy probabilities
    with torch.no_grad():
        alone = critic(real[:1])
        among_real = critic(real)[:1]
        among_soft = critic(torch.cat([real[:1], soft]))[:1]
    assert torch.allclose(alone, among_real, atol=1e-6) and torch.allclose(alone, among_soft, atol=1e-6)
    assert not any(isinstance(m, torch.nn.modules.batchnorm._NormBase) for m in critic.modules())


@pytest.mark.parametrize("batch_size", range(2, 20))
def test_the_partner_is_never_the_sample_itself(batch_size):
    partner = reversed_partners(batch_size)
    assert partner.shape == (batch_size,)
    assert not torch.any(partner == torch.arange(batch_size))
    assert partner.min() >= 0 and partner.max() < batch_size
    if batch_size % 2 == 0:  # ACAI's reversed batch
        assert torch.equal(partner, torch.arange(batch_size).flip(0))


def test_partners_need_two_samples():
    with pytest.raises(ValueError, match="at least 2"):
        reversed_partners(1)


def test_folded_alpha_covers_zero_to_one_half_uniformly():
    alpha = folded_alpha(20000, torch.Generator().manual_seed(0))
    assert alpha.min() >= 0 and alpha.max() <= 0.5
    assert alpha.mean().item() == pytest.approx(0.25, abs=0.005)  # U(0, 0.5): mean 0.25
    assert (alpha < 0.25).float().mean().item() == pytest.approx(0.5, abs=0.01)


def test_with_lambda_zero_the_critic_term_sends_no_gradient_to_the_autoencoder():
    torch.manual_seed(0)
    cfg = AEConfig(resolution=16, base_width=4, top_width=16, output="occupancy")
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    x = (torch.rand(4, 1, 16, 16, 16) > 0.6).float()

    def grads(lam: float, with_critic: bool) -> list[torch.Tensor]:
        z = ae.encoder(x)
        recon = ae.decoder(z)
        c_interp = (
            critic(torch.sigmoid(ae.interpolate(z, z[reversed_partners(4)], torch.full((4,), 0.3))))
            if with_critic
            else None
        )
        loss, _, _ = autoencoder_loss(recon, x, c_interp, lam)
        return torch.autograd.grad(loss, list(ae.parameters()), allow_unused=True)

    bce_only = grads(0.0, with_critic=False)
    lam_zero = grads(0.0, with_critic=True)
    lam_half = grads(0.5, with_critic=True)
    assert all(torch.equal(a, b) for a, b in zip(bce_only, lam_zero))
    assert not all(torch.equal(a, b) for a, b in zip(bce_only, lam_half))  # the test can fail: λ > 0 does move them
