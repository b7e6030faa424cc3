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
