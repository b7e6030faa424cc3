"""The critic study (``critic_eval``: does the AE-Critic's regularizer make interpolants more shape-like?), in one
folder: :mod:`.numbers` (interpolations, outlier percentages, the paired contrasts over interpolation pairs),
:mod:`.words` (the contrasts in words), :mod:`.figures` (what the figures draw)."""
