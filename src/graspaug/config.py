"""Typed parameters, read from params.yaml.

One frozen dataclass per params section. Every field says what it is in its
``help`` metadata (the CLI's ``--help`` prints them) and what values it allows.
An unknown key, a wrong type or an out-of-range value raises :class:`ParamsError`
whose message is one line naming the key and what is allowed.
"""
from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml


class ParamsError(ValueError):
    """Invalid params; the message is one line naming the key."""


def param(default: Any, help: str, *, choices: tuple | None = None, ge: float | None = None, le: float | None = None, gt: float | None = None, key: str | None = None) -> Any:
    """A dataclass field with its help text and allowed values; ``key`` is its name in
    params.yaml when that is not a Python identifier (``lambda``)."""
    return field(default=default, metadata={"help": help, "choices": choices, "ge": ge, "le": le, "gt": gt, "key": key})


def _key(f: dataclasses.Field) -> str:
    return f.metadata.get("key") or f.name


@dataclass(frozen=True)
class DataParams:
    """Where the shape corpus comes from."""

    source: str = param("pybullet", "`pybullet`: the 1000 objects of pybullet_data/random_urdfs (URDF mesh scale applied); `folder`: every .obj/.stl/.ply/.off/.glb under `path`, recursively (e.g. a local 3DNet copy).", choices=("pybullet", "folder"))
    path: str | None = param(None, "Folder of meshes when source is `folder`, relative to the project or absolute; its files are taken as meters times `unit_scale`.")
    unit_scale: float = param(1.0, "Meters per file unit for `folder` sources (0.001 for millimeter files).", gt=0)
    limit: int | None = param(None, "Use only the first `limit` files in sorted order (null: all).", ge=1)


@dataclass(frozen=True)
class IngestParams:
    """Checking, rebuilding, sizing and splitting the shapes."""

    max_faces: int = param(1_000_000, "A file with more triangles is rejected.", ge=1)
    max_file_mb: float = param(100.0, "A larger file is rejected before it is read, MB.", gt=0)
    min_shapes: int = param(10, "The stage fails if fewer shapes survive the checks.", ge=1)
    surface_resolution: int = param(96, "Marching-cubes samples along a shape's largest extent when its closed outer surface is rebuilt (cell = extent / resolution).", ge=16, le=512)
    finest_surface_resolution: int = param(160, "Upper limit of that resolution for shapes made of thin convex parts (lattices), which get a finer grid.", ge=16, le=512)
    cells_per_thickness: float = param(6.0, "Field cells across a typical (median) convex part; sets the finer grid for thin-part shapes (0: always surface_resolution).", ge=0)
    face_budget: int = param(5000, "Triangles per outer surface after quadric decimation.", ge=100)
    size_rule: str = param("mid", "Which extent the size rule fixes: `min`, `mid` (the middle one) or `max`.", choices=("min", "mid", "max"))
    size_m: float = param(0.06, "That extent after scaling, meters. Default: middle extent 0.06 m, so a Franka Panda (0.08 m opening) closes across the two smaller extents of most objects.", gt=0)
    max_dropped: float = param(0.1, "Reject a shape whose largest connected piece misses more than this share of its volume.", ge=0, le=1)
    max_gap: float = param(0.05, "Widest hole or crack bridged when an open mesh (a scan) is rebuilt as a solid, as a share of the shape's largest extent (0.05: 5 mm on a 10 cm object); a mesh that needs a wider one bridged is rejected. Openings wider than this (a mug's top) stay open, narrower concave gaps get filled.", ge=0, le=0.5)
    test_fraction: float = param(0.2663, "Share of shapes in the test split (0.2663 = the paper's 363 test : 1000 train).", gt=0, le=0.9)


@dataclass(frozen=True)
class VoxelizeParams:
    """Solid occupancy grids for the AutoEncoder."""

    resolution: int = param(32, "Voxels per side R (32 on CPU, 64 in the paper).", choices=(16, 32, 64, 128))
    margin: int = param(1, "Empty voxels kept around the shape's largest extent.", ge=0, le=4)


@dataclass(frozen=True)
class AEParams:
    """AutoEncoder-Critic network and its two training phases."""

    z_dim: int = param(128, "Latent size (paper: 128).", ge=2)
    base_width: int = param(16, "Channels of the first conv layer; doubles per down-sampling layer up to top_width (paper profile: 64).", ge=1)
    top_width: int = param(128, "Channels of the 4×4×4 map before the FC layer (paper: 512).", ge=1)
    batch_size: int = param(16, "Shapes per batch (16 reached a higher test IoU than 32 in the same CPU time).", ge=2)
    epochs_ae: int = param(40, "Phase 1 epochs: plain AutoEncoder, binary cross-entropy.", ge=0)
    epochs_critic: int = param(8, "Phase 2 epochs: AE-Critic initialised from phase 1.", ge=0)
    critic_warmup: int = param(1, "First phase-2 epochs in which only the critic learns (the AE's eq. (2) term then starts from a trained critic).", ge=0)
    lr_ae: float = param(1e-3, "Phase 1 Adam learning rate (paper: 1e-3).", gt=0)
    lr_ae_critic: float = param(1e-4, "Phase 2 Adam learning rate of the AutoEncoder (paper: 1e-4).", gt=0)
    lr_critic: float = param(1e-3, "Phase 2 Adam learning rate of the Critic (paper: 1e-3).", gt=0)
    gamma: float = param(0.2, "γ of eq. (1): the critic sees γx + (1−γ)x̂ as non-interpolated (ACAI: 0.2).", ge=0, le=1)
    lam: float = param(0.5, "λ of eq. (2): weight of the critic term in the AE loss (ACAI: 0.5).", ge=0, key="lambda")
    flips: bool = param(True, "Flip training grids along random axes (the AE learns shape, not pose).")


@dataclass(frozen=True)
class EmbedParams:
    """Latents of every shape and their t-SNE map."""

    perplexity: float = param(30.0, "t-SNE perplexity (lowered automatically below the number of shapes).", gt=0)


@dataclass(frozen=True)
class CriticEvalParams:
    """The paper's critic study: outliers of decoded interpolations, AE vs AE-Critic."""

    n_shapes: int = param(200, "Random train shapes to draw pairs from (paper: 200).", ge=2)
    n_pairs: int = param(68, "Random pairs among them; 6 weights each gives 408 shapes per model (paper: ~409).", ge=1)
    alphas: list[float] = param((0.0, 0.1, 0.2, 0.3, 0.4, 0.5), "Interpolation weights.")
    threshold: float = param(0.5, "Occupancy threshold of decoded grids.", gt=0, le=1)
    n_examples: int = param(4, "Interpolation sequences drawn in the picture.", ge=1)


@dataclass(frozen=True)
class GraspsParams:
    """Antipodal grasps on every shape, labelled by robust Ferrari-Canny (Dex-Net 2.0)."""

    n_grasps: int = param(100, "Grasps sampled per shape (Dex-Net 2.0: up to 100; EGAD: 100).", ge=1)
    threshold: float = param(0.002, "A grasp succeeds when its robust ε exceeds this (Dex-Net 2.0, with the torque scaling and object size below).", ge=0)
    friction_coef: float = param(0.5, "Friction coefficient μ for sampling and quality (Dex-Net: 0.5); also the mean of the perturbed μ.", gt=0, le=1)
    cone_faces: int = param(8, "Faces of the polyhedral friction cone (Dex-Net: 8).", ge=3, le=32)
    torque_scaling: float = param(1000.0, "s in the wrench [f; s·τ] (1/m). With s = 1000, soft fingers bound ε by π r² μ s = 0.039 and 0.002 splits grasps as in Dex-Net 2.0.", gt=0)
    max_width: float = param(0.08, "Gripper opening in m (Franka Panda: 0.08).", gt=0)
    finger_radius: float = param(0.005, "Soft-finger contact radius in m for the torsion columns (Dex-Net: 0.005).", ge=0)
    min_contact_dist: float = param(0.0025, "Contacts closer than this (m) are rejected (Dex-Net: 2.5 mm).", ge=0)
    coverage_dist: float = param(0.0025, "Grasp centers closer than this (m) to a kept one are dropped (EGAD: 2.5 mm; 0 disables).", ge=0)
    tries_per_point: int = param(2, "Grasp axes drawn per sampled surface point (Dex-Net: 2).", ge=1)
    oversample: int = param(5, "Candidates per missing grasp in the first round; doubles each round (Dex-Net: 5).", ge=1)
    max_rounds: int = param(5, "Sampling rounds before giving up on a shape (Dex-Net: 5-10).", ge=1, le=10)
    max_surface_points: int = param(100, "Surface points sampled per round at most (Dex-Net: 100).", ge=1)
    n_samples: int = param(25, "Perturbed samples per grasp in the robust metric (Dex-Net: 25).", ge=1)
    center_sigma: float = param(0.005, "Std of the grasp center perturbation in m.", ge=0)
    axis_sigma: float = param(0.001, "Std of the grasp axis rotation in rad.", ge=0)
    object_translation_sigma: float = param(0.01, "Std of the object translation in m.", ge=0)
    object_rotation_sigma: float = param(0.01, "Std of the object rotation in rad.", ge=0)
    friction_sigma: float = param(0.1, "Std of the perturbed friction coefficient (truncated to [0, 1]).", ge=0)


@dataclass(frozen=True)
class ScoreParams:
    """Rarity (eq. 3-4 on AE-Critic latents) and graspness of every shape."""

    k: int = param(20, "Neighbours in the rarity score, eq. (3)-(4) (scikit-learn LOF default: 20).", ge=1)
    bins: int = param(20, "Bins of the graspness and rarity histograms.", ge=2)


@dataclass(frozen=True)
class GenerateParams:
    """New shapes from rare and graspable neighbours of each base set (paper Section III-C)."""

    base_sizes: list[int] = param((50, 100, 200), "Base set sizes drawn from the train split (paper: 50, 100, 200); smaller sets lie inside larger ones.")
    ratios: list[float] = param((0.0, 0.5, 1.0, 1.5, 2.0), "Augmentation ratios generated:base (paper: 1:0 ... 1:2); each pool holds max ratio × base size shapes.")
    percentile: float = param(75.0, "Shapes above this percentile of rarity, and separately of graspness, in the base set are paired (top 25%).", ge=0, le=99)
    first_neighbour: int = param(2, "N: pair each selected shape with its N-th ... (N+K)-th nearest selected neighbours (1 = nearest; 2 avoids near-duplicates).", ge=1)
    extra_neighbours: int = param(3, "K: see first_neighbour. Widened (logged) if a pool runs dry, see alphas.", ge=0)
    alphas: list[float] = param((0.5, 0.3), "Interpolation weights in (0, 0.5]. If a pool runs dry, 0.4, 0.2, 0.1, 0.05 are added, then K widens, then the percentile drops by 5s (each step logged).")
    threshold: float = param(0.5, "Occupancy threshold of decoded grids.", gt=0, le=1)
    opening: int = param(1, "Binary opening iterations on the decoded solid (removes one-voxel spurs).", ge=0, le=3)
    min_voxels: int = param(100, "A decode with a largest piece smaller than this is rejected (tiny).", ge=1)
    min_main_share: float = param(0.9, "A decode whose largest piece holds less than this share of its voxels is rejected (in pieces).", gt=0, le=1)
    smoothing_iterations: int = param(10, "Humphrey smoothing iterations on the marching-cubes mesh.", ge=0)
    n_examples: int = param(6, "Parent pairs drawn with their child in the picture.", ge=1)


@dataclass(frozen=True)
class RenderParams:
    """Dex-Net 2.0 style depth crops of every grasp seen from above (the GQ-CNN's data)."""

    max_poses: int = param(5, "Most probable stable resting poses rendered per shape.", ge=1)
    min_pose_probability: float = param(0.01, "Stable poses less likely than this are pruned (Dex-Net: 0.01).", ge=0, le=1)
    images_per_pose: int = param(1, "Random camera views per stable pose (Dex-Net 2.0: 5; each view holds every table-parallel grasp).", ge=1)
    max_grasps_per_image: int = param(0, "At most this many grasps per view, a seeded random subset (0: all).", ge=0)
    axis_tolerance_deg: float = param(5.0, "A grasp is rendered in a pose if its jaw axis is within this angle of parallel to the table (deg).", ge=0, le=90)
    approach_distance: float = param(0.1, "Length of the straight approach from above checked for gripper collisions (m).", ge=0)
    camera_distance: list[float] = param((0.65, 0.75), "Range of the camera's distance to its target point on the table (m).")
    camera_tilt_deg: list[float] = param((0.1, 5.0), "Range of the optical axis' angle from straight down (deg).")
    object_offset: float = param(0.1, "The camera aims up to this far from the object in x and y (m), so objects sit off the image center.", ge=0)
    image_width: int = param(640, "Depth image width (px).", ge=32)
    image_height: int = param(480, "Depth image height (px).", ge=32)
    focal_length: float = param(525.0, "fx = fy (px); the principal point is the image center (Primesense/D435 at 640×480: ~525).", gt=0)
    crop_size: int = param(96, "Side of the grasp-centered crop in image pixels (Dex-Net: 96).", ge=1)
    out_size: int = param(32, "Side of the stored crop after block averaging (Dex-Net: 32); must divide crop_size.", ge=1)
    shard_rows: int = param(20000, "Datapoints per .npy shard.", ge=1)
    n_examples: int = param(24, "Crops in the example picture (half positive, half negative when there are enough).", ge=2)


@dataclass(frozen=True)
class GQCNNParams:
    """GQ-CNN networks per base size × augmentation ratio (paper Section IV-C) and their training."""

    filters: int = param(8, "Channels of each conv layer (Dex-Net 2.0 / paper profile: 64; 8 fits the CPU budget).", ge=1)
    fc: int = param(64, "Width of fc3 and fc4 (Dex-Net: 1024).", ge=1)
    pose_fc: int = param(16, "Width of the gripper-depth layer pc1 (Dex-Net: 16).", ge=1)
    pool_after_conv2: bool = param(True, "Max pool after conv2_2 (Dex-Net's 2018 config; 2017: none).")
    steps: int = param(400, "SGD steps per network, the same for every training set (the budget rule).", ge=1)
    batch_size: int = param(64, "Datapoints per step (Dex-Net: 64-128).", ge=2)
    lr: float = param(0.01, "SGD learning rate (Dex-Net: 0.01).", gt=0)
    momentum: float = param(0.9, "SGD momentum (Dex-Net: 0.9).", ge=0, le=1)
    lr_decay: float = param(0.95, "Learning rate factor every decay_steps steps (Dex-Net: 0.95).", gt=0, le=1)
    decay_steps: int = param(100, "Steps between learning-rate decays (Dex-Net: ~0.66 epoch).", ge=1)
    weight_decay: float = param(5e-4, "L2 weight decay (Dex-Net: 5e-4).", ge=0)
    gamma_shape: float = param(1000.0, "Multiplicative noise ~ Gamma(k, 1/k) per image (Dex-Net: k = 1000; 0: off); unlike Dex-Net it scales the gripper depth too, so the object's height relative to the gripper keeps its meaning.", ge=0)
    gp_prob: float = param(0.5, "Chance of adding smooth Gaussian-process noise to an image (Dex-Net: 0.5).", ge=0, le=1)
    gp_sigma: float = param(0.005, "Its standard deviation (m) (Dex-Net: 0.005).", ge=0)
    gp_grid: int = param(8, "Its grid side before upsampling to the image (Dex-Net: 8 for 32 px).", ge=1)
    symmetrize: bool = param(True, "Turn images 180° and flip them about either axis at random (Dex-Net).")
    val_fraction: float = param(0.1, "Share of the training views (whole images) held out for the validation curves; a view is held out or not by a hash of its id and the seed, the same for every ratio and pool.", ge=0, le=0.5)
    log_every: int = param(100, "Steps between DVCLive points (loss, train/val accuracy, val AP).", ge=1)
    seeds: list[int] = param((0,), "Training seeds; each network is trained once per seed (study profile: 0, 1, 2).")
    random_base_sizes: list[int] = param((200,), "Base sizes that also get random-pair augmentation networks (the baseline).")
    random_ratios: list[float] = param((0.5, 1.0, 1.5, 2.0), "Their ratios (ratio 0 is the same network as the targeted one).")


@dataclass(frozen=True)
class SimParams:
    """Simulated Panda pick-and-place trials before and after augmentation (paper Section IV-E)."""

    objects: list[str] = param(("mug", "duck", "teddy", "bunny", "torus", "cube", "cylinder", "prism"), "Everyday objects of pybullet_data to pick (any of mug, duck, teddy, bunny, torus, cube, cylinder, prism).")
    n_test_objects: int = param(2, "Held-out test shapes (test split of data/shapes, a seeded choice) picked as well.", ge=0)
    attempts: int = param(10, "Attempts per object and arm (paper: 10); each attempt drops the object anew from a seeded pose, the same for both arms.", ge=1)
    base_size: int = param(200, "Base size B of the two networks compared: B-0 (before) and B at the report's best ratio (after).", ge=2)
    object_mass: float = param(0.1, "Mass of every object (kg; the random_urdfs objects weigh 0.1).", gt=0)
    object_friction: float = param(0.5, "Lateral friction of the objects (pybullet multiplies it by the partner's: fingers, table).", gt=0)
    finger_friction: float = param(1.0, "Lateral friction of the finger pads.", gt=0)
    table_friction: float = param(0.8, "Lateral friction of the table.", gt=0)
    grip_force: float = param(20.0, "Closing force limit per finger (N; the URDF's effort limit is 20).", gt=0)
    camera_height: float = param(0.65, "Depth camera height above the table, looking straight down (m; paper: 0.65).", gt=0.1)
    image_width: int = param(640, "Depth image width (px).", ge=128)
    image_height: int = param(480, "Depth image height (px).", ge=128)
    focal_length: float = param(525.0, "fx = fy (px); the principal point is the image center.", gt=0)
    drop_offset: float = param(0.05, "Objects are dropped up to this far from the table center in x and y, in a random orientation (m).", ge=0, le=0.15)
    seed_samples: int = param(250, "Antipodal seed grasps per image (Dex-Net: 100-250).", ge=1)
    cem_iters: int = param(3, "Cross-entropy iterations (Dex-Net: 3).", ge=0)
    elite_fraction: float = param(0.25, "Share of the best grasps refit each iteration (Dex-Net: 0.25).", gt=0, le=1)
    gmm_components: int = param(3, "Gaussian mixture components at most; fewer when ceil(0.4 × elites) is smaller.", ge=1)
    gmm_samples: int = param(50, "Grasps drawn from the mixture per iteration (Dex-Net: 50).", ge=1)
    friction_coef: float = param(0.8, "Friction coefficient of the antipodality test on depth edges (Dex-Net: 0.8).", gt=0)
    depth_grad_thresh: float = param(0.0025, "Depth gradient (m per px) that marks an edge pixel (Dex-Net: 0.0025).", gt=0)
    min_dist_from_boundary: int = param(45, "Edge pixels this close to the image border are ignored (px; Dex-Net: 45).", ge=0)
    min_depth_offset: float = param(0.005, "Grasp depth below the surface between the jaws, lowest (m; Dex-Net: 0.005).", ge=0)
    max_depth_offset: float = param(0.04, "... and highest (m; Dex-Net: 0.04).", ge=0)
    antipodal_arm: bool = param(False, "Also run the reference arm `antipodal`: a random antipodal seed grasp, no network (how much the GQ-CNN adds).")
    n_pictures: int = param(3, "Trials per arm (first attempts of the first objects) drawn with their depth image, grasp and pick frames.", ge=0)
    vhacd_resolution: int = param(100000, "V-HACD voxel resolution of the convex decompositions (cached per mesh in ~/.cache/graspaug/sim or $GRASPAUG_CACHE).", ge=10000)


@dataclass(frozen=True)
class Params:
    """All parameters of the pipeline."""

    seed: int = param(0, "Seeds every random choice: the split, network initialisation and batches, critic-study pairs, t-SNE, grasp sampling and perturbations.", ge=0)
    device: str = param("auto", "Torch device: `auto` (CUDA when present), `cpu` or `cuda`.", choices=("auto", "cpu", "cuda"))
    n_jobs: int = param(2, "Worker processes for per-shape loops (-1: all cores).", ge=-1)
    executor: str = param("joblib", "Where per-shape loops (ingest, voxelize, grasps, generate, render, sim) run: `joblib` (n_jobs local processes) or `dask` (the Dask cluster at `scheduler`; needs `pip install 'graspaug[dask]'` and workers that see the project at the same path).", choices=("joblib", "dask"))
    scheduler: str | None = param(None, "Dask scheduler address when executor is `dask`, e.g. tcp://10.0.0.5:8786.")
    data: DataParams = field(default_factory=DataParams)
    ingest: IngestParams = field(default_factory=IngestParams)
    voxelize: VoxelizeParams = field(default_factory=VoxelizeParams)
    ae: AEParams = field(default_factory=AEParams)
    embed: EmbedParams = field(default_factory=EmbedParams)
    critic_eval: CriticEvalParams = field(default_factory=CriticEvalParams)
    grasps: GraspsParams = field(default_factory=GraspsParams)
    score: ScoreParams = field(default_factory=ScoreParams)
    generate: GenerateParams = field(default_factory=GenerateParams)
    render: RenderParams = field(default_factory=RenderParams)
    gqcnn: GQCNNParams = field(default_factory=GQCNNParams)
    sim: SimParams = field(default_factory=SimParams)

    @property
    def workers(self):
        """Where per-shape loops run (``graspaug.parallel.Workers``); not a DVC param: results do not depend on it."""
        from graspaug.parallel import Workers

        return Workers(n_jobs=self.n_jobs, executor=self.executor, scheduler=self.scheduler)


def _type_name(tp: Any) -> str:
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        return " or ".join(_type_name(a) for a in typing.get_args(tp))
    return "null" if tp is type(None) else getattr(tp, "__name__", str(tp))


def _coerce(key: str, value: Any, tp: Any) -> Any:
    """Check ``value`` against the annotation ``tp``; ints are accepted for floats."""
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        for arg in typing.get_args(tp):
            try:
                return _coerce(key, value, arg)
            except ParamsError:
                continue
        raise ParamsError(f"{key}: expected {_type_name(tp)}, got {value!r}")
    if origin is list:
        (item,) = typing.get_args(tp)
        if not isinstance(value, list):
            raise ParamsError(f"{key}: expected a list of {_type_name(item)}, got {value!r}")
        return tuple(_coerce(f"{key}[{i}]", v, item) for i, v in enumerate(value))
    if tp is type(None):
        if value is None:
            return None
    elif tp is float:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return float(value)
    elif tp is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
    elif isinstance(value, tp):
        return value
    raise ParamsError(f"{key}: expected {_type_name(tp)}, got {value!r}")


def _check_range(key: str, value: Any, meta: typing.Mapping) -> None:
    if value is None:
        return
    choices = meta.get("choices")
    if choices is not None and value not in choices:
        raise ParamsError(f"{key}: must be one of {', '.join(map(str, choices))}; got {value!r}")
    for bound, ok, word in (("ge", lambda v, b: v >= b, ">="), ("gt", lambda v, b: v > b, ">"), ("le", lambda v, b: v <= b, "<=")):
        b = meta.get(bound)
        if b is not None and not ok(value, b):
            raise ParamsError(f"{key}: must be {word} {b:g}; got {value!r}")


def _build(cls: type, raw: Any, prefix: str) -> Any:
    if raw is None:
        raw = {}
    if not isinstance(raw, dict):
        raise ParamsError(f"{prefix or 'params'}: expected a mapping of keys, got {raw!r}")
    hints = typing.get_type_hints(cls)
    fields = {_key(f): f for f in dataclasses.fields(cls)}
    unknown = sorted(set(raw) - set(fields))
    if unknown:
        name = f"{prefix}{unknown[0]}"
        raise ParamsError(f"{name}: unknown key; allowed here: {', '.join(fields)}")
    values = {}
    for name, f in fields.items():
        if name not in raw:
            continue
        key = f"{prefix}{name}"
        tp = hints[f.name]
        if dataclasses.is_dataclass(tp):
            values[f.name] = _build(tp, raw[name], f"{key}.")
        else:
            values[f.name] = _coerce(key, raw[name], tp)
            _check_range(key, values[f.name], f.metadata)
    return cls(**values)


def parse_params(raw: Any) -> Params:
    """Typed :class:`Params` from a parsed params.yaml mapping; raises :class:`ParamsError`."""
    params = _build(Params, raw, "")
    for section, key in (("generate", "ratios"), ("gqcnn", "random_ratios")):
        written = ((raw or {}).get(section) or {}).get(key) or []
        if any(isinstance(value, int) for value in written):
            raise ParamsError(f"{section}.{key}: write every ratio as a float (1.0, not 1): DVC names the networks' folders after them; got {written}")
    if params.data.source == "folder" and not params.data.path:
        raise ParamsError("data.path: required when data.source is folder")
    if params.n_jobs == 0:
        raise ParamsError("n_jobs: must be >= 1, or -1 for all cores; got 0")
    if params.executor == "dask" and not params.scheduler:
        raise ParamsError("scheduler: required when executor is dask (e.g. tcp://10.0.0.5:8786)")
    alphas = params.critic_eval.alphas
    if not alphas or not all(0 <= a <= 1 for a in alphas):
        raise ParamsError(f"critic_eval.alphas: must be a non-empty list of weights in [0, 1]; got {list(alphas)}")
    if len({f"{a:.2f}" for a in alphas}) != len(alphas):
        raise ParamsError(f"critic_eval.alphas: weights must differ in the first two decimals (they name the metrics); got {list(alphas)}")
    gen = params.generate
    if not gen.base_sizes or any(b < 2 for b in gen.base_sizes) or len(set(gen.base_sizes)) != len(gen.base_sizes):
        raise ParamsError(f"generate.base_sizes: must be distinct sizes >= 2; got {list(gen.base_sizes)}")
    if not gen.ratios or any(r < 0 for r in gen.ratios) or max(gen.ratios) <= 0:
        raise ParamsError(f"generate.ratios: must be ratios >= 0, the largest > 0; got {list(gen.ratios)}")
    if not gen.alphas or not all(0 < a <= 0.5 for a in gen.alphas) or len(set(gen.alphas)) != len(gen.alphas):
        raise ParamsError(f"generate.alphas: must be distinct weights in (0, 0.5]; got {list(gen.alphas)}")
    render = params.render
    for key, values, lowest, highest in (("camera_distance", render.camera_distance, 0.01, 10.0), ("camera_tilt_deg", render.camera_tilt_deg, 0.0, 89.0)):
        if len(values) != 2 or not lowest <= values[0] <= values[1] <= highest:
            raise ParamsError(f"render.{key}: must be [low, high] with {lowest} <= low <= high <= {highest}; got {list(values)}")
    net = params.gqcnn
    if not net.seeds or len(set(net.seeds)) != len(net.seeds) or min(net.seeds) < 0:
        raise ParamsError(f"gqcnn.seeds: must be distinct seeds >= 0; got {list(net.seeds)}")
    if not set(net.random_base_sizes) <= set(gen.base_sizes):
        raise ParamsError(f"gqcnn.random_base_sizes: must be among generate.base_sizes {list(gen.base_sizes)}; got {list(net.random_base_sizes)}")
    if not set(net.random_ratios) <= set(gen.ratios) or 0.0 in net.random_ratios:
        raise ParamsError(f"gqcnn.random_ratios: must be nonzero ratios among generate.ratios {list(gen.ratios)}; got {list(net.random_ratios)}")
    if render.crop_size % render.out_size or render.crop_size < render.out_size:
        raise ParamsError(f"render.out_size: must divide render.crop_size ({render.crop_size}); got {render.out_size}")
    sim = params.sim
    from graspaug.sim.catalog import EVERYDAY_OBJECTS

    unknown = [name for name in sim.objects if name not in EVERYDAY_OBJECTS]
    if unknown or len(set(sim.objects)) != len(sim.objects):
        raise ParamsError(f"sim.objects: must be distinct names among {', '.join(EVERYDAY_OBJECTS)}; got {list(sim.objects)}")
    if not sim.objects and sim.n_test_objects == 0:
        raise ParamsError("sim.objects: no objects to pick (sim.objects is empty and sim.n_test_objects is 0)")
    if sim.base_size not in gen.base_sizes:
        raise ParamsError(f"sim.base_size: must be one of generate.base_sizes {list(gen.base_sizes)}; got {sim.base_size}")
    if sim.min_depth_offset > sim.max_depth_offset:
        raise ParamsError(f"sim.max_depth_offset: must be >= sim.min_depth_offset ({sim.min_depth_offset}); got {sim.max_depth_offset}")
    return params


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


def describe(cls: type) -> str:
    """Markdown list of a params section's keys, types, defaults and help (for ``--help``)."""
    hints = typing.get_type_hints(cls)
    lines = []
    for f in dataclasses.fields(cls):
        if dataclasses.is_dataclass(hints[f.name]):
            continue
        default = f.default
        lines.append(f"* **{_key(f)}** ({_type_name(hints[f.name])}, default {default!r}): {f.metadata.get('help', '')}")
    return "\n".join(lines)
