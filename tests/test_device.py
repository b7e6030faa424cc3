"""The process setting every stage makes (freed tensors are reused, not faulted in again) and
what the device computes natively."""

import subprocess
import sys

import pytest

STEPS = """
import resource, sys, torch, torch.nn.functional as F
if sys.argv[1] == "keep":
    from graspaug.device import keep_freed_memory
    assert keep_freed_memory() and keep_freed_memory()  # idempotent
from graspaug.nets.gqcnn import GQCNN, GQCNNConfig
torch.manual_seed(0)
net = GQCNN(GQCNNConfig())
opt = torch.optim.SGD(net.parameters(), lr=0.01)
images, z, labels = torch.rand(128, 1, 32, 32), torch.rand(128), torch.randint(0, 2, (128,))
def step():
    loss = F.cross_entropy(net(images, z), labels)
    opt.zero_grad()
    loss.backward()
    opt.step()
for _ in range(3):
    step()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(5):
    step()
print((resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 5)
"""


def faults_per_step(mode: str) -> float:
    out = subprocess.run([sys.executable, "-c", STEPS, mode], check=True, capture_output=True, text=True)
    return float(out.stdout.split()[-1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_a_training_step_reuses_freed_memory():
    plain, kept = faults_per_step("plain"), faults_per_step("keep")
    assert kept < plain / 4, (plain, kept)  # measured: ~3,300 → ~400 page faults per step of the default GQ-CNN


def test_native_bfloat16_is_a_property_of_the_device():
    import torch

    from graspaug.device import has_native_bfloat16

    assert has_native_bfloat16(torch.device("meta")) is False  # no hardware behind it
    cpu = has_native_bfloat16(torch.device("cpu"))
    assert cpu is bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())  # what oneDNN dispatches on
