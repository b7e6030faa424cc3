"""One thin module per DVC stage: read its params, call library functions, write outputs."""


class StageError(RuntimeError):
    """A stage cannot produce valid outputs; the message says why (the CLI prints it, exit code 1)."""
