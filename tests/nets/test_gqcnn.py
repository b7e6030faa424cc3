"""The GQ-CNN network: shapes, layer sizes, normalization kept in the model."""

import pytest
import torch

from graspaug.nets.gqcnn import GQCNN, GQCNNConfig


@pytest.mark.parametrize("pool", [True, False])
def test_output_shapes_and_layer_sizes(pool):
    net = GQCNN(GQCNNConfig(filters=8, fc=32, pose_fc=4, pool_after_conv2=pool))
    logits = net(torch.rand(5, 1, 32, 32) + 0.5, torch.rand(5) + 0.5)
    assert logits.shape == (5, 2)
    side = 8 if pool else 16
    assert net.fc3.in_features == 8 * side * side and net.fc3.out_features == 32
    assert net.pc1.out_features == 4 and net.fc4_pose.in_features == 4 and net.fc5.out_features == 2
    p = net.success_probability(torch.rand(3, 1, 32, 32), torch.rand(3))
    assert p.shape == (3,) and torch.all((p >= 0) & (p <= 1))


def test_dexnet_widths_and_normalization_in_the_model():
    net = GQCNN(GQCNNConfig(filters=64, fc=1024))  # Dex-Net 2.0 (2018 config) widths
    assert [net.conv1_1.kernel_size, net.conv1_2.kernel_size, net.conv2_1.kernel_size] == [(7, 7), (5, 5), (3, 3)]
    assert net.conv1_1.out_channels == 64 and net.fc3.out_features == 1024 and net.fc4_image.out_features == 1024
    assert net.lrn.size == 5 and net.lrn.alpha == pytest.approx(1e-4) and net.lrn.beta == 0.75 and net.lrn.k == 1.0
    images, z = torch.rand(4, 1, 32, 32) * 0.05 + 0.65, torch.rand(4) * 0.05 + 0.65
    before = net(images, z)
    net.set_normalization(0.7, 0.02, 0.68, 0.03)
    assert not torch.allclose(before, net(images, z))
    state = net.state_dict()
    assert float(state["image_mean"]) == pytest.approx(0.7) and float(state["z_std"]) == pytest.approx(0.03)
    again = GQCNN(net.config)
    again.load_state_dict(state)
    assert torch.allclose(again(images, z), net(images, z))
    with pytest.raises(ValueError, match="divisible"):
        GQCNNConfig(image_size=30)


@pytest.mark.parametrize("size", [3, 4, 5])
def test_local_response_norm_equals_torchs(size):
    from graspaug.nets.gqcnn import LocalResponseNorm

    x = torch.randn(3, 7, 5, 6, dtype=torch.float64)
    expected = torch.nn.LocalResponseNorm(size, alpha=0.3, beta=0.75, k=1.0)(x)
    torch.testing.assert_close(
        LocalResponseNorm(size, alpha=0.3, beta=0.75, k=1.0)(x), expected, rtol=1e-12, atol=1e-12
    )


def test_an_ensemble_averages_its_members_and_survives_a_checkpoint(tmp_path):
    from graspaug.io.checkpoints import read_gqcnn, save_gqcnn
    from graspaug.nets.gqcnn import GQCNNEnsemble

    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    torch.manual_seed(0)
    members = [GQCNN(config).eval() for _ in range(3)]
    ensemble = GQCNNEnsemble(members).eval()
    images, z = torch.rand(6, 1, 32, 32) * 0.05 + 0.65, torch.rand(6) * 0.05 + 0.65
    each = torch.stack([m.success_probability(images, z) for m in members])
    assert not torch.allclose(each[0], each[1])  # the members differ
    torch.testing.assert_close(ensemble.success_probability(images, z), each.mean(0))
    torch.testing.assert_close(
        torch.softmax(ensemble(images, z), dim=1)[:, 1], each.mean(0)
    )  # what export_model traces
    assert ensemble.describe()["members"] == 3 and ensemble.describe()["parameters"] == 3 * sum(
        p.numel() for p in members[0].parameters()
    )
    save_gqcnn(tmp_path / "model.pt", ensemble, {"pool": "targeted"}, None)
    loaded, card = read_gqcnn(tmp_path / "model.pt")
    assert isinstance(loaded, GQCNNEnsemble) and len(loaded.members) == 3 and card is None
    torch.testing.assert_close(loaded.success_probability(images, z), each.mean(0))
    from graspaug.planning import export_model

    export_model(tmp_path / "model.pt", tmp_path / "export")  # TorchScript of the ensemble's P(success)
    torch.testing.assert_close(torch.jit.load(str(tmp_path / "export" / "model.ts"))(images, z), each.mean(0))
    save_gqcnn(tmp_path / "single.pt", members[0], {}, None)  # a single network stays a GQCNN
    assert type(read_gqcnn(tmp_path / "single.pt")[0]) is GQCNN
    with pytest.raises(ValueError, match="one config"):
        GQCNNEnsemble([GQCNN(config), GQCNN(GQCNNConfig(filters=8, fc=8, pose_fc=4))])


@pytest.mark.parametrize("image_input", ["depth_minus_gripper", "depth"])
def test_a_stack_computes_what_each_member_computes_and_gives_their_weights_back(image_input):
    from graspaug.nets.gqcnn import GQCNNStack

    config = GQCNNConfig(filters=4, fc=8, pose_fc=4, image_input=image_input)
    torch.manual_seed(0)
    members = [GQCNN(config) for _ in range(3)]
    for m, net in enumerate(members):
        net.set_normalization(0.6 + 0.01 * m, 0.02, 0.62, 0.03 + 0.01 * m)
    images, z = torch.rand(3, 5, 1, 32, 32) * 0.05 + 0.6, torch.rand(3, 5) * 0.05 + 0.6
    stack = GQCNNStack(members)
    each = torch.stack([net(images[m], z[m]) for m, net in enumerate(members)])
    torch.testing.assert_close(stack(images, z), each, rtol=1e-4, atol=1e-5)
    (stack(images, z)[1].sum()).backward()  # member 1's loss moves member 1's filters only
    c = config.filters
    grad = stack.conv1_2_weight.grad
    assert grad[c : 2 * c].abs().sum() > 0 and grad[:c].abs().sum() == 0 and grad[2 * c :].abs().sum() == 0
    with torch.no_grad():
        stack.fc5_bias[2] += 1.0
    copies = [GQCNN(config) for _ in range(3)]
    for k, copy in enumerate(copies):
        copy.load_state_dict(stack.member_state(k))
    torch.testing.assert_close(copies[2].fc5.bias, members[2].fc5.bias + 1.0)
    torch.testing.assert_close(copies[0](images[0], z[0]), members[0](images[0], z[0]))
    with pytest.raises(ValueError, match="one config"):
        GQCNNStack([GQCNN(config), GQCNN(GQCNNConfig(filters=8, fc=8, pose_fc=4))])
