"""Benchmark support: generated circuits and timing helpers (used by benchmarks/)."""
