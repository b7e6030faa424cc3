"""The torch device the ``device`` param names, and the process's memory allocator (glibc).

torch is imported inside the functions that need it: per-shape worker processes import this module
for :func:`release_freed_memory` alone."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import torch


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
    step pays page faults (a default GQ-CNN step on one batch: ~3,300; ~400 with this).
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
    """Whether ``device`` computes bfloat16 convolutions and matrix products in hardware (a
    CUDA GPU that supports it; a CPU with AVX512-BF16 or AMX, as oneDNN reports); elsewhere
    ``torch.autocast`` emulates bfloat16, slower than float32."""
    import torch

    if device.type == "cuda":
        return torch.cuda.is_bf16_supported()
    return (
        device.type == "cpu"
        and torch.backends.mkldnn.is_available()
        and bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())
    )
