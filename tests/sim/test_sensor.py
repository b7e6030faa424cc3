"""The D435-like depth sensor: its measured statistics match its params."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from graspaug.render.settings import Intrinsics
from graspaug.sim.sensor import edge_band, noise_sd, sense_depth, surface_tilt
from graspaug.sim.settings import DepthNoise

K = Intrinsics()


def plane_and_box(table: float = 0.65, top: float = 0.60) -> np.ndarray:
    """A flat table 0.65 m away with a 120 × 120 px box whose top is 5 cm nearer."""
    depth = np.full((480, 640), table)
    depth[180:300, 260:380] = top
    return depth


def test_noise_sd_at_the_plane_matches_the_param():
    depth = plane_and_box()
    settings = DepthNoise()
    exact = dataclasses.replace(settings, quantization=0.0, edge_dropout=0.0)
    table = np.zeros(depth.shape, dtype=bool)
    table[:, :200] = True  # far from the box's edges
    sd = float(noise_sd(np.array(0.65), settings))
    assert sd == pytest.approx(0.0038 * 0.65**2) and 0.0014 < sd < 0.0018  # 1.6 mm, the D435 at 65 cm
    measured = (sense_depth(depth, K, exact, np.random.default_rng(0)) - depth)[table].std()
    assert measured == pytest.approx(sd, rel=0.05)
    # quantized to 1 mm it adds the rounding's q²/12 (within sampling error)
    quantized = (sense_depth(depth, K, settings, np.random.default_rng(0)) - depth)[table].std()
    assert quantized == pytest.approx(np.hypot(sd, 0.001 / np.sqrt(12)), rel=0.08)
    # twice as far: four times the SD
    far = (sense_depth(np.full((480, 640), 1.3), K, exact, np.random.default_rng(1)) - 1.3).std()
    assert far == pytest.approx(4 * sd, rel=0.05)


def test_missing_pixels_at_edges_and_steep_surfaces_match_the_params():
    depth = plane_and_box()
    settings = DepthNoise(edge_dropout=0.3, steep_dropout=0.5)
    read = sense_depth(depth, K, settings, np.random.default_rng(2))
    band = edge_band(depth, settings)
    # along each 120 px side of the box: the jump's two pixels widened by 2 px either way, 6 px wide
    assert 4 * 116 * 6 < band.sum() < 4 * 126 * 6
    assert (read[band] == 0).mean() == pytest.approx(0.3, abs=0.04)
    assert not np.any(read[~band] == 0)  # flat surfaces away from edges lose nothing
    # a ramp tilted 72 degrees from the image plane (3.8 mm per pixel: no edge) loses half its pixels
    ramp = np.full((480, 640), 0.65)
    slope = np.tan(np.radians(72)) * 0.65 / K.fx
    ramp[:, 300:340] = 0.65 - slope * np.arange(1, 41)[None, :]
    ramp[:, 340:] = ramp[:, 339:340]
    tilt = surface_tilt(ramp, K)
    steep = (tilt > settings.steep_angle) & ~edge_band(ramp, settings)
    assert steep[:, 302:338].all() and not steep[:, :290].any()
    lost = sense_depth(ramp, K, settings, np.random.default_rng(3)) == 0
    assert lost[steep].mean() == pytest.approx(0.5, abs=0.03) and not lost[:, :290].any()


def test_values_are_quantized_and_seeded():
    depth = plane_and_box()
    settings = DepthNoise()
    a = sense_depth(depth, K, settings, np.random.default_rng(5))
    steps = a[a > 0] / 0.001
    assert np.allclose(steps, np.round(steps), atol=1e-6)
    assert np.array_equal(a, sense_depth(depth, K, settings, np.random.default_rng(5)))
    assert not np.array_equal(a, sense_depth(depth, K, settings, np.random.default_rng(6)))
    assert np.array_equal(depth, plane_and_box())  # the input is left unchanged
    off = sense_depth(depth, K, DepthNoise(enabled=False), np.random.default_rng(5))
    assert np.array_equal(off, depth) and off is not depth
