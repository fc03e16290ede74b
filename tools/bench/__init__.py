"""Benchmarks and the evaluation: bench_*.py, evaluate.py (its work in evaluation/), the
Blender peers (blender_compare.py, cycles_peer.py) and benchlib.py, which they share."""
