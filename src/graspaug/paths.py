"""Where each stage's outputs live, relative to the project root (the data layout in one place).

``dvc.yaml`` declares the same paths as the stages' outs; the README's data contracts
say what each file holds.
"""
from pathlib import Path

# ingest
SHAPES_DIR = Path("data/shapes")
SHAPES_TABLE = Path("data/shapes.parquet")
REJECTS_TABLE = Path("data/rejects.parquet")
# voxelize
VOXELS = Path("data/voxels.npz")
# train_ae
AE_MODEL = Path("models/ae.pt")
AE_CRITIC_MODEL = Path("models/ae_critic.pt")
TRAIN_AE_LIVE = Path("metrics/train_ae")
TRAIN_AE_SUMMARY = Path("metrics/train_ae.json")
# embed
LATENTS = Path("data/latents.parquet")
TSNE_CSV = Path("reports/embed/tsne.csv")
TSNE_PNG = Path("reports/embed/tsne.png")
# critic_eval
CRITIC_EVAL_METRICS = Path("metrics/critic_eval.json")
OUTLIERS_CSV = Path("reports/critic_eval/outliers.csv")
OUTLIERS_PNG = Path("reports/critic_eval/outliers.png")
INTERPOLATIONS_PNG = Path("reports/critic_eval/interpolations.png")
# grasps (one table per corpus: `dvc.yaml` runs the stage for each)
CORPORA = {"original": (SHAPES_TABLE, SHAPES_DIR)}  # corpus -> (shape table, mesh folder)


def grasps_table(corpus: str) -> Path:
    return Path(f"data/grasps/{corpus}.parquet")


def grasps_metrics(corpus: str) -> Path:
    return Path(f"metrics/grasps/{corpus}.json")


# score
SCORES = Path("data/scores.parquet")
SCORE_METRICS = Path("metrics/score.json")
GRASPNESS_HIST_CSV = Path("reports/score/graspness_hist.csv")
GRASPNESS_HIST_PNG = Path("reports/score/graspness_hist.png")
RARITY_HIST_CSV = Path("reports/score/rarity_hist.csv")
RARITY_HIST_PNG = Path("reports/score/rarity_hist.png")
GRASP_EXAMPLES_PNG = Path("reports/score/grasp_examples.png")
