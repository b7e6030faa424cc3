"""Training loops: take tensors and config dataclasses, report through callbacks, no file I/O."""
