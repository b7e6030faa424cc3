"""One thin module per DVC stage: read its params, call library functions, write outputs."""

from graspaug.errors import StageError

__all__ = ["StageError", "corpus_paths"]


def corpus_paths(corpus: str):
    """(shape table, mesh folder, mesh suffix) of a corpus name, or a StageError naming the known ones."""
    from graspaug.pipeline.paths import corpus_files

    files = corpus_files(corpus)
    if files is None:
        raise StageError(f"unknown corpus {corpus!r}; known: original, gen_<base size>")
    return files
