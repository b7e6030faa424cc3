"""Every dvc.yaml stage lists exactly the graspaug source it runs: no more, no less.

A stage's code is the import closure (found with ``ast``, nothing is imported) of the stage module that its
``cmd`` runs, ``python -m graspaug.pipeline.stages.x_y ...`` (its ``__main__`` block imports
``graspaug.pipeline.entry``); the CLI that lists every command is no stage's code. dvc.yaml lists it module by
module (:func:`dvc_deps`), a library package as its folder only where the stage reaches every module in it.
``python tests/test_dvc_deps.py --write`` rewrites every stage's ``src/`` deps in dvc.yaml from the import graph
(the one source of truth this test checks against); without ``--write`` it prints them.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
SRC = REPO / "src"
DVC_YAML = REPO / "dvc.yaml"
STAGES = "graspaug.pipeline.stages."


def module_file(module: str, src: Path) -> Path | None:
    """The file of a dotted module name under ``src`` (``a/b.py`` or ``a/b/__init__.py``), or None."""
    base = src.joinpath(*module.split("."))
    return next((f for f in (base.with_suffix(".py"), base / "__init__.py") if f.is_file()), None)


def _with_packages(module: str) -> set[str]:
    """``a.b.c`` -> ``{a, a.b, a.b.c}``: importing a module first runs every package it sits in."""
    parts = module.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts) + 1)}


def _is_inert(tree: ast.Module) -> bool:
    """Only a docstring and dunder metadata (``__version__ = "0.1.0"``): editing it changes no result."""
    return all(
        isinstance(node, (ast.Expr, ast.Assign))
        and isinstance(node.value, ast.Constant)
        and all(isinstance(t, ast.Name) and t.id.startswith("__") for t in getattr(node, "targets", []))
        for node in tree.body
    )


def _run_nodes(tree: ast.Module):
    """Every node of ``tree`` but those under ``if TYPE_CHECKING:`` (imports for type checkers, never run)."""
    todo: list[ast.AST] = [tree]
    while todo:
        node = todo.pop()
        yield node
        checking = isinstance(node, ast.If) and "TYPE_CHECKING" in {getattr(node.test, a, None) for a in ("id", "attr")}
        todo.extend(node.orelse if checking else ast.iter_child_nodes(node))


def lazy_exports(package: str, src: Path) -> dict[str, str]:
    """Name -> module of the names a package's ``__init__.py`` imports only ``if TYPE_CHECKING:``: the names it loads
    on first use (a module ``__getattr__``, as ``graspaug.planning`` does), run only by whoever imports one."""
    file = module_file(package, src)
    if file is None or file.name != "__init__.py":
        return {}
    tree = ast.parse(file.read_text())
    run = {id(n) for n in _run_nodes(tree)}
    return {
        alias.asname or alias.name: node.module
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and node.module and not node.level and id(node) not in run
        for alias in node.names
    }


def module_imports(module: str, src: Path) -> set[str]:
    """Modules of the same top package that ``module`` imports anywhere (function bodies too, not imports for type
    checkers), with every package they sit in: ``from a.b import c`` gives ``a``, ``a.b``, and ``a.b.c`` if it is a
    module, or the module ``a.b`` loads ``c`` from on first use (:func:`lazy_exports`)."""
    root, file = module.split(".")[0], module_file(module, src)
    package = module if file.name == "__init__.py" else module.rpartition(".")[0]
    names: set[str] = set()
    for node in _run_nodes(ast.parse(file.read_text(), str(file))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            origin = ".".join(base + ([node.module] if node.module else []))
            names.add(origin)
            names.update(f"{origin}.{alias.name}" for alias in node.names if alias.name != "*")
            lazy = lazy_exports(origin, src)
            names.update(lazy[alias.name] for alias in node.names if alias.name in lazy)
    return {m for n in names for m in _with_packages(n) if m.split(".")[0] == root and module_file(m, src)}


def _closure(starts: set[str], src: Path) -> set[str]:
    """Repo-relative files of ``starts`` and everything they import, transitively."""
    seen: set[str] = set()
    todo = set().union(*map(_with_packages, starts))
    while todo:
        module = todo.pop()
        if module not in seen:
            seen.add(module)
            todo |= module_imports(module, src) - seen
    files = {module_file(m, src) for m in seen if "." in m or not _is_inert(ast.parse(module_file(m, src).read_text()))}
    return {f.relative_to(src.parent).as_posix() for f in files}


def import_closure(module: str, src: Path) -> set[str]:
    """Repo-relative paths of ``module``, its packages' ``__init__.py`` and every module of its top
    package that it imports, transitively (lazy imports in functions included; the top package's
    ``__init__.py`` only when it holds more than a docstring and ``__version__``-style metadata)."""
    return _closure({module}, src)


def stage_code(cmd: str, src: Path = SRC) -> set[str]:
    """The code a ``python -m graspaug.pipeline.stages.<stage> ...`` cmd runs: the stage module's closure."""
    words = cmd.split()
    module = words[2] if words[:2] == ["python", "-m"] and len(words) > 2 else ""
    if not module.startswith(STAGES) or module_file(module, src) is None:
        raise ValueError(f"cmd {cmd!r} does not run a stage module (python -m {STAGES}<stage>)")
    return _closure({module}, src)


def dvc_deps(files: set[str], src: Path = SRC) -> set[str]:
    """``files`` (repo-relative ``src/graspaug/...`` paths) as dvc.yaml lists them: each file, except that a
    library package (``src/graspaug/geometry``) every one of whose modules is in ``files`` is listed as its folder.
    A stage re-runs for the modules it runs, not for the rest of their package (ingest for ``augment/corpus.py``,
    not ``augment/pools.py``)."""
    out = set(files)
    for package in {"/".join(p.split("/")[:3]) for p in files if len(p.split("/")) > 3}:
        if package.endswith("/pipeline"):
            continue
        modules = {f.relative_to(src.parent).as_posix() for f in (src.parent / package).rglob("*.py")}
        if modules <= files:
            out = (out - modules) | {package}
    return out


def dvc_stages(dvc: dict) -> dict[str, dict]:
    """Stage name -> its definition; a ``foreach`` stage's is its ``do:`` block (matrix stages are flat)."""
    return {name: body.get("do", body) for name, body in dvc["stages"].items()}


def expected_code_deps(dvc_yaml: Path = DVC_YAML, src: Path = SRC) -> dict[str, set[str]]:
    """Stage name -> the ``src/`` files it runs (dvc.yaml lists them as :func:`dvc_deps` does)."""
    return {
        name: stage_code(body["cmd"], src) for name, body in dvc_stages(yaml.safe_load(dvc_yaml.read_text())).items()
    }


def compare_code_deps(dvc: dict, src: Path = SRC) -> dict[str, dict[str, set[str]]]:
    """Stage name -> {"missing": expected but not listed, "extra": listed but not expected}, both as
    :func:`dvc_deps` lists them, for stages where either is non-empty."""
    problems = {}
    for name, body in dvc_stages(dvc).items():
        listed = {
            d
            for d in (d if isinstance(d, str) else next(iter(d)) for d in body.get("deps", []))
            if d.startswith("src/")
        }
        expected = dvc_deps(stage_code(body["cmd"], src), src)
        missing, extra = expected - listed, listed - expected
        if missing or extra:
            problems[name] = {"missing": missing, "extra": extra}
    return problems


def _yaml_lists(deps: dict[str, set[str]]) -> str:
    return "\n".join(f"{name}:\n" + "".join(f"  - {p}\n" for p in sorted(paths)) for name, paths in deps.items())


def _real_dvc() -> dict:
    return yaml.safe_load(DVC_YAML.read_text())


def test_every_stage_lists_exactly_its_code():
    """dvc.yaml's src/ deps equal each stage's import closure."""
    problems = compare_code_deps(_real_dvc())
    report = "".join(
        f"\n{name}:\n" + "".join(f"  {kind}: {p}\n" for kind in ("missing", "extra") for p in sorted(d[kind]))
        for name, d in problems.items()
    )
    assert not problems, f"dvc.yaml code deps differ from the imports:{report}(python tests/test_dvc_deps.py --write)"


def test_a_stage_depends_only_on_the_settings_it_reads():
    """Settings modules are plain data and a stage imports only the params sections it reads: the robot cell's
    settings are code of the stages that run the cell (`sim`, `grasp_calibration`) alone, so editing them re-runs
    nothing before them. `check_params` reads every section (the whole params model, `params/model.py`) and writes
    nothing, so editing any settings module re-runs it and nothing else."""
    deps = expected_code_deps()
    cell = {name for name, files in deps.items() if "src/graspaug/sim/settings.py" in files}
    assert cell == {"sim", "grasp_calibration", "check_params"}
    assert {name for name, files in deps.items() if "src/graspaug/pipeline/params/model.py" in files} == {
        "check_params"
    }
    early = deps["ingest"] | deps["voxelize"]
    assert not {
        f for f in early if f.startswith(("src/graspaug/sim/", "src/graspaug/planning/", "src/graspaug/render/"))
    }


def test_a_planted_missing_dep_is_caught():
    """Drop one listed src file from one stage: exactly that path becomes missing."""
    dvc, planted = _real_dvc(), "src/graspaug/pipeline/stages/render.py"
    dvc_stages(dvc)["render"]["deps"].remove(planted)
    before = compare_code_deps(_real_dvc()).get("render", {}).get("missing", set())
    assert compare_code_deps(dvc)["render"]["missing"] - before == {planted}


def test_a_folder_the_stage_does_not_run_is_caught():
    """A library folder the stage never imports is an extra dep; a package is listed as its folder only when the
    stage runs every module in it, else module by module (ingest runs augment's corpus code, not its pools)."""
    dvc = _real_dvc()
    dvc_stages(dvc)["voxelize"]["deps"].append("src/graspaug/sim")
    assert "src/graspaug/sim" in compare_code_deps(dvc)["voxelize"]["extra"]
    some = {"src/graspaug/geometry/voxelize.py", "src/graspaug/pipeline/stages/voxelize.py"}
    assert dvc_deps(some) == some
    whole = {f.relative_to(REPO).as_posix() for f in (SRC / "graspaug/geometry").rglob("*.py")}
    assert dvc_deps(whole | some) == {"src/graspaug/geometry", "src/graspaug/pipeline/stages/voxelize.py"}
    ingest = expected_code_deps()["ingest"]
    assert "src/graspaug/augment/corpus.py" in ingest and "src/graspaug/augment/pools.py" not in ingest


def test_no_stage_runs_the_cli_or_another_stage():
    """A stage's code is its own module's closure: editing cli.py (a help text, a user's command) or another stage's
    adapter re-runs nothing; check_params reads the params model, not the libraries that use it."""
    for name, files in expected_code_deps().items():
        commands = {"cli.py", "planner_cli.py", "study_cli.py"}
        assert not {f for f in files if f.rsplit("/", 1)[-1] in commands}, name
        stages = {f for f in files if f.startswith("src/graspaug/pipeline/stages/") and not f.endswith("__init__.py")}
        assert len(stages) == 1, (name, sorted(stages))
    check = expected_code_deps()["check_params"]
    assert not {
        f
        for f in check
        if f.startswith("src/graspaug/")
        and f.count("/") > 2
        and "/pipeline/" not in f
        and not f.endswith(("/settings.py", "/__init__.py", "/gripper.py", "/catalog.py"))
    }, sorted(check)


WIDTH = 118  # dvc.yaml's lines, as ruff's for the code


def flow_list(indent: str, key: str, items: list[tuple[str, str | None]]) -> list[str]:
    """``key: [a, b, ...]`` at ``indent``, wrapped at :data:`WIDTH` with continuation lines two spaces deeper; each item
    a (value, comment or None) pair, quoted where YAML's flow context needs it, a comment ending its line."""
    lines, line = [], f"{indent}{key}: ["
    for n, (value, comment) in enumerate(items):
        text = f"'{value}'" if any(c in value for c in "{}[],#") else value
        text += "]" if n == len(items) - 1 else ","
        if len(line) + 1 + len(text) > WIDTH and not line.endswith("["):
            lines.append(line)
            line = f"{indent}  {text}"
        else:
            line += ("" if line.endswith("[") else " ") + text
        if comment:
            lines.append(f"{line}  # {comment}")
            line = f"{indent}  "
    if line.strip():
        lines.append(line)
    return lines


def written_deps(text: str, deps: dict[str, set[str]]) -> str:
    """dvc.yaml's ``text`` with each stage's ``src/`` deps replaced by ``deps[stage]``: its ``deps: [...]`` list
    rewritten as its other deps in their order, then ``deps[stage]`` sorted (:func:`flow_list`); every other line
    kept."""
    out, stage, lines, i = [], None, text.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("  ") and not line.startswith("   ") and line.split("#")[0].rstrip().endswith(":"):
            stage = line.split(":")[0].strip()
        if stage in deps and line.lstrip().startswith("deps: ["):
            j = i
            while "]" not in lines[j].split("#")[0]:
                j += 1
            listed = yaml.safe_load("\n".join(x.split("  # ")[0] for x in lines[i : j + 1]))["deps"]
            others = [(d, None) for d in listed if not d.startswith("src/")]
            out += flow_list(
                line[: len(line) - len(line.lstrip())], "deps", others + [(d, None) for d in sorted(deps[stage])]
            )
            i = j + 1
            continue
        out.append(line)
        i += 1
    return "\n".join(out) + "\n"


def test_write_puts_back_what_the_check_expects():
    """`--write` on a dvc.yaml with a stage's src deps scrambled gives a file this test passes on."""
    text = DVC_YAML.read_text()
    scrambled = text.replace("src/graspaug/pipeline/stages/voxelize.py", "src/graspaug/sim", 1)
    assert scrambled != text
    expected = {name: dvc_deps(files) for name, files in expected_code_deps().items()}
    assert compare_code_deps(yaml.safe_load(written_deps(scrambled, expected))) == {}


def test_import_closure_follows_every_import_form(tmp_path):
    """Absolute, relative, lazy and `from pkg import module` imports, and the __init__ chain."""
    files = {
        "pkg/__init__.py": '"""Docstring only."""\n__version__ = "1"\n',
        "pkg/top.py": "import os\nimport pkg.a.absolute\nfrom pkg import sub\nfrom pkg.b import helper\n",
        "pkg/sub.py": "def f():\n    from . import lazy\n",
        "pkg/lazy.py": "",
        "pkg/a/__init__.py": "",
        "pkg/a/absolute.py": "from ..b.helper import name\nfrom .sibling import x\n",
        "pkg/a/sibling.py": "x = 1\n",
        "pkg/b/__init__.py": "from pkg.b.helper import name\n",
        "pkg/b/helper.py": "name = 1\n",
        "pkg/unused.py": "",
    }
    for path, text in files.items():
        (tmp_path / "src" / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "src" / path).write_text(text)
    expected = {f"src/{p}" for p in files} - {"src/pkg/__init__.py", "src/pkg/unused.py"}
    assert import_closure("pkg.top", tmp_path / "src") == expected
    (tmp_path / "src/pkg/__init__.py").write_text("import logging\n")
    assert "src/pkg/__init__.py" in import_closure("pkg.a.sibling", tmp_path / "src")


def test_imports_for_type_checkers_count_only_where_their_name_is_imported(tmp_path):
    """``if TYPE_CHECKING:`` imports never run, except as a package's lazily loaded names: ``from pkg import Heavy``
    runs ``pkg/heavy.py``, ``from pkg.settings import x`` does not."""
    files = {
        "pkg/__init__.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.heavy import Heavy\n",
        "pkg/heavy.py": "Heavy = 1\n",
        "pkg/settings.py": "x = 1\n",
        "pkg/light.py": "from pkg.settings import x\n",
        "pkg/user.py": "from pkg import Heavy\n",
    }
    for path, text in files.items():
        (tmp_path / "src" / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "src" / path).write_text(text)
    assert "src/pkg/heavy.py" not in import_closure("pkg.light", tmp_path / "src")
    assert "src/pkg/heavy.py" in import_closure("pkg.user", tmp_path / "src")


def test_stages_are_thin_adapters_that_import_no_stage():
    """A stage reads its params, calls library code and writes outputs: at most ~100 lines as ruff formats them, and
    what a test or another stage needs lives in a library module, not in a stage."""
    for path in sorted((SRC / "graspaug/pipeline/stages").glob("*.py")):
        if path.name == "__init__.py":
            continue
        lines = path.read_text().split('\nif __name__ == "__main__":')[0].rstrip().splitlines()  # the entry point aside
        assert len(lines) <= 100, f"{path.name} is {len(lines)} lines"
        imported = module_imports(f"graspaug.pipeline.stages.{path.stem}", SRC)
        assert not {m for m in imported if m.startswith(STAGES)}, (
            f"{path.name} imports a stage: {sorted(m for m in imported if m.startswith(STAGES))}"
        )


if __name__ == "__main__":
    listed = {name: dvc_deps(files) for name, files in expected_code_deps().items()}
    if "--write" in sys.argv[1:]:
        DVC_YAML.write_text(written_deps(DVC_YAML.read_text(), listed))
    else:
        sys.stdout.write(_yaml_lists(listed))
