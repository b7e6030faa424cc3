"""Training a GQ-CNN: metrics, noise, and learning a separable toy set."""

import numpy as np
import pytest
import torch

from graspaug.nets.gqcnn import GQCNN, GQCNNConfig
from graspaug.training.gqcnn import (
    GraspArrays,
    NoiseSettings,
    TrainSettings,
    augment,
    classification_metrics,
    cosine_lr,
    predict,
    train_gqcnn,
)


def test_average_precision_matches_a_hand_computed_case():
    # ranked: 1 (pos), 0.8 (neg), 0.7 (pos), 0.1 (neg): precision at the positives 1/1 and 2/3
    scores = classification_metrics(np.array([1, 0, 1, 0]), np.array([0.9, 0.8, 0.7, 0.1]))
    assert scores["ap"] == pytest.approx((1 + 2 / 3) / 2)
    assert scores["accuracy"] == pytest.approx(0.75)  # 0.8 > 0.5 is the one mistake
    assert scores["roc_auc"] == pytest.approx(0.75)  # 3 of 4 (pos, neg) pairs ordered right
    assert scores["positive_share"] == 0.5 and scores["datapoints"] == 4
    one_class = classification_metrics(np.zeros(3), np.array([0.1, 0.2, 0.3]))
    assert one_class["ap"] is None and one_class["roc_auc"] is None


def test_augmentation_noise_and_symmetries():
    gen = torch.Generator().manual_seed(0)
    images = torch.rand(2000, 1, 8, 8) * 0.1 + 0.6
    z = torch.rand(2000) * 0.1 + 0.6
    sym, same_z = augment(images, z, NoiseSettings(gamma_shape=0, gp_prob=0, symmetrize=True), gen)
    torch.testing.assert_close(same_z, z)
    # turns and flips only move pixels
    torch.testing.assert_close(sym.flatten(1).sort(dim=1).values, images.flatten(1).sort(dim=1).values)
    # a 180° turn is both flips, so the 8 equally likely combinations give 4 distinct images: 3/4 change
    changed = float((sym != images).flatten(1).any(1).float().mean())
    assert 0.72 < changed < 0.78
    scaled, scaled_z = augment(
        torch.ones(4000, 1, 4, 4),
        torch.full((4000,), 2.0),
        NoiseSettings(gamma_shape=1000, gp_prob=0, symmetrize=False),
        gen,
    )
    scaled = scaled[:, 0, 0, 0]
    assert float(scaled.mean()) == pytest.approx(1.0, abs=0.003) and float(scaled.std()) == pytest.approx(
        1000**-0.5, rel=0.1
    )
    torch.testing.assert_close(scaled_z, 2 * scaled)  # image and gripper depth scaled together
    field, _ = augment(
        torch.zeros(2000, 1, 32, 32),
        torch.zeros(2000),
        NoiseSettings(gamma_shape=0, gp_prob=0.5, gp_sigma=0.005, symmetrize=False),
        gen,
    )
    noisy = field.flatten(1).abs().amax(1) > 0
    assert 0.45 < float(noisy.float().mean()) < 0.55
    assert 0.003 < float(field[noisy].std()) < 0.006  # the grid's sigma, smoothed by the upsampling
    a = augment(images, z, NoiseSettings(), torch.Generator().manual_seed(3))
    b = augment(images, z, NoiseSettings(), torch.Generator().manual_seed(3))
    torch.testing.assert_close(a, b)


def toy_set(n: int, rng: np.random.Generator) -> GraspArrays:
    """Positives: an object (2 cm nearer than the table) under the gripper; negatives: the
    object off to one side. Table depth, object size and position vary."""
    images = np.full((n, 32, 32), 0.7, np.float32) + rng.uniform(-0.02, 0.02, (n, 1, 1)).astype(np.float32)
    labels = rng.random(n) < 0.3
    for i in range(n):
        half = rng.integers(3, 6)
        cx = 16 if labels[i] else rng.choice([5, 27])
        cy = 16 + rng.integers(-3, 4)
        images[i, cy - half : cy + half, cx - half : cx + half] -= 0.02
    return GraspArrays(images, (images[:, 16, 16] + 0.01).astype(np.float32), labels.astype(np.uint8))


def test_a_tiny_gqcnn_learns_a_separable_toy_set():
    rng = np.random.default_rng(0)
    train, test = toy_set(1500, rng), toy_set(500, rng)
    torch.manual_seed(0)
    net = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4))
    logged = []
    settings = TrainSettings(epochs=1.0, min_steps=150, max_steps=150, batch_size=32, lr=0.01, evals=3)
    speed = train_gqcnn(
        net,
        train,
        test,
        settings,
        torch.device("cpu"),
        torch.Generator().manual_seed(0),
        lambda step, m: logged.append((step, m)),
    )
    assert [step for step, _ in logged] == [50, 100, 150] and speed["steps"] == 150
    assert set(logged[0][1]) == {"loss", "train_accuracy", "lr", "val_accuracy", "val_ap"}
    assert logged[-1][1]["loss"] < logged[0][1]["loss"]
    assert logged[-1][1]["lr"] == pytest.approx(0.01 * 0.01, rel=1e-6)  # annealed to final_lr of the start
    scores = classification_metrics(test.labels, predict(net, test, torch.device("cpu")))
    assert scores["ap"] > 0.95
    # the kept weights are those of the best validation evaluation
    best = max(logged, key=lambda entry: entry[1]["val_ap"])
    assert speed["best_step"] == best[0] and scores["ap"] == pytest.approx(best[1]["val_ap"])
    assert speed["samples_per_second"] > 0


def test_the_step_budget_follows_the_training_set():
    settings = TrainSettings(epochs=4.0, min_steps=100, max_steps=1000, batch_size=100)
    assert settings.steps_for(1000) == 100 and settings.steps_for(5000) == 200 and settings.steps_for(50_000) == 1000
    assert (
        cosine_lr(0, 11, 0.01) == 1.0
        and cosine_lr(10, 11, 0.01) == pytest.approx(0.01)
        and cosine_lr(5, 11, 0.01) == pytest.approx(0.505)
    )
    with pytest.raises(ValueError, match="min_steps"):
        TrainSettings(min_steps=10, max_steps=5)


def test_depth_minus_gripper_input_sees_heights_relative_to_the_gripper():
    images, z = torch.full((3, 1, 32, 32), 0.7), torch.tensor([0.6, 0.65, 0.7])
    net = GQCNN(GQCNNConfig(filters=4, fc=8, pose_fc=4, image_input="depth_minus_gripper"))
    assert torch.allclose(net.image_input(images, z)[:, 0, 0, 0], torch.tensor([0.1, 0.05, 0.0]))
    assert torch.equal(
        GQCNN(GQCNNConfig(filters=4, fc=8, pose_fc=4, image_input="depth")).image_input(images, z), images
    )


def test_averaged_weights_are_the_exponential_moving_average_of_the_trained_ones():
    rng = np.random.default_rng(1)
    data = toy_set(256, rng)
    cfg = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    torch.manual_seed(0)
    init = GQCNN(cfg).state_dict()

    def weights(steps: int, decay: float) -> dict[str, torch.Tensor]:
        net = GQCNN(cfg)
        net.load_state_dict(init)
        settings = TrainSettings(min_steps=steps, max_steps=steps, batch_size=32, evals=1, ema_decay=decay)
        train_gqcnn(net, data, None, settings, torch.device("cpu"), torch.Generator().manual_seed(5), progress=False)
        return {k: v.detach().clone() for k, v in net.state_dict().items()}

    # the first step's weights are the same in a 1- and a 2-step run (the cosine starts at 1 in both)
    w1, w2, averaged = weights(1, 0.0), weights(2, 0.0), weights(2, 0.9)
    for name in w2:
        torch.testing.assert_close(averaged[name], 0.9 * w1[name] + 0.1 * w2[name])
    assert any(
        not torch.equal(averaged[name], w2[name]) for name in w2
    )  # the kept weights are the average, not the last


def test_bfloat16_mixed_precision_learns_and_keeps_float32_weights():
    rng = np.random.default_rng(2)
    train, test = toy_set(1500, rng), toy_set(500, rng)
    torch.manual_seed(0)
    init = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4)).state_dict()

    def trained(precision: str) -> GQCNN:
        net = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4))
        net.load_state_dict(init)
        settings = TrainSettings(min_steps=150, max_steps=150, batch_size=32, lr=0.01, evals=1, precision=precision)
        train_gqcnn(net, train, None, settings, torch.device("cpu"), torch.Generator().manual_seed(0), progress=False)
        return net

    half, again, full = trained("bfloat16"), trained("bfloat16"), trained("float32")
    assert all(p.dtype == torch.float32 for p in half.parameters())
    assert all(
        torch.equal(a, b) for a, b in zip(half.state_dict().values(), again.state_dict().values())
    )  # same seed, same weights
    assert any(
        not torch.equal(a, b) for a, b in zip(half.state_dict().values(), full.state_dict().values())
    )  # the setting acts
    probability = predict(half, test, torch.device("cpu"))
    assert probability.dtype == np.float32 and classification_metrics(test.labels, probability)["ap"] > 0.95


def test_a_member_trained_in_a_stack_ends_as_it_would_alone():
    """Three members trained at once (one model) against the same member trained alone from the same
    initial weights and noise stream: after 20 steps each weight tensor agrees within 1% (of its norm)
    and the validation AP and predictions within 1e-3. Only float rounding differs (the grouped layers
    sum in another order), which training then amplifies: the tolerance is not zero."""
    from graspaug.training.gqcnn import train_members

    rng = np.random.default_rng(0)
    train, val = toy_set(1500, rng), toy_set(500, rng)
    config = GQCNNConfig(filters=8, fc=32, pose_fc=4)
    torch.manual_seed(0)
    inits = [GQCNN(config).state_dict() for _ in range(3)]

    def fresh(m: int) -> GQCNN:
        net = GQCNN(config)
        net.load_state_dict(inits[m])
        return net

    settings = TrainSettings(min_steps=20, max_steps=20, batch_size=64, evals=2, precision="float32")  # its rounding
    cpu, logged = torch.device("cpu"), []
    members = [fresh(m) for m in range(3)]
    gens = [torch.Generator().manual_seed(10 + m) for m in range(3)]
    fits = train_members(members, train, val, settings, cpu, gens, lambda m, step, _: logged.append((m, step)))
    assert sorted(logged) == [(m, step) for m in range(3) for step in (10, 20)]
    for m in range(3):
        alone = fresh(m)
        fit = train_gqcnn(alone, train, val, settings, cpu, torch.Generator().manual_seed(10 + m), progress=False)
        for name, weight in alone.state_dict().items():
            assert float((members[m].state_dict()[name] - weight).norm()) <= 0.01 * float(weight.norm()), name
        assert fits[m]["best_step"] == fit["best_step"]
        assert fits[m]["best_val_ap"] == pytest.approx(fit["best_val_ap"], abs=1e-3)
        np.testing.assert_allclose(predict(members[m], val, cpu), predict(alone, val, cpu), atol=1e-3)
    # the members differ: each has its own initial weights and noise
    assert not np.allclose(predict(members[0], val, cpu), predict(members[1], val, cpu), atol=1e-3)


def test_auto_precision_trains_as_the_precision_it_resolves_to():
    """``auto`` gives the weights of bfloat16 where this CPU has it natively, of float32 elsewhere, bit for bit."""
    from graspaug.device import resolve_precision

    rng = np.random.default_rng(3)
    train = toy_set(300, rng)
    torch.manual_seed(0)
    init = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4)).state_dict()

    def trained(precision: str) -> dict[str, torch.Tensor]:
        net = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4))
        net.load_state_dict(init)
        settings = TrainSettings(min_steps=5, max_steps=5, batch_size=32, evals=1, precision=precision)
        train_gqcnn(net, train, None, settings, torch.device("cpu"), torch.Generator().manual_seed(0), progress=False)
        return net.state_dict()

    resolved = resolve_precision("auto", torch.device("cpu")).dtype
    other = {"bfloat16": "float32", "float32": "bfloat16"}[resolved]
    auto, same, different = trained("auto"), trained(resolved), trained(other)
    assert all(torch.equal(auto[k], same[k]) for k in auto)
    assert any(not torch.equal(auto[k], different[k]) for k in auto)
