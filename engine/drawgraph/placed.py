"""Boxes of a graph drawing put where they were placed (the file's ``layout:``, or the
studio's canvas), and each box's anchors for a program drawing on top."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

__all__ = ["anchors", "pin"]


def pin(
    boxes: Mapping[str, Any],
    positions: Mapping[str, tuple[float, float]],
    pinned: set[str],
    page_w: float,
    top: float,
    gap: float,
    margin: float,
) -> tuple[float, float]:
    """Put the ``pinned`` boxes (keys ``n:name`` / ``p:name``) at their ``positions`` (by
    name); the others keep their laid-out places, moved down below the placed ones (a node
    added in the text lands where nothing is). Returns the page's size to hold them all."""
    bottom = top
    for k in pinned:
        b = boxes[k]
        b.x, b.y = (max(0.0, float(c)) for c in positions[k[2:]])
        bottom = max(bottom, b.y + b.height)
    free = [boxes[k] for k in boxes if k not in pinned]
    if free:
        shift = bottom + 3 * gap - min(b.y for b in free)
        for b in free:
            b.y += shift
    right = max((b.x + b.width + 40 for b in boxes.values()), default=page_w)
    low = max((b.y + b.height for b in boxes.values()), default=top)
    return max(page_w, right + margin), low + margin + 4


def anchors(boxes: Iterable[Any]) -> dict[str, dict[str, Any]]:
    """Each box by name: its place and size, and the y of each input port and output."""
    return {
        box.key[2:]: {
            "x": box.x,
            "y": box.y,
            "w": box.width,
            "h": box.height,
            "param": box.is_param,
            "ports": {p: box.port_y(p) for p in box.ports},
            "outputs": {o: box.output_y(o) for o, _ in box.outputs},
        }
        for box in boxes
    }
