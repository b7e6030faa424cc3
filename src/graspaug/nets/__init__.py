"""Networks, one file each, no I/O."""
