"""The fidelity experiment (``fidelity@<B>``: how close is each pool to real shapes before any network trains on it?),
in one folder: :mod:`.numbers` (Chamfer distances, coverage, MMD, 1-NNA, graspness kept, datapoints per shape, each with
its bootstrap interval over shapes) and :mod:`.words` (report.md's table)."""
