"""The simulated robot cell (the ``sim`` and ``grasp_calibration`` stages), in one folder: :mod:`.trials` (the arms, the
objects and the pick attempts), :mod:`.numbers` (success rates, the declared paired contrasts, the networks' ranking of
the calibration grasps' outcomes), :mod:`.words` (report.md's text), :mod:`.figures` (the success bars and the picture
of each recorded attempt), :mod:`.calibration` (which grasps the cell holds: the calibration of its hold against the
grasp labels)."""
