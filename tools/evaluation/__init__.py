"""The evaluation benchmark behind tools/evaluate.py: results (the dataclasses that carry
them), run (the renderer and its references), metrics, plots and report (results.md and
results.json). Imported with tools/ on sys.path, as evaluate.py sets it."""
