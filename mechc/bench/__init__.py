"""Benchmark support: generated circuits, the speed benchmark's studies (one module each) and
its driver ``speed_accuracy`` (used by ``mechc bench`` and benchmarks/)."""
