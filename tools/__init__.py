"""pathreuse's Python tools, one package so that they import each other without touching
sys.path. Run them as modules from the repository root, e.g.

  python3 -m tools.scenes.gen_scenes --check scenes/
  /usr/bin/python3 -m tools.bench.evaluate --quick --out-dir /tmp/eval

(or with the repository root on PYTHONPATH from anywhere else). tools/requirements.txt names
what they need beyond the standard library."""
