"""The studies a researcher reruns outside ``dvc repro``: ``graspaug study <name>``
(:mod:`graspaug.pipeline.study_cli`).

One module per study, each a ``run`` that reads a project's files (they know file names, as stages do), calls the
experiments' code and returns the text the command prints: ``attribution`` and ``lifelong`` (an experiment over
several draws of the data, each draw a clone of the project), ``cell_ranking`` (the robot cell's ranking over several
projects' networks), ``grasp_calibration`` (the cell's labelled grasps with changed cell settings),
``heldout_fidelity`` and ``roundtrip_ceiling`` (what a decoder keeps of a shape). :mod:`.draws` holds what the draw
studies share.
"""
