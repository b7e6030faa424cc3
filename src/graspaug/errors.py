"""Errors a stage reports in one line (the CLI prints them and exits with code 1)."""


class StageError(RuntimeError):
    """A stage cannot produce valid outputs; the message says why."""


class CheckpointMismatch(RuntimeError):
    """A checkpoint was trained with other settings than the ones asked for."""
