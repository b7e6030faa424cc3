"""Experiment logic the stages report: tables, contrasts, verdicts."""
