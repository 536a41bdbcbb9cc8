"""The studio: ``formgraph serve GRAPH``, a local web page to edit, see and tune a graph.

    from formgraph.studio import serve
    serve("graphs/spiral_tube.yaml")     # prints http://127.0.0.1:8765/index.html?token=...

- :mod:`.session`: the graph file, its text and params, every evaluation through the one
  engine (no trame here);
- :mod:`.worker`: the thread that runs the session's requests, newest first;
- :mod:`.scene`: node values as vtk actors the browser draws, updated in place;
- :mod:`.page`: the trame page's state and wiring (requests out, results shown);
- :mod:`.layout`: its widgets (editor, 3-D view, graph drawing, controls, status);
- :mod:`.guard`: the token, Host and Origin checks in front of every request;
- :mod:`.app`: :func:`serve`.

``import formgraph`` does not import this package; importing it does not import trame
(the page's modules do, when the studio starts).
"""

from __future__ import annotations

from typing import Any

__all__ = ["serve"]


def serve(*args: Any, **kwargs: Any) -> int:
    """Serve the studio on a graph file: see :func:`formgraph.studio.app.serve`."""
    from .app import serve as _serve

    return _serve(*args, **kwargs)
