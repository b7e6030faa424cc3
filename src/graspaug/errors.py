"""Errors reported in one line: the CLI prints the message and exits with code 1.

Libraries raise :class:`DataError` (bad or inconsistent input data: a table, a folder, an
array) and :class:`CheckpointMismatch`; only stages raise :class:`StageError` (a stage cannot
produce valid outputs, e.g. an input file of the pipeline is missing).
"""


class DataError(ValueError):
    """Input data a library function cannot use; the message names the culprit and why."""


class StageError(RuntimeError):
    """A stage cannot produce valid outputs; the message says why."""


class CheckpointMismatch(RuntimeError):
    """A checkpoint was trained with other settings than the ones asked for."""
