"""The torch device the ``device`` param names."""

from __future__ import annotations

import torch


def resolve_device(device: str) -> torch.device:
    """``auto`` → CUDA when present, else CPU; ``cuda`` without a CUDA device is an error."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if device == "cuda" and not torch.cuda.is_available():
        raise RuntimeError("device: cuda was asked for but torch sees no CUDA device")
    return torch.device(device)


_HEAP_KEPT = 1 << 30  # bytes


def keep_freed_memory() -> bool:
    """Let glibc keep freed memory for reuse instead of handing it back to the kernel.

    A CPU training step allocates and frees dozens of MB-sized tensors; glibc serves each from
    fresh ``mmap`` pages (above its mmap threshold) or trims the heap after a free, so every
    step pays page faults (a default GQ-CNN step on one batch: ~3,300; ~400 with this).
    Raising the mmap and trim thresholds to 1 GiB (``mallopt``) keeps those pages, as jemalloc
    or tcmalloc would. Process-wide and idempotent; returns False where there is no glibc
    (macOS, musl), which changes nothing there."""
    import ctypes
    import ctypes.util
    import sys

    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    m_trim_threshold, m_mmap_threshold = -1, -3  # glibc's malloc.h
    mmap_set = mallopt(m_mmap_threshold, _HEAP_KEPT) or mallopt(
        m_mmap_threshold, 32 << 20
    )  # glibc < 2.35 caps it at 32 MiB
    return bool(mmap_set) and bool(mallopt(m_trim_threshold, _HEAP_KEPT))


def has_native_bfloat16(device: torch.device) -> bool:
    """Whether ``device`` computes bfloat16 convolutions and matrix products in hardware (a
    CUDA GPU that supports it; a CPU with AVX512-BF16 or AMX, as oneDNN reports); elsewhere
    ``torch.autocast`` emulates bfloat16, slower than float32."""
    if device.type == "cuda":
        return torch.cuda.is_bf16_supported()
    return (
        device.type == "cpu"
        and torch.backends.mkldnn.is_available()
        and bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())
    )
