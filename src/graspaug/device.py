"""The torch device the ``device`` param names, the precision a network trains in there (``precision``
settings: :func:`resolve_precision`), and the process's memory allocator (glibc).

torch is imported inside the functions that need it: per-shape worker processes import this module
for :func:`release_freed_memory` alone."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:
    import torch

log = logging.getLogger(__name__)


def resolve_device(device: str) -> torch.device:
    """``auto`` → CUDA when present, else CPU; ``cuda`` without a CUDA device is an error."""
    import torch

    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if device == "cuda" and not torch.cuda.is_available():
        raise RuntimeError("device: cuda was asked for but torch sees no CUDA device")
    return torch.device(device)


_HEAP_KEPT = 1 << 30  # bytes


def _glibc(name: str):
    """The glibc function ``name`` (ctypes), or None where there is none (macOS, musl)."""
    import ctypes
    import ctypes.util
    import sys

    if not sys.platform.startswith("linux"):
        return None
    try:
        return getattr(ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6"), name)
    except (OSError, AttributeError):
        return None


def keep_freed_memory() -> bool:
    """Let glibc keep freed memory for reuse instead of handing it back to the kernel.

    A CPU training step allocates and frees dozens of MB-sized tensors; glibc serves each from
    fresh ``mmap`` pages (above its mmap threshold) or trims the heap after a free, so every
    step pays page faults (a default GQ-CNN step on one batch: 1,400–7,100 by machine; 0–400 with this).
    Raising the mmap and trim thresholds to 1 GiB (``mallopt``) keeps those pages, as jemalloc
    or tcmalloc would. Process-wide and idempotent; returns False where there is no glibc
    (macOS, musl), which changes nothing there."""
    mallopt = _glibc("mallopt")
    if mallopt is None:
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's malloc.h
    mmap_set = mallopt(m_mmap_threshold, _HEAP_KEPT) or mallopt(
        m_mmap_threshold, 32 << 20
    )  # glibc < 2.35 caps it at 32 MiB
    return bool(mmap_set) and bool(mallopt(m_trim_threshold, _HEAP_KEPT))


def release_freed_memory() -> bool:
    """Hand the memory this process has freed back to the operating system (glibc's ``malloc_trim``);
    False where there is no glibc. A per-shape worker process calls it after each shape
    (:mod:`graspaug.parallel`): glibc keeps what a large mesh or scene freed, so a worker's resident
    size would grow from shape to shape."""
    malloc_trim = _glibc("malloc_trim")
    if malloc_trim is None:
        return False
    malloc_trim(0)
    return True


def has_native_bfloat16(device: torch.device) -> bool:
    """Whether ``device`` computes bfloat16 convolutions and matrix products in hardware: a CUDA GPU
    with bfloat16 units (compute capability 8.0 on, not torch's emulation on older ones); an x86 CPU
    with AVX512-BF16 or AMX (cpuinfo, as torch reads it); another CPU where oneDNN reports bfloat16
    (on ARM: the BF16 extension). Elsewhere ``torch.autocast`` emulates bfloat16, slower than float32.
    oneDNN's own report is not used on x86: it says yes on any AVX-512 CPU, whose bfloat16 is emulated."""
    import platform

    import torch

    if device.type == "cuda":
        return torch.cuda.is_available() and torch.cuda.is_bf16_supported(including_emulation=False)
    if device.type != "cpu":
        return False
    if platform.machine().lower() in ("x86_64", "amd64", "i386", "i686"):
        return bool(torch.cpu._is_avx512_bf16_supported() or torch.cpu._is_amx_tile_supported())
    return torch.backends.mkldnn.is_available() and bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())


PRECISIONS = ("auto", "float32", "bfloat16")
"""The values of a ``precision`` setting (``gqcnn.train.precision``, ``ae.train.precision``)."""


class Precision(NamedTuple):
    """The arithmetic a training loop's steps run in, as :func:`choose_precision` resolved it."""

    dtype: str  # "float32" or "bfloat16" (torch.autocast on the training steps)
    label: str  # how the log, the checkpoint and the model card say it, e.g. "bfloat16 (auto: native on this CPU)"


def choose_precision(precision: str, device_type: str, native_bfloat16: bool, gpu_bfloat16: bool = True) -> Precision:
    """The precision a ``precision`` setting (:data:`PRECISIONS`) gives on a device of ``device_type``
    (``cpu``, ``cuda``) that does (``native_bfloat16``) or does not compute bfloat16 in hardware
    (:func:`has_native_bfloat16`): ``auto`` → bfloat16 where native, float32 elsewhere, and float32 on a GPU for a
    network that bfloat16 does not speed up there (``gpu_bfloat16`` False: the GQ-CNN, :data:`GQCNN_GPU_BFLOAT16`);
    ``float32`` and ``bfloat16`` as asked, labelled as written (bfloat16 on a device without it is emulated, slower
    than float32: the stage warns). A pure function of those facts, so a test can give it any device."""
    if precision not in PRECISIONS:
        raise ValueError(f"precision: {precision!r} is not one of {', '.join(PRECISIONS)}")
    where = "this GPU" if device_type == "cuda" else f"this {device_type.upper()}"
    if precision == "auto" and device_type == "cuda" and native_bfloat16 and not gpu_bfloat16:
        return Precision("float32", "float32 (auto: bfloat16 is slower for this network on a GPU)")
    if precision == "auto":
        if native_bfloat16:
            return Precision("bfloat16", f"bfloat16 (auto: native on {where})")
        return Precision("float32", f"float32 (auto: no native bfloat16 on {where})")
    return Precision(precision, precision)


GQCNN_GPU_BFLOAT16 = False
"""Whether bfloat16 speeds the GQ-CNN up on a GPU: no, measured on an H200 (bfloat16 autocast 11,469 samples/s against
float32's 13,081; docs/results.md, "Training on a CUDA GPU"), so its ``auto`` stays float32 there."""


def resolve_precision(precision: str, device: torch.device, gpu_bfloat16: bool = True) -> Precision:
    """:func:`choose_precision` of ``precision`` on ``device`` (:func:`has_native_bfloat16` asked here)."""
    return choose_precision(precision, device.type, has_native_bfloat16(device), gpu_bfloat16)


def precision_warning(precision: str, device: torch.device, key: str) -> str | None:
    """The warning for the setting ``key`` asking for bfloat16 (``precision``) on a ``device`` without bfloat16
    instructions (emulated: slower than float32), else None."""
    if precision == "bfloat16" and not has_native_bfloat16(device):
        return (
            f"{key}: bfloat16, but this {device.type.upper()} has no bfloat16 instructions: training is emulated "
            f"and slower than float32 (-S {key}=float32, or auto)"
        )
    return None


def log_precision(stage: str, key: str, precision: str, device: torch.device, gpu_bfloat16: bool = True) -> Precision:
    """The setting ``key`` (value ``precision``) resolved on ``device`` (:func:`resolve_precision`), said once in
    the log as ``<stage>: precision <label>``, with :func:`precision_warning` where it asks for emulated bfloat16."""
    resolved = resolve_precision(precision, device, gpu_bfloat16)
    log.info("%s: precision %s", stage, resolved.label)
    if (warning := precision_warning(precision, device, key)) is not None:
        log.warning("%s", warning)
    return resolved


def training_autocast(precision: Precision, device: torch.device) -> torch.autocast:
    """The ``torch.autocast`` context of a training step's forward pass and loss: bfloat16 on ``device``
    for a bfloat16 ``precision``, a no-op for float32. Weights, optimizer and evaluation stay float32."""
    import torch

    return torch.autocast(device.type, dtype=torch.bfloat16, enabled=precision.dtype == "bfloat16")
