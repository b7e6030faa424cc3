"""Where each stage's outputs live, relative to the project root (the data layout in one place).

``dvc.yaml`` declares the same paths as the stages' outs; the README's data contracts
say what each file holds.
"""

from pathlib import Path

# ingest: every object, with no train/test split (per-object work reads this, so a new split reruns none of it)
SHAPES_DIR = Path("data/shapes")
OBJECTS_TABLE = Path("data/objects.parquet")
REJECTS_TABLE = Path("data/rejects.parquet")
# split: the objects table with each shape's split (every stage that tells train from test reads this)
SHAPES_TABLE = Path("data/shapes.parquet")
# voxelize
VOXELS = Path("data/voxels.npz")
# train_ae
AE_MODEL = Path("models/ae.pt")
AE_EXTRA_MODEL = Path("models/ae_extra.pt")  # the critic study's control: phase 2 with λ = 0
AE_CRITIC_MODEL = Path("models/ae_critic.pt")
TRAIN_AE_LIVE = Path("metrics/train_ae")
TRAIN_AE_SUMMARY = Path("metrics/train_ae.json")  # the headline: test IoU per arm, the critic's AUC
TRAIN_AE_REPORT = Path("reports/train_ae/summary.json")  # everything the stage measured
# train_ae_own (one folder per augmented base size B): the own pool's AE-Critic, trained on base set B alone


def ae_own_dir(base_size: int) -> Path:
    return Path(f"models/ae_own/{base_size}")


def ae_own_model(base_size: int) -> Path:  # its train_params name the shapes it trained on (train_ids)
    return ae_own_dir(base_size) / "ae_critic.pt"


def ae_own_latents(base_size: int) -> Path:  # the base set's latents as the own AE-Critic encodes them
    return ae_own_dir(base_size) / "latents.parquet"


def ae_own_summary(base_size: int) -> Path:
    return ae_own_dir(base_size) / "summary.json"


def ae_own_metrics(base_size: int) -> Path:
    return Path(f"metrics/train_ae_own/{base_size}.json")


# embed
LATENTS = Path("data/latents.parquet")
TSNE_CSV = Path("reports/embed/tsne.csv")
TSNE_PNG = Path("reports/embed/tsne.png")
# critic_eval
CRITIC_EVAL_METRICS = Path("metrics/critic_eval.json")
CRITIC_EVAL_STUDY = Path("reports/critic_eval/study.json")
OUTLIERS_CSV = Path("reports/critic_eval/outliers.csv")
OUTLIERS_PNG = Path("reports/critic_eval/outliers.png")
INTERPOLATIONS_PNG = Path("reports/critic_eval/interpolations.png")
# generate (one folder per base size B)


def generated_dir(base_size: int) -> Path:
    return Path(f"data/generated/{base_size}")


def generated_index(base_size: int) -> Path:
    return generated_dir(base_size) / "index.parquet"


def generated_meshes(base_size: int) -> Path:
    return generated_dir(base_size) / "meshes"


def base_set_table(base_size: int) -> Path:
    return generated_dir(base_size) / "base.parquet"


def generate_metrics(base_size: int) -> Path:
    return Path(f"metrics/generate/{base_size}.json")


def generate_reports(base_size: int) -> Path:
    return Path(f"reports/generate/{base_size}")


def generate_summary(base_size: int) -> Path:
    return generate_reports(base_size) / "summary.json"


GENERATED_SUFFIX = ".obj"


def fidelity_metrics(base_size: int) -> Path:  # one file per pool and headline figure
    return Path(f"metrics/fidelity/{base_size}")


def fidelity_reports(base_size: int) -> Path:
    return Path(f"reports/fidelity/{base_size}")


# grasps (one table per corpus: `dvc.yaml` runs the stage for each)
def corpus_files(corpus: str) -> tuple[Path, Path, str] | None:
    """(shape table, mesh folder, mesh suffix) of a corpus: ``original`` (ingested shapes: the objects table, with
    no split) or ``gen_<B>`` (the shapes generated for base size B); None for an unknown name."""
    if corpus == "original":
        return OBJECTS_TABLE, SHAPES_DIR, ".ply"
    if corpus.startswith("gen_") and corpus[4:].isdigit():
        size = int(corpus[4:])
        return generated_index(size), generated_meshes(size), GENERATED_SUFFIX
    return None


def grasps_table(corpus: str) -> Path:
    return Path(f"data/grasps/{corpus}.parquet")


def grasps_metrics(corpus: str) -> Path:
    return Path(f"metrics/grasps/{corpus}.json")


def grasps_report(corpus: str) -> Path:
    return Path(f"reports/grasps/{corpus}.json")


# score
SCORES = Path("data/scores.parquet")
SCORE_METRICS = Path("metrics/score.json")
SCORE_SUMMARY = Path("reports/score/summary.json")
GRASPNESS_HIST_CSV = Path("reports/score/graspness_hist.csv")
GRASPNESS_HIST_PNG = Path("reports/score/graspness_hist.png")
RARITY_HIST_CSV = Path("reports/score/rarity_hist.csv")
RARITY_HIST_PNG = Path("reports/score/rarity_hist.png")
GRASP_EXAMPLES_PNG = Path("reports/score/grasp_examples.png")


# render (one dataset folder per corpus)
def gqcnn_dir(corpus: str) -> Path:
    return Path(f"data/gqcnn/{corpus}")


def render_metrics(corpus: str) -> Path:
    return Path(f"metrics/render/{corpus}.json")


def render_examples(corpus: str) -> Path:
    return Path(f"reports/render/{corpus}/examples.png")


def render_report(corpus: str) -> Path:
    return Path(f"reports/render/{corpus}/summary.json")


# train_gqcnn (every network of one training seed) and report
def gqcnn_seed_dir(seed: int) -> Path:
    """The networks of a training seed, one folder each (``<pool>/<B>-<R>``, named by
    :attr:`graspaug.training.variants.Variant.name`)."""
    return Path(f"models/gqcnn/s{seed}")


def gqcnn_seed_metrics(seed: int) -> Path:
    return Path(f"metrics/gqcnn/s{seed}.json")


def gqcnn_seed_networks(seed: int) -> Path:
    """Validation and test AP, steps and datapoints of every network of a seed (JSON)."""
    return Path(f"reports/gqcnn/networks/s{seed}.json")


def gqcnn_val_curves(seed: int) -> Path:
    """Validation AP vs step of every network of a seed (PNG; the CSV beside it)."""
    return Path(f"reports/gqcnn/validation/s{seed}.png")


AP_METRICS = Path("metrics/ap")  # one file per declared contrast
REPORT_DIR = Path("reports/gqcnn")
AP_REPORT = REPORT_DIR / "ap.json"  # contrasts, networks, chosen ratios (sim reads it)
# sim
SIM_METRICS = Path("metrics/sim")  # one file per contrast
SIM_REPORT_DIR = Path("reports/sim")
CALIBRATION_METRICS = Path("metrics/grasp_calibration")  # one file per figure: mean, lo, hi
CALIBRATION_REPORT_DIR = Path("reports/grasp_calibration")


def timing_file(stage: str, item: str | None = None) -> Path:
    """Where a stage writes how long it took (not a metric: ``dvc metrics diff`` shows results only)."""
    return Path("reports/timing") / (f"{stage}.json" if item is None else f"{stage}/{item}.json")


# lifelong: round k (0: the 1:0 networks of train_gqcnn scored) of the loop
def lifelong_data(round_: int) -> Path:
    """Round k's shapes and datapoints: ``meshes/`` (this round's), ``shapes.parquet``, ``dataset/``, ``real.csv``
    (every round's so far), ``failures.csv``, ``history.csv``, ``curve.csv``."""
    return Path(f"data/lifelong/r{round_}")


def lifelong_models(round_: int) -> Path:
    """Round k's networks: ``s<seed>/<arm>/<B>-<R>/`` as train_gqcnn writes them."""
    return Path(f"models/lifelong/r{round_}")


def lifelong_metrics(round_: int) -> Path:  # one file per arm's AP and contrast: mean, lo, hi
    return Path(f"metrics/lifelong/r{round_}")


def lifelong_reports(round_: int) -> Path:
    """Round k's report.md, curve.png, failures.png, followed.csv."""
    return Path(f"reports/lifelong/r{round_}")
