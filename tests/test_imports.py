"""The import graph of graspaug: arrows point one way.

Edges come from the source (``ast``; imports inside functions count too): ``import a.b`` and
``from a.b import name`` are edges to the module ``a.b`` (and to ``a.b.name`` when that is a
module). A package's ``__init__`` is a node of its own, reached only by importing a name it
defines, so a package that re-exports its modules' names is no cycle by itself.
"""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

SRC = Path(__file__).resolve().parents[1] / "src"


def module_name(path: Path, src: Path) -> str:
    parts = list(path.relative_to(src).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def module_file(module: str, src: Path) -> Path | None:
    base = src.joinpath(*module.split("."))
    return next((f for f in (base.with_suffix(".py"), base / "__init__.py") if f.is_file()), None)


def import_graph(src: Path, root: str = "graspaug") -> nx.DiGraph:
    """Module → the modules of ``root`` it imports."""
    graph = nx.DiGraph()
    for path in sorted((src / root).rglob("*.py")):
        module = module_name(path, src)
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        graph.add_node(module)
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
                origin = ".".join(base + ([node.module] if node.module else []))
                submodules = [f"{origin}.{a.name}" for a in node.names if module_file(f"{origin}.{a.name}", src)]
                names = [a.name for a in node.names if not module_file(f"{origin}.{a.name}", src)]
                targets = submodules + ([origin] if names or not node.names else [])
            for target in targets:
                if target.split(".")[0] == root and module_file(target, src) and target != module:
                    graph.add_edge(module, target)
    return graph


def test_no_import_cycle():
    cycles = [sorted(c) for c in nx.strongly_connected_components(import_graph(SRC)) if len(c) > 1]
    assert not cycles, f"modules that import each other (directly or through others): {cycles}"


def test_a_planted_cycle_is_found(tmp_path):
    for name, text in {
        "pkg/__init__.py": "",
        "pkg/a.py": "from pkg.b import f\n",
        "pkg/b.py": "def f():\n    from pkg import a\n",
    }.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    cycles = [c for c in nx.strongly_connected_components(import_graph(tmp_path, "pkg")) if len(c) > 1]
    assert cycles == [{"pkg.a", "pkg.b"}]


def test_planning_does_not_import_sim_or_experiments():
    """The planner is a library the robot cell uses; it never reaches back into the cell or the experiments."""
    graph = import_graph(SRC)
    planning = [m for m in graph if m == "graspaug.planning" or m.startswith("graspaug.planning.")]
    assert planning, "graspaug.planning is a package"
    reached = set().union(*(nx.descendants(graph, m) for m in planning))
    bad = sorted(m for m in reached if (m.split(".") + [""])[1] in ("sim", "experiments", "stages", "cli", "config"))
    assert not bad, f"graspaug.planning reaches {bad}"


def test_libraries_know_no_file_layout():
    """Only stages, the studies and the CLI's modules know file names (graspaug.pipeline.paths); only the pipeline
    handles StageError."""
    graph = import_graph(SRC)
    users = {m for m in graph.predecessors("graspaug.pipeline.paths")}
    knowing = ("graspaug.pipeline.stages", "graspaug.pipeline.studies")
    commands = {f"graspaug.pipeline.{m}" for m in ("cli", "planner_cli", "study_cli")}
    assert {m for m in users if not (m.startswith(knowing) or m in commands)} == set()
    for path in sorted((SRC / "graspaug").rglob("*.py")):
        module = module_name(path, SRC)
        if module.startswith("graspaug.pipeline.") or module == "graspaug.errors":
            continue
        assert "StageError" not in path.read_text(), f"{module} uses StageError (libraries raise DataError)"


def test_settings_modules_are_plain_data():
    """A settings module imports only other settings modules (its section is data, not code)."""
    graph = import_graph(SRC)
    code = {"graspaug.pipeline.params.base", "graspaug.pipeline.params.model", "graspaug.pipeline.params.profiles"}
    data = {m for m in graph if m.endswith(".settings") or m.startswith("graspaug.pipeline.params.")} - code
    allowed = data | {
        "graspaug.settings",
        "graspaug.pipeline.params",
        "graspaug.sim.catalog",
        "graspaug.grasping.gripper",
    }
    for module in sorted(data):
        reached = nx.descendants(graph, module)
        assert reached <= allowed, f"{module} imports code: {sorted(reached - allowed)}"


def _room(module: str) -> str:
    """The room of a module: its package under graspaug (``graspaug.augment.pools`` → ``augment``)."""
    return (module.split(".") + [""])[1]


def test_rooms_point_down():
    """pipeline → experiments / planning → augment / training → libraries: nothing outside ``pipeline`` imports
    it (params, stages, paths, the CLI: a library takes its own settings classes, never a params section), and
    ``training`` never reaches the experiments."""
    graph = import_graph(SRC)
    up = sorted((a, b) for a, b in graph.edges if _room(b) == "pipeline" and _room(a) != "pipeline")
    assert not up, f"imports of the pipeline from below it: {up}"
    training = [m for m in graph if _room(m) == "training"]
    reached = set().union(*(nx.descendants(graph, m) for m in training))
    assert not {m for m in reached if _room(m) == "experiments"}, "training reaches the experiments"


def room_cycles(graph: nx.DiGraph) -> list[list[str]]:
    """Rooms (packages under graspaug) that import each other, directly or through other rooms: each cycle's rooms,
    sorted; the root package (``graspaug`` itself) is no room."""
    rooms = nx.DiGraph(
        (_room(a), _room(b)) for a, b in graph.edges if _room(a) != _room(b) and "" not in (_room(a), _room(b))
    )
    return sorted(sorted(c) for c in nx.strongly_connected_components(rooms) if len(c) > 1)


def test_no_cycle_between_rooms():
    """Arrows point one way between rooms too: no module of ``training`` imports ``augment`` while one of ``augment``
    imports ``training`` (a cycle of modules it is not, but of the layers it is)."""
    graph = import_graph(SRC)
    cycles = room_cycles(graph)
    edges = sorted(
        (a, b) for a, b in graph.edges if any({_room(a), _room(b)} <= set(c) for c in cycles) and _room(a) != _room(b)
    )
    assert not cycles, f"rooms that import each other: {cycles}, through {edges}"


def test_a_planted_room_cycle_is_found(tmp_path):
    for name, text in {
        "graspaug/__init__.py": "",
        "graspaug/training/__init__.py": "",
        "graspaug/training/data.py": "from graspaug.augment.sets import f\n",
        "graspaug/augment/__init__.py": "",
        "graspaug/augment/sets.py": "def f():\n    pass\n",
        "graspaug/augment/decode.py": "from graspaug.training.loop import g\n",
        "graspaug/training/loop.py": "def g():\n    pass\n",
    }.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    graph = import_graph(tmp_path)
    assert not [c for c in nx.strongly_connected_components(graph) if len(c) > 1]  # no module cycle
    assert room_cycles(graph) == [["augment", "training"]]


def test_a_planted_upward_import_is_found(tmp_path):
    for name, text in {
        "graspaug/__init__.py": "",
        "graspaug/pipeline/__init__.py": "",
        "graspaug/pipeline/params.py": "X = 1\n",
        "graspaug/grasping/__init__.py": "",
        "graspaug/grasping/labelled.py": "from graspaug.pipeline.params import X\n",
    }.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    graph = import_graph(tmp_path)
    assert [(a, b) for a, b in graph.edges if _room(b) == "pipeline" and _room(a) != "pipeline"] == [
        ("graspaug.grasping.labelled", "graspaug.pipeline.params")
    ]
