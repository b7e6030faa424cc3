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
