import numpy as np

from graspaug.io.voxels import VoxelSet, read_voxels, write_voxels


def test_roundtrip_and_identical_bytes_for_identical_arrays(tmp_path):
    rng = np.random.default_rng(0)
    voxels = VoxelSet(
        shape_id=np.array(["rnd_000", "rnd_001"]),
        occupancy=rng.random((2, 16, 16, 16)) > 0.7,
        pitch=np.array([0.002, 0.003]),
        origin=rng.normal(size=(2, 3)),
    )
    write_voxels(voxels, tmp_path / "a.npz")
    back = read_voxels(tmp_path / "a.npz")
    assert list(back.shape_id) == ["rnd_000", "rnd_001"] and back.resolution == 16
    assert np.array_equal(back.occupancy, voxels.occupancy)
    assert np.array_equal(back.pitch, voxels.pitch) and np.array_equal(back.origin, voxels.origin)
    assert back.grid(1).pitch == 0.003
    write_voxels(voxels, tmp_path / "b.npz")
    assert (tmp_path / "a.npz").read_bytes() == (tmp_path / "b.npz").read_bytes()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries left
    assert (tmp_path / "a.npz").stat().st_mode & 0o044 == 0o044  # readable by others, like any file (umask 022)


def test_an_interrupted_write_leaves_the_old_file(tmp_path):
    import pytest

    from graspaug.io.atomic import atomic_path

    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("killed")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_signed_distances_travel_in_steps_of_a_127th_and_keep_their_sign(tmp_path):
    rng = np.random.default_rng(1)
    sdf = rng.uniform(-1, 1, size=(2, 8, 8, 8)).astype(np.float32)
    sdf[0, 0, 0, :3] = (-1e-4, 1e-4, 0.0)  # centres next to the surface round to zero steps
    voxels = VoxelSet(np.array(["a", "b"]), sdf < 0, np.array([0.002, 0.003]), np.zeros((2, 3)), sdf, 3.0)
    write_voxels(voxels, tmp_path / "s.npz")
    back = read_voxels(tmp_path / "s.npz")
    assert back.truncation == 3.0 and np.abs(back.sdf - sdf).max() <= 1 / 127 + 1e-6  # a step at most (inside kept)
    assert np.array_equal(back.sdf < 0, sdf < 0)  # the inside is the occupancy's, voxel for voxel
    plain = VoxelSet(voxels.shape_id, voxels.occupancy, voxels.pitch, voxels.origin)
    write_voxels(plain, tmp_path / "o.npz")
    assert read_voxels(tmp_path / "o.npz").sdf is None  # an occupancy file holds its keys alone
