"""The GQ-CNN augmentation experiment (paper Section IV-C/D), in one folder: :mod:`.numbers` (test and validation AP
of every network, the declared paired contrasts, the ratio chosen on validation, per-object AP), :mod:`.words` (the
verdicts and report.md's text), :mod:`.figures` (what the figures draw, and drawing them), :mod:`.attribution`
(several draws of the data, the decomposition real → recon → blend → targeted)."""
