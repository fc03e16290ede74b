"""The evaluation benchmark behind tools/bench/evaluate.py: results (the dataclasses that carry
them), run (the renderer and its references), metrics, plots and report (results.md and
results.json)."""
