"""The pipeline's parameters: ``params.yaml`` read into the library's own settings classes.

Each params section is a settings class (:func:`graspaug.settings.settings`); a section that
configures a library object *is* that object's settings class (``gqcnn.net`` is
:class:`~graspaug.nets.gqcnn.GQCNNConfig`, ``grasps.sampler`` is
:class:`~graspaug.grasping.antipodal.AntipodalSettings`, …), so every default lives on one
field. pydantic checks types, ranges and unknown keys; :func:`load_params` turns the first
problem into a :class:`ParamsError`, one line naming the key and what is allowed.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError, model_validator

from graspaug.geometry.settings import DecodeSettings, SurfaceSettings
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.settings import AntipodalSettings, Perturbations, QualitySettings
from graspaug.io.settings import CorpusSettings
from graspaug.nets.settings import AEConfig, GQCNNConfig
from graspaug.render.settings import RenderSettings
from graspaug.settings import Field, is_settings, settings
from graspaug.sim.catalog import EVERYDAY_OBJECTS
from graspaug.sim.settings import CellLayout, CEMSettings, DepthNoise, HandSettings, ObjectPhysics, SamplerSettings, TrialSettings
from graspaug.training.settings import AETrainConfig, TrainSettings


class ParamsError(ValueError):
    """Invalid params; the message is one line naming the key."""


def _floats_written_as_floats(raw: Any, section: str, key: str) -> Any:
    written = (raw or {}).get(key) or [] if isinstance(raw, dict) else []
    if any(isinstance(value, int) and not isinstance(value, bool) for value in written):
        raise ValueError(f"{section}.{key}: write every ratio as a float (1.0, not 1): DVC names the networks' folders after them; got {written}")
    return raw


@settings
class IngestParams:
    """Checking, rebuilding, sizing and splitting the shapes."""

    max_faces: int = Field(1_000_000, ge=1, description="A file with more triangles is rejected.")
    max_file_mb: float = Field(100.0, gt=0, description="A larger file is rejected before it is read, MB.")
    min_shapes: int = Field(10, ge=1, description="The stage fails if fewer shapes survive the checks.")
    test_fraction: float = Field(0.2663, gt=0, le=0.9, description="Share of shapes in the test split (0.2663 = the paper's 363 test : 1000 train).")
    surface: SurfaceSettings = Field(default_factory=SurfaceSettings, description="How each shape's closed outer surface is rebuilt and sized.")


@settings
class VoxelizeParams:
    """Solid occupancy grids for the AutoEncoder."""

    resolution: Literal[16, 32, 64, 128] = Field(32, description="Voxels per side R (32 on CPU, 64 in the paper).")
    margin: int = Field(1, ge=0, le=4, description="Empty voxels kept around the shape's largest extent.")


@settings
class AEParams:
    """AutoEncoder-Critic network and its two training phases (paper Section III)."""

    net: AEConfig = Field(default_factory=AEConfig, description="Layer sizes.")
    train: AETrainConfig = Field(default_factory=AETrainConfig, description="The two training phases.")


@settings
class EmbedParams:
    """Latents of every shape and their t-SNE map."""

    perplexity: float = Field(30.0, gt=0, description="t-SNE perplexity (lowered automatically below the number of shapes).")


@settings
class CriticEvalParams:
    """The paper's critic study: outliers of decoded interpolations, AE vs its λ = 0 control vs AE-Critic."""

    n_shapes: int = Field(200, ge=2, description="Random train shapes to draw pairs from (paper: 200).")
    n_pairs: int = Field(68, ge=1, description="Random pairs among them; 6 weights each gives 408 shapes per model (paper: ~409).")
    alphas: tuple[float, ...] = Field((0.0, 0.1, 0.2, 0.3, 0.4, 0.5), description="Interpolation weights in [0, 1], distinct in their first two decimals.")
    threshold: float = Field(0.5, gt=0, le=1, description="Occupancy threshold of decoded grids.")
    n_examples: int = Field(4, ge=1, description="Interpolation sequences drawn in the picture.")
    n_bootstrap: int = Field(2000, ge=100, description="Bootstrap resamples of the pairs for the 95% intervals.")

    def __post_init__(self) -> None:
        if not self.alphas or not all(0 <= a <= 1 for a in self.alphas):
            raise ValueError(f"critic_eval.alphas: must be a non-empty list of weights in [0, 1]; got {list(self.alphas)}")
        if len({f"{a:.2f}" for a in self.alphas}) != len(self.alphas):
            raise ValueError(f"critic_eval.alphas: weights must differ in the first two decimals (they name the metrics); got {list(self.alphas)}")


@settings
class GraspsParams:
    """Antipodal grasps on every shape, labelled by robust Ferrari-Canny (Dex-Net 2.0)."""

    threshold: float = Field(0.002, ge=0, description="A grasp succeeds when its robust ε exceeds this (Dex-Net 2.0, with the torque scaling and object size of the defaults).")
    gripper: ParallelJawGripper = Field(default_factory=ParallelJawGripper, description="The Franka Panda hand every grasp is made for.")
    sampler: AntipodalSettings = Field(default_factory=AntipodalSettings, description="Antipodal grasp sampling on the mesh.")
    quality: QualitySettings = Field(default_factory=QualitySettings, description="The grasp wrench model of Ferrari-Canny ε.")
    perturbations: Perturbations = Field(default_factory=Perturbations, description="The robust metric's perturbations.")


@settings
class ScoreParams:
    """Rarity (eq. 3-4 on AE-Critic latents) and graspness of every shape."""

    k: int = Field(20, ge=1, description="Neighbours in the rarity score, eq. (3)-(4) (scikit-learn LOF default: 20).")
    bins: int = Field(20, ge=2, description="Bins of the graspness and rarity histograms.")


@settings
class GenerateParams:
    """New shapes from rare and graspable neighbours of each base set (paper Section III-C)."""

    base_sizes: tuple[int, ...] = Field((50, 200), description="Base set sizes drawn from the train split (paper: 50, 100, 200); smaller sets lie inside larger ones.")
    ratios: tuple[float, ...] = Field((0.0, 1.0), description="Augmentation ratios generated:base (paper: 1:0, 1:0.5, 1:1, 1:1.5, 1:2; the study and paper profiles run all five, the CPU default 1:0 and 1:1), written as floats; each pool holds max ratio × base size shapes.")
    percentile: float = Field(75.0, ge=0, le=99, description="Shapes above this percentile of rarity, and separately of graspness, in the base set are paired (top 25%).")
    first_neighbour: int = Field(2, ge=1, description="N: pair each selected shape with its N-th ... (N+K)-th nearest selected neighbours (1 = nearest; 2 avoids near-duplicates).")
    extra_neighbours: int = Field(3, ge=0, description="K: see first_neighbour. Widened (logged) if a pool runs dry, see alphas.")
    alphas: tuple[float, ...] = Field((0.5, 0.3), description="Interpolation weights in (0, 0.5]. If a pool runs dry, 0.4, 0.2, 0.1, 0.05 are added, then K widens, then the percentile drops by 5s (each step logged).")
    n_examples: int = Field(6, ge=1, description="Parent pairs drawn with their child in the picture.")
    decode: DecodeSettings = Field(default_factory=DecodeSettings, description="Decoded grid → mesh.")

    @model_validator(mode="before")
    @classmethod
    def _ratios_are_floats(cls, raw: Any) -> Any:
        return _floats_written_as_floats(raw, "generate", "ratios")

    def __post_init__(self) -> None:
        if not self.base_sizes or any(b < 2 for b in self.base_sizes) or len(set(self.base_sizes)) != len(self.base_sizes):
            raise ValueError(f"generate.base_sizes: must be distinct sizes >= 2; got {list(self.base_sizes)}")
        if not self.ratios or any(r < 0 for r in self.ratios) or max(self.ratios) <= 0:
            raise ValueError(f"generate.ratios: must be ratios >= 0, the largest > 0; got {list(self.ratios)}")
        if not self.alphas or not all(0 < a <= 0.5 for a in self.alphas) or len(set(self.alphas)) != len(self.alphas):
            raise ValueError(f"generate.alphas: must be distinct weights in (0, 0.5]; got {list(self.alphas)}")


@settings
class RenderParams(RenderSettings):
    """Dex-Net 2.0 style depth crops of every grasp seen from above (the GQ-CNN's data)."""

    shard_rows: int = Field(20000, ge=1, description="Datapoints per .npy shard.")
    n_examples: int = Field(24, ge=2, description="Crops in the example picture (half positive, half negative when there are enough).")


@settings
class GQCNNParams:
    """GQ-CNN networks per base size × augmentation ratio (paper Section IV-C), their training and the experiment's design.

    Per training seed: a 1:0 network (the base set alone) at every base size of `generate`;
    `targeted`, `random` (random-pair interpolants) and `real` (more real train shapes, the
    positive control for augmentation) at every nonzero ratio of `augment_base_sizes`; the
    `ceiling` (every train shape outside validation). Every network of a seed starts from the same weights and noise
    stream; all are validated on the same `val_shapes` train shapes that no network trains on.
    """

    net: GQCNNConfig = Field(default_factory=GQCNNConfig, description="Layer sizes.")
    train: TrainSettings = Field(default_factory=TrainSettings, description="SGD schedule, checkpoint choice and train-time noise.")
    val_shapes: int = Field(100, ge=1, description="Train-split shapes outside every base set held out for validation (checkpoints and the best ratio are chosen on them), the same for every network and seed.")
    seeds: tuple[int, ...] = Field((0, 1, 2, 3), description="Training seeds, the replicates of the paired design; intervals need at least 2 (4 by default, what fits make repro in 30 min on 2 cores with 3 float32 members; the study profile: 5; the 95% t-interval is 3.18 standard errors wide on each side with 4 seeds, 2.78 with 5, 4.30 with 3).")
    augment_base_sizes: tuple[int, ...] = Field((50,), description="Base sizes that get augmented networks: targeted, random and real at every nonzero ratio of generate.ratios (the others get their 1:0 network only; study profile: all).")
    ceiling: bool = Field(False, description="Also train one network per seed on every train shape outside validation (how much of the gap augmentation closes; study and paper profiles: on).")
    members: int = Field(3, ge=1, le=64, description="GQ-CNNs trained per network, each from its own initial weights and noise stream (member m of every network of a seed shares them, so the design stays paired); the network's P(success) is their mean (an ensemble, validated, tested and planned with). Over 8 float32 seeds the seed-to-seed SD of the default contrasts is 0.015-0.017 AP with 1 member, 0.007-0.012 with 2, 0.006-0.008 with 3 and 0.006-0.008 with 4 (studies/gqcnn_members.py): 3 is the fewest that meets SD <= 0.01 (4 held-out seeds: 0.002-0.009); each member costs one more network's training time, planning grows less (study and paper profiles: 1).")

    def __post_init__(self) -> None:
        if not self.seeds or len(set(self.seeds)) != len(self.seeds) or min(self.seeds) < 0:
            raise ValueError(f"gqcnn.seeds: must be distinct seeds >= 0; got {list(self.seeds)}")


@settings
class SimParams:
    """Simulated Panda pick-and-place trials: the networks before and after augmentation, the `real` pool's network and a random antipodal grasp (paper Section IV-E)."""

    objects: tuple[str, ...] = Field(tuple(EVERYDAY_OBJECTS), description=f"Everyday objects of pybullet_data to pick (any of {', '.join(EVERYDAY_OBJECTS)}).")
    n_test_objects: int = Field(20, ge=0, description="Held-out test shapes (test split of data/shapes, a seeded choice) picked as well.")
    objects_path: str | None = Field(None, description="A folder of mesh files (.obj, .stl, .ply; one object each, named by file stem) picked as well, loaded and scaled as the corpus's shapes (ingest.surface); a broken mesh is skipped with its reason logged. Relative to the project or absolute; DVC tracks this value, not the folder's files.")
    attempts: int = Field(2, ge=1, description="Attempts per object and arm (paper: 10); each attempt drops the object anew from a seeded pose, the same for every arm. Default: 28 objects × 2 attempts × 4 training seeds = 224 paired attempts per network arm.")
    base_size: int = Field(50, ge=2, description="Base size B of the networks compared: B-0 (before) and B at the ratio chosen on validation AP (after, and the `real` pool's network at that ratio); one of gqcnn.augment_base_sizes.")
    n_bootstrap: int = Field(2000, ge=100, description="Bootstrap resamples of the objects for the contrasts' 95% intervals.")
    n_pictures: int = Field(3, ge=0, description="Trials per arm (first attempts of the first objects) drawn with their depth image, grasp and pick frames.")
    vhacd_resolution: int = Field(100000, ge=10000, description="V-HACD voxel resolution of the convex decompositions (cached per mesh in ~/.cache/graspaug/sim or $GRASPAUG_CACHE).")
    physics: ObjectPhysics = Field(default_factory=ObjectPhysics, description="Mass and friction of each object, drawn per object from the global seed.")
    sensor: DepthNoise = Field(default_factory=DepthNoise, description="The overhead depth sensor's noise, modelled on a RealSense D435 at 0.65 m.")
    cell: CellLayout = Field(default_factory=CellLayout, description="The cell: table, robot, bin, overhead camera, physics step.")
    hand: HandSettings = Field(default_factory=HandSettings, description="How the hand moves and holds.")
    trial: TrialSettings = Field(default_factory=TrialSettings, description="The pick-and-place motion script.")
    sampler: SamplerSettings = Field(default_factory=SamplerSettings, description="Antipodal grasp seeds on the depth image.")
    cem: CEMSettings = Field(default_factory=CEMSettings, description="Cross-entropy refinement of the seeds by the GQ-CNN.")

    def __post_init__(self) -> None:
        unknown = [name for name in self.objects if name not in EVERYDAY_OBJECTS]
        if unknown or len(set(self.objects)) != len(self.objects):
            raise ValueError(f"sim.objects: must be distinct names among {', '.join(EVERYDAY_OBJECTS)}; got {list(self.objects)}")
        if not self.objects and self.n_test_objects == 0 and self.objects_path is None:
            raise ValueError("sim.objects: no objects to pick (sim.objects is empty, sim.n_test_objects is 0 and no sim.objects_path)")
        if self.sampler.min_depth_offset > self.sampler.max_depth_offset:
            raise ValueError(f"sim.sampler.max_depth_offset: must be >= sim.sampler.min_depth_offset ({self.sampler.min_depth_offset}); got {self.sampler.max_depth_offset}")


class Params(BaseModel):
    """All parameters of the pipeline (the whole ``params.yaml``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    seed: int = Field(0, ge=0, description="Seeds every random choice: the split, network initialisation and batches, critic-study pairs, t-SNE, grasp sampling and perturbations.")
    device: Literal["auto", "cpu", "cuda"] = Field("auto", description="Torch device: `auto` (CUDA when present), `cpu` or `cuda`.")
    n_jobs: int = Field(2, ge=-1, description="Worker processes for per-shape loops (-1: all cores).")
    executor: Literal["joblib", "dask"] = Field("joblib", description="Where per-shape loops (ingest, voxelize, grasps, generate, render, sim) run: `joblib` (n_jobs local processes) or `dask` (the Dask cluster at `scheduler`; needs `pip install 'graspaug[dask]'` and workers that see the project at the same path).")
    scheduler: str | None = Field(None, description="Dask scheduler address when executor is `dask`, e.g. tcp://10.0.0.5:8786.")
    data: CorpusSettings = Field(default_factory=CorpusSettings, description="Where the shape corpus comes from.")
    ingest: IngestParams = Field(default_factory=IngestParams, description=IngestParams.__doc__)
    voxelize: VoxelizeParams = Field(default_factory=VoxelizeParams, description=VoxelizeParams.__doc__)
    ae: AEParams = Field(default_factory=AEParams, description=AEParams.__doc__)
    embed: EmbedParams = Field(default_factory=EmbedParams, description=EmbedParams.__doc__)
    critic_eval: CriticEvalParams = Field(default_factory=CriticEvalParams, description=CriticEvalParams.__doc__)
    grasps: GraspsParams = Field(default_factory=GraspsParams, description=GraspsParams.__doc__)
    score: ScoreParams = Field(default_factory=ScoreParams, description=ScoreParams.__doc__)
    generate: GenerateParams = Field(default_factory=GenerateParams, description=GenerateParams.__doc__)
    render: RenderParams = Field(default_factory=RenderParams, description=RenderParams.__doc__)
    gqcnn: GQCNNParams = Field(default_factory=GQCNNParams, description=GQCNNParams.__doc__)
    sim: SimParams = Field(default_factory=SimParams, description=SimParams.__doc__)

    @model_validator(mode="after")
    def _consistent(self) -> Params:
        """Checks across sections: values that must agree are named in both places."""
        agree = (("ae.net.resolution", self.ae.net.resolution, "voxelize.resolution", self.voxelize.resolution),
                 ("gqcnn.net.image_size", self.gqcnn.net.image_size, "render.crop.out_size", self.render.crop.out_size),
                 ("sim.sampler.max_width", self.sim.sampler.max_width, "grasps.gripper.max_width", self.grasps.gripper.max_width))
        for key, value, other, expected in agree:
            if value != expected:
                raise ValueError(f"{key}: must equal {other} ({expected}); got {value}")
        if self.n_jobs == 0:
            raise ValueError("n_jobs: must be >= 1, or -1 for all cores; got 0")
        if self.executor == "dask" and not self.scheduler:
            raise ValueError("scheduler: required when executor is dask (e.g. tcp://10.0.0.5:8786)")
        gen, net = self.generate, self.gqcnn
        if not set(net.augment_base_sizes) <= set(gen.base_sizes):
            raise ValueError(f"gqcnn.augment_base_sizes: must be among generate.base_sizes {list(gen.base_sizes)}; got {list(net.augment_base_sizes)}")
        if self.sim.base_size not in net.augment_base_sizes:
            raise ValueError(f"sim.base_size: must be one of gqcnn.augment_base_sizes {list(net.augment_base_sizes)}; got {self.sim.base_size}")
        return self

    @property
    def workers(self):
        """Where per-shape loops run (``graspaug.parallel.Workers``); not a DVC param: results do not depend on it."""
        from graspaug.parallel import Workers

        return Workers(n_jobs=self.n_jobs, executor=self.executor, scheduler=self.scheduler)


def _section_class(loc: tuple) -> type | None:
    """The settings class at ``loc`` (a path of field names or aliases) inside :class:`Params`."""
    cls: Any = Params
    for part in loc:
        fields = getattr(cls, "model_fields", None) or getattr(cls, "__pydantic_fields__", {})
        match = next((info for name, info in fields.items() if part in (name, info.alias)), None)
        if match is None:
            return None
        cls = match.annotation
    return cls


def _one_line(error: dict) -> str:
    """One line naming the key: ``gqcnn.train.steps: Input should be greater than or equal to 1; got 0``."""
    loc = error["loc"]
    key = ".".join(str(p) for p in loc) or "params"
    message = error["msg"].removeprefix("Value error, ")
    if error["type"] == "value_error":  # our own checks name their keys
        return message if " " not in message.split(": ")[0] else f"{key}: {message}"
    if error["type"] in ("extra_forbidden", "unexpected_keyword_argument"):
        section = _section_class(tuple(loc[:-1]))
        fields = getattr(section, "model_fields", None) or getattr(section, "__pydantic_fields__", {})
        allowed = ", ".join(info.alias or name for name, info in fields.items())
        return f"{key}: unknown key; allowed here: {allowed}"
    return f"{key}: {message}; got {error.get('input')!r}"


def parse_params(raw: Any) -> Params:
    """Typed :class:`Params` from a parsed params.yaml mapping; raises :class:`ParamsError`."""
    if raw is not None and not isinstance(raw, dict):
        raise ParamsError(f"params: expected a mapping of keys, got {raw!r}")
    try:
        return Params.model_validate(raw or {})
    except ValidationError as exc:
        raise ParamsError(_one_line(exc.errors()[0])) from None


def load_params(path: str | Path = "params.yaml") -> Params:
    """Read and check params.yaml; raises :class:`ParamsError` (also for a missing or broken file)."""
    path = Path(path)
    if not path.exists():
        raise ParamsError(f"{path}: params file not found")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ParamsError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    return parse_params(raw)


def params_dict(params: Params | None = None) -> dict:
    """``params`` (default: the defaults) as plain YAML-ready data, keys as params.yaml spells them."""
    return (params or Params()).model_dump(mode="json", by_alias=True)


def json_schema() -> str:
    """JSON Schema of params.yaml (for editors: ``# yaml-language-server: $schema=params.schema.json``)."""
    schema = Params.model_json_schema(by_alias=True)
    schema["title"] = "graspaug params.yaml"
    return json.dumps(schema, indent=2, ensure_ascii=False) + "\n"


__all__ = ["Params", "ParamsError", "load_params", "parse_params", "params_dict", "json_schema", "is_settings"]
