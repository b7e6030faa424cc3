"""The shared figure primitives, drawn to PNG files and read back: what a person sees."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from graspaug.plots import DPI, voxel_rows


def blank_below_title(png) -> int:
    """The height (pixels) of the blank (white) band between a figure's first line of text (its title) and whatever
    comes next: read from the PNG file ``png``."""
    import matplotlib.image

    image = matplotlib.image.imread(png)[..., :3]  # (H, W, 3) float in [0, 1]
    inked = (image < 0.9).any(axis=(1, 2))  # (H,) rows with anything drawn
    first = int(np.argmax(inked))  # the title's first row
    title_end = first + int(np.argmax(~inked[first:]))
    after = title_end + int(np.argmax(inked[title_end:]))
    return after - title_end


def _solid(shape: trimesh.Trimesh, resolution: int = 16) -> np.ndarray:
    """(R, R, R) bool: the filled voxel grid of ``shape``, padded to ``resolution`` per side."""
    grid = shape.voxelized(pitch=shape.extents.max() / (resolution - 2)).fill().matrix
    out = np.zeros((resolution,) * 3, dtype=bool)
    out[: grid.shape[0], : grid.shape[1], : grid.shape[2]] = grid[:resolution, :resolution, :resolution]
    return out


@pytest.mark.parametrize("n_rows", [1, 3, 8])
def test_voxel_rows_put_the_title_right_above_the_columns(tmp_path, n_rows):
    """generate's pairs.png opened with an empty band a fifth of its height under its title (issue #62, 14)."""
    shapes = [trimesh.creation.box(extents=(0.04, 0.03, 0.02)), trimesh.creation.capsule(height=0.03, radius=0.01)]
    cells = [(g, g) for g in map(_solid, shapes)]
    rows = [[cells[0], cells[1], cells[0]] for _ in range(n_rows)]
    path = tmp_path / "pairs.png"
    voxel_rows(rows, [f"row {i}" for i in range(n_rows)], ["parent a", "generated", "parent b"], path, "Title")
    assert blank_below_title(path) < 0.3 * DPI  # under 0.3 inch, whatever the number of rows


def own_drawings(src) -> dict[str, str]:
    """The functions of ``graspaug.plots`` (under the source root ``src``) that one experiment alone imports and
    ``plots`` itself never calls: name → the experiment (``graspaug.experiments.<name>``)."""
    import ast

    from tests.test_imports import module_name

    users: dict[str, set[str]] = {}
    for path in sorted((src / "graspaug").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom) and node.module == "graspaug.plots":
                for alias in node.names:
                    users.setdefault(alias.name, set()).add(module_name(path, src))
    plots = ast.parse((src / "graspaug" / "plots.py").read_text())
    called = {node.id for node in ast.walk(plots) if isinstance(node, ast.Name)}
    own = {}
    for name, modules in users.items():
        rooms = {".".join(m.split(".")[:3]) for m in modules}
        if name not in called and len(rooms) == 1 and next(iter(rooms)).startswith("graspaug.experiments."):
            own[name] = next(iter(rooms))
    return own


def test_an_experiment_draws_its_own_figures():
    """One figure, one place: a drawing that one experiment alone uses sits in that experiment's folder, beside its
    data and caption; ``plots`` keeps what several figures share (and the stages' own pictures)."""
    from tests.test_imports import SRC

    assert own_drawings(SRC) == {}, "plots.py functions one experiment alone draws with: move them to its figures"


def test_a_drawing_only_one_experiment_uses_is_found(tmp_path):
    for name, text in {
        "graspaug/__init__.py": "",
        "graspaug/plots.py": "def save_figure():\n    pass\n\n\ndef bars():\n    save_figure()\n",
        "graspaug/experiments/__init__.py": "",
        "graspaug/experiments/cell/__init__.py": "",
        "graspaug/experiments/cell/figures.py": "def draw():\n    from graspaug.plots import bars, save_figure\n",
    }.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    assert own_drawings(tmp_path) == {"bars": "graspaug.experiments.cell"}
