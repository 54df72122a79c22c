"""Benchmarks for rescon: published baselines, graph families and the runner.

Nothing in this package is part of the library; ``rescon`` never imports it.
See ``benchmarks/README.md``.
"""
