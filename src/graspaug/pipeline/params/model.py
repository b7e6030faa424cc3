"""The whole ``params.yaml``: every section's settings class in one model.

Stages read only their own sections (:mod:`graspaug.pipeline.params.base`); this model is for what looks at
every key at once: ``graspaug profile`` (which validates and writes a complete params.yaml), the
JSON Schema for editors, and the tests. Each section is a settings class
(:func:`graspaug.settings.settings`) defined in ``graspaug/params/<section>.py``; a section that
configures a library object *is* that object's settings class (``gqcnn.net`` is
:class:`~graspaug.nets.settings.GQCNNConfig`, ``grasps.sampler`` is
:class:`~graspaug.grasping.settings.AntipodalSettings`, …), so every default lives on one field.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import model_validator

from graspaug.io.settings import CorpusSettings
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import BaseParams, ParamsError, load, params_model, parse
from graspaug.pipeline.params.critic_eval import CriticEvalParams
from graspaug.pipeline.params.embed import EmbedParams
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.lifelong import LifelongParams
from graspaug.pipeline.params.render import RenderParams
from graspaug.pipeline.params.score import ScoreParams
from graspaug.pipeline.params.sim import SimParams
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.settings import is_settings
from graspaug.training.settings import check_networks

_Sections = params_model(
    "All parameters of the pipeline (the whole ``params.yaml``).",
    data=(CorpusSettings, "Where the shape corpus comes from."),
    ingest=IngestParams,
    voxelize=VoxelizeParams,
    ae=AEParams,
    embed=EmbedParams,
    critic_eval=CriticEvalParams,
    grasps=GraspsParams,
    score=ScoreParams,
    generate=GenerateParams,
    render=RenderParams,
    gqcnn=GQCNNParams,
    lifelong=LifelongParams,
    sim=SimParams,
)


def networks_problem(generate: GenerateParams, gqcnn: GQCNNParams) -> str | None:
    """Why ``gqcnn.networks`` cannot be trained with these ``generate`` and ``gqcnn`` settings (one line naming the
    key: :func:`graspaug.training.variants.check_networks`; a ``views`` network also needs ``gqcnn.extra_views``),
    or None."""
    sizes = (generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes)
    problem = check_networks(gqcnn.networks, *sizes, gqcnn.pools, gqcnn.control_ratios)
    if problem is None and not gqcnn.extra_views and any(str(n[0]) == "views" for n in gqcnn.networks):
        problem = "gqcnn.networks: a views network needs gqcnn.extra_views > 0 (extra camera views of its base shapes)"
    return problem


class Params(_Sections):
    """All parameters of the pipeline (the whole ``params.yaml``)."""

    @model_validator(mode="after")
    def _networks_generated(self) -> Params:
        """The explicit networks (``gqcnn.networks``) are ones ``generate`` makes the shapes of: checked with the
        whole file (``graspaug profile``, the check_params stage); train_gqcnn checks them again itself."""
        problem = networks_problem(self.generate, self.gqcnn)
        if problem:
            raise ValueError(problem)
        return self


def parse_params(raw: Any) -> BaseParams:
    """Typed :class:`Params` from a parsed params.yaml mapping; raises :class:`ParamsError`."""
    return parse(raw, Params)


def load_params(path: str | Path = "params.yaml") -> BaseParams:
    """Read and check the whole params.yaml; raises :class:`ParamsError` (also for a missing or broken file)."""
    return load(path, Params)


def params_dict(params: BaseParams | None = None) -> dict:
    """``params`` (default: the defaults) as plain YAML-ready data, keys as params.yaml spells them."""
    return (params or Params()).model_dump(mode="json", by_alias=True)


def json_schema() -> str:
    """JSON Schema of params.yaml (for editors: ``# yaml-language-server: $schema=params.schema.json``)."""
    schema = Params.model_json_schema(by_alias=True)
    schema["title"] = "graspaug params.yaml"
    return json.dumps(schema, indent=2, ensure_ascii=False) + "\n"


__all__ = [
    "Params",
    "ParamsError",
    "load_params",
    "parse_params",
    "params_dict",
    "json_schema",
    "is_settings",
    "AEParams",
    "CriticEvalParams",
    "EmbedParams",
    "GenerateParams",
    "GQCNNParams",
    "GraspsParams",
    "IngestParams",
    "RenderParams",
    "ScoreParams",
    "SimParams",
    "VoxelizeParams",
]
