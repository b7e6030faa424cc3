"""``graspaug``: one command per pipeline stage (``dvc.yaml`` calls these)."""
from __future__ import annotations

import logging
import sys
from pathlib import Path

import typer

from graspaug.config import DataParams, IngestParams, Params, ParamsError, VoxelizeParams, describe, load_params

app = typer.Typer(
    help="graspaug: augment a grasp planner's training objects with generated shapes.\n\n"
    "Each command runs one stage of the DVC pipeline with the settings in params.yaml; "
    "`dvc repro` runs them in order.",
    rich_markup_mode="markdown",
    no_args_is_help=True,
    add_completion=False,
)

ParamsOption = typer.Option(Path("params.yaml"), "--params", "-p", help="The params file to read.")


def _load(path: Path) -> Params:
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    try:
        return load_params(path)
    except ParamsError as exc:
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(code=2) from None


def _run(stage_run, params: Params) -> None:
    from graspaug.stages.ingest import StageError

    try:
        stage_run(params)
    except StageError as exc:
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(code=1) from None


@app.command(
    help="Load the shape corpus, reject broken meshes with a reason, rebuild one closed outer surface "
    "per shape, center and scale it, and split train/test.\n\n"
    "Writes `data/shapes/<shape_id>.ply`, `data/shapes.parquet`, `data/rejects.parquet`.\n\n"
    f"Params `data`:\n\n{describe(DataParams)}\n\nParams `ingest`:\n\n{describe(IngestParams)}\n\n"
    "Also `seed` (split) and `n_jobs`."
)
def ingest(params: Path = ParamsOption) -> None:
    from graspaug.stages import ingest as stage

    _run(stage.run, _load(params))


@app.command(
    help="Voxelize every shape's closed surface into a solid R×R×R occupancy grid (voxel centers "
    "inside the surface), scaled to fit with a margin; pitch and origin are kept to go back to meters.\n\n"
    f"Writes `data/voxels.npz`.\n\nParams `voxelize`:\n\n{describe(VoxelizeParams)}\n\nAlso `n_jobs`."
)
def voxelize(params: Path = ParamsOption) -> None:
    from graspaug.stages import voxelize as stage

    _run(stage.run, _load(params))


def main() -> None:
    app()


if __name__ == "__main__":
    main()
