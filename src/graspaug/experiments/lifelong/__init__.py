"""The lifelong loop (``lifelong_start`` and ``lifelong@r<k>``: generate from the planner's failures, round after
round), in one folder: :mod:`.numbers` (the failures, the anchors, the arms and their contrasts over rounds),
:mod:`.words` (a round's report), :mod:`.figures` (the curve over rounds), :mod:`.round` (one round: label, render,
train, score, write)."""
