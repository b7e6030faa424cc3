"""The sections of ``params.yaml``, one module each, and the loader a stage uses to read only its own."""
