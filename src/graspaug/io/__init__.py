"""Readers and writers, in pairs; one module owns each format. All writes are atomic."""
