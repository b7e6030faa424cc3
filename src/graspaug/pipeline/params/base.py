"""Reading ``params.yaml`` into settings classes: the keys every stage shares, and a loader that
validates only the sections a stage reads.

A stage declares its params model with :func:`params_model` (the shared keys plus its sections),
so it imports, and DVC tracks, only the settings modules of those sections: editing the robot
cell's settings re-runs the robot trials, not the pipeline before them. Sections a stage does
not read are not validated by it (their own stage, ``graspaug profile`` and the tests do); a
top-level key that names no section is an error everywhere. pydantic checks types, ranges and
unknown keys; the first problem becomes a :class:`ParamsError`, one line naming the key.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, ValidationError, create_model, model_validator

#: Every section of params.yaml, in the order the pipeline runs.
SECTIONS = (
    "data",
    "ingest",
    "voxelize",
    "ae",
    "embed",
    "critic_eval",
    "grasps",
    "score",
    "generate",
    "render",
    "gqcnn",
    "lifelong",
    "sim",
)


class ParamsError(ValueError):
    """Invalid params; the message is one line naming the key."""


def _get(params: Any, key: str) -> Any:
    for part in key.split("."):
        params = getattr(params, part)
    return params


def _subset(key: str, other: str) -> Callable[[Any], str | None]:
    def check(p: Any) -> str | None:
        value, allowed = _get(p, key), _get(p, other)
        if value is not None and not set(value) <= set(allowed):
            return f"{key}: must be among {other} {list(allowed)}; got {list(value)}"
        return None

    return check


def _member(key: str, other: str) -> Callable[[Any], str | None]:
    def check(p: Any) -> str | None:
        value, allowed = _get(p, key), _get(p, other)
        return None if value in allowed else f"{key}: must be one of {other} {list(allowed)}; got {value}"

    return check


def _equal(key: str, other: str) -> Callable[[Any], str | None]:
    def check(p: Any) -> str | None:
        value, expected = _get(p, key), _get(p, other)
        return None if value == expected else f"{key}: must equal {other} ({expected}); got {value}"

    return check


#: Values that must agree across sections: (sections involved, check → message or None). A stage
#: runs the checks whose sections it reads.
CROSS_CHECKS: tuple[tuple[tuple[str, ...], Callable[[Any], str | None]], ...] = (
    (("ae", "voxelize"), _equal("ae.net.resolution", "voxelize.resolution")),
    (("gqcnn", "render"), _equal("gqcnn.net.image_size", "render.crop.out_size")),
    (("sim", "grasps"), _equal("sim.sampler.max_width", "grasps.gripper.max_width")),
    (("gqcnn", "generate"), _subset("gqcnn.augment_base_sizes", "generate.base_sizes")),
    (("gqcnn", "generate"), _subset("gqcnn.control_ratios", "generate.ratios")),
    (("sim", "gqcnn"), _member("sim.base_size", "gqcnn.augment_base_sizes")),
)


class BaseParams(BaseModel):
    """The keys every stage shares; a stage's model adds its sections (:func:`params_model`)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    seed: int = Field(
        0,
        ge=0,
        description="Seeds every random choice that data_seed does not: the train/test split, network initialisation "
        "and batches, critic-study pairs, t-SNE, grasp sampling and perturbations, the robot cell.",
    )
    data_seed: int = Field(
        0,
        ge=0,
        description="Seeds the draws of the GQ-CNN experiment's data, apart from the training seeds: the base sets, "
        "the validation shapes and the real pool's order, and the random pool's pairs (so every generated pool). The "
        "test split, the AutoEncoder and the grasp labels stay on `seed` unless independent_draws is on. Cross it "
        "with gqcnn.seeds to cover data draws: `dvc exp run -S data_seed=1`.",
    )
    independent_draws: bool = Field(
        False,
        description="On: data_seed also redraws the train/test split (so the AutoEncoder, trained on the train "
        "split, and everything after it) and seeds the GQ-CNNs' initial weights with the training seed, so training "
        "seeds are nested in draws and draws are independent (the confirmatory study's design). Off: the split and "
        "the initial weights stay on `seed`, the same in every draw (seeds crossed with draws). Per-object work "
        "(ingest, voxels, the original shapes' grasps and renders) never depends on it.",
    )
    device: Literal["auto", "cpu", "cuda"] = Field(
        "auto", description="Torch device: `auto` (CUDA when present), `cpu` or `cuda`."
    )
    n_jobs: int = Field(2, ge=-1, description="Worker processes for per-shape loops (-1: all cores).")
    executor: Literal["joblib", "dask"] = Field(
        "joblib",
        description="Where per-shape loops (ingest, voxelize, grasps, generate, render, sim) and the GQ-CNN networks "
        "(train_gqcnn, lifelong) run: `joblib` (n_jobs local processes; networks one after another in the stage's "
        "process) or `dask` (the Dask cluster at `scheduler`, one network per task at 1 torch thread; needs `pip "
        "install 'graspaug[dask]'` and workers that see the project at the same path).",
    )
    scheduler: str | None = Field(
        None, description="Dask scheduler address when executor is `dask`, e.g. tcp://10.0.0.5:8786."
    )

    @model_validator(mode="after")
    def _consistent(self) -> BaseParams:
        """Checks across keys: values that must agree are named in both places."""
        if self.n_jobs == 0:
            raise ValueError("n_jobs: must be >= 1, or -1 for all cores; got 0")
        if self.executor == "dask" and not self.scheduler:
            raise ValueError("scheduler: required when executor is dask (e.g. tcp://10.0.0.5:8786)")
        present = set(type(self).model_fields)
        for sections, check in CROSS_CHECKS:
            problem = check(self) if set(sections) <= present else None
            if problem:
                raise ValueError(problem)
        return self

    _file_text: str | None = PrivateAttr(None)  # set by load(): the file's header names its profile

    def __eq__(self, other: object) -> bool:  # equal values are equal params, whichever file they came from
        if not isinstance(other, BaseModel):
            return NotImplemented
        return type(self) is type(other) and self.__dict__ == other.__dict__

    @property
    def file_text(self) -> str | None:
        """The text of the params file these params were read from (:func:`load`); None when built in code."""
        return self._file_text

    @property
    def workers(self):
        """Where per-shape loops run (``graspaug.parallel.Workers``); not a DVC param: results do not depend on it."""
        from graspaug.parallel import Workers

        return Workers(n_jobs=self.n_jobs, executor=self.executor, scheduler=self.scheduler)


def params_model(doc: str, **sections: type | tuple[type, str]) -> type[BaseParams]:
    """A params model named ``Params`` in the calling module (bind it to that name there): the
    shared keys plus ``sections`` (section name → settings class, or (class, description); each
    defaulted by its class, described by its docstring unless given)."""
    unknown = set(sections) - set(SECTIONS)
    if unknown:
        raise ValueError(f"not sections of params.yaml: {sorted(unknown)}")
    fields = {}
    for key in sorted(sections, key=SECTIONS.index):
        cls, description = sections[key] if isinstance(sections[key], tuple) else (sections[key], sections[key].__doc__)
        fields[key] = (cls, Field(default_factory=cls, description=description))
    return create_model(
        "Params", __base__=BaseParams, __doc__=doc, __module__=sys._getframe(1).f_globals["__name__"], **fields
    )


def _section_class(model: type, loc: tuple) -> type | None:
    """The settings class at ``loc`` (a path of field names or aliases) inside ``model``."""
    cls: Any = model
    for part in loc:
        fields = getattr(cls, "model_fields", None) or getattr(cls, "__pydantic_fields__", {})
        match = next((info for name, info in fields.items() if part in (name, info.alias)), None)
        if match is None:
            return None
        cls = match.annotation
    return cls


def _one_line(error: dict, model: type) -> str:
    """One line naming the key: ``gqcnn.train.steps: Input should be greater than or equal to 1; got 0``."""
    loc = error["loc"]
    key = ".".join(str(p) for p in loc) or "params"
    message = error["msg"].removeprefix("Value error, ")
    if error["type"] == "value_error":  # our own checks name their keys
        head = message.split(": ")[0]
        if " " in head or ": " not in message:
            return f"{key}: {message}"
        if not loc or head.split(".")[0] == str(loc[0]):
            return message  # named from the top (``critic_eval.alphas: …``)
        return f"{key}.{message}"  # a settings class names its own field: put its section in front
    if error["type"] in ("extra_forbidden", "unexpected_keyword_argument"):
        section = _section_class(model, tuple(loc[:-1]))
        fields = getattr(section, "model_fields", None) or getattr(section, "__pydantic_fields__", {})
        allowed = ", ".join(info.alias or name for name, info in fields.items())
        return f"{key}: unknown key; allowed here: {allowed}"
    return f"{key}: {message}; got {error.get('input')!r}"


def parse(raw: Any, model: type[BaseParams]) -> BaseParams:
    """``model`` from a parsed params.yaml mapping; sections ``model`` does not hold are left
    unread. Raises :class:`ParamsError`."""
    if raw is not None and not isinstance(raw, dict):
        raise ParamsError(f"params: expected a mapping of keys, got {raw!r}")
    raw = dict(raw or {})
    known = set(BaseParams.model_fields) | set(SECTIONS)
    for key in raw:
        if key not in known:
            allowed = ", ".join([*BaseParams.model_fields, *SECTIONS])
            raise ParamsError(f"{key}: unknown key; allowed here: {allowed}")
    raw = {key: value for key, value in raw.items() if key in model.model_fields}
    try:
        return model.model_validate(raw)
    except ValidationError as exc:
        raise ParamsError(_one_line(exc.errors()[0], model)) from None


def _duplicate_key(node: yaml.Node, prefix: str = "") -> str | None:
    """The first key given twice in one mapping of the composed YAML ``node`` (depth first), as
    ``key.path at line L (first at line F)``; None when every mapping's keys are distinct. YAML forbids
    duplicates, PyYAML keeps the last value silently, DVC refuses the file: params are read one way only."""
    if isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            found = _duplicate_key(item, f"{prefix}{i}.")
            if found:
                return found
    if not isinstance(node, yaml.MappingNode):
        return None
    first: dict[Any, int] = {}
    for key_node, value_node in node.value:
        if key_node.tag == "tag:yaml.org,2002:merge":  # `<<: *anchor` keys are a merge, not a key
            continue
        key = key_node.value if isinstance(key_node, yaml.ScalarNode) else id(key_node)
        line = key_node.start_mark.line + 1
        if key in first:
            return f"{prefix}{key} at line {line} (first at line {first[key]})"
        first[key] = line
        found = _duplicate_key(value_node, f"{prefix}{key}.")
        if found:
            return found
    return None


def parse_yaml(text: str, name: str = "params") -> Any:
    """The data of YAML ``text`` (``name`` names it in errors), refusing a key given twice in one mapping.

    Raises :class:`ParamsError`: ``<name>: duplicate key ingest.surface.size_m at line 12 (first at line 10)``, or
    ``<name>: not valid YAML at line L, column C (problem)``."""
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        duplicate = _duplicate_key(node) if node is not None else None
        if duplicate:
            raise ParamsError(f"{name}: duplicate key {duplicate}; give each key once")
        return loader.construct_document(node) if node is not None else None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ParamsError(f"{name}: not valid YAML{where} ({problem})") from None
    finally:
        loader.dispose()


def read_yaml(path: str | Path, text: str | None = None) -> Any:
    """The parsed params file (its ``text`` when already read); raises :class:`ParamsError` for a missing or broken
    file (with the line) and for a key given twice (:func:`parse_yaml`)."""
    path = Path(path)
    if text is None and not path.exists():
        raise ParamsError(f"{path}: params file not found")
    return parse_yaml(path.read_text() if text is None else text, str(path))


def load(path: str | Path, model: type[BaseParams]) -> BaseParams:
    """Read and check the sections of ``model`` in the params file at ``path``; raises :class:`ParamsError`. The
    file's text stays with them (``file_text``): a report names the profile its header names."""
    path = Path(path)
    if not path.exists():
        raise ParamsError(f"{path}: params file not found")
    text = path.read_text()
    params = parse(read_yaml(path, text), model)
    params._file_text = text
    return params
