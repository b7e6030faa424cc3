"""One thin module per DVC stage: read its params, call library functions, write outputs."""
