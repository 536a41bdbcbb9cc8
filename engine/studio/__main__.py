"""``python -m formgraph.studio GRAPH ...``: the same as ``formgraph serve GRAPH ...``."""

from __future__ import annotations

import sys

from formgraph.cli.main import main

if __name__ == "__main__":
    sys.exit(main(["serve", *sys.argv[1:]]))
