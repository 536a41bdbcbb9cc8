"""The faces-keyed memo (formgraph.kernels.mesh.memo): orient, cap and the flat-sheet count
reuse their connectivity work while only the positions change, and give what they give
without it."""

from __future__ import annotations

import numpy as np
import pytest

from formgraph.kernels.mesh import memo
from formgraph.kernels.mesh import repair as kr
from formgraph.kernels.mesh.grid import grid_faces


def _tube(nu: int, nv: int, radius: float, twist: float = 0.0):
    """An open tube (no caps): nu around, nv + 1 rings along z, faces in random order and
    half of them reversed, so orient has work to do."""
    fi, fo = grid_faces(nu, nv + 1, True, False)
    a = np.linspace(0, 2 * np.pi, nu, endpoint=False)[:, None] + twist * np.linspace(0, 1, nv + 1)
    z = np.broadcast_to(np.linspace(0, 3, nv + 1), a.shape)
    v = np.stack([radius * np.cos(a), radius * np.sin(a), z], -1).reshape(-1, 3)
    rng = np.random.default_rng(4)
    faces = np.split(fi, fo[1:-1])
    faces = [
        faces[i][::-1] if rng.random() < 0.5 else faces[i] for i in rng.permutation(len(faces))
    ]
    return v, np.concatenate(faces), fo.copy()


def _fresh(fn, *args):
    memo.clear()
    return fn(*args)


@pytest.mark.parametrize("step", [0.25, 0.5, 1.5])
def test_the_same_faces_give_what_a_fresh_call_gives(step):
    v, fi, fo = _tube(64, 40, 1.0)
    kr.orient(v, fi, fo)  # keeps the faces' connectivity
    capped = kr.cap(v, *kr.orient(v, fi, fo)[:1], fo)
    kr.flat_open_parts(v, fi, fo)
    w = _tube(64, 40, 1.0 + step, twist=step)[0]  # new positions, the same faces
    hits = memo.hits
    kept = (kr.orient(w, fi, fo), kr.flat_open_parts(w, fi, fo))
    oriented = kept[0][0]
    kept_cap = kr.cap(w, oriented, fo)
    assert memo.hits == hits + 4  # orient: its topology and fan corners; the sheets; the loops
    fresh = _fresh(kr.orient, w, fi, fo)
    assert np.array_equal(kept[0][0], fresh[0]) and kept[0][1] == fresh[1] == 0
    assert kept[1] == _fresh(kr.flat_open_parts, w, fi, fo) == 0
    fresh_cap = _fresh(kr.cap, w, oriented, fo)
    for a, b in zip(kept_cap, fresh_cap, strict=True):
        assert np.array_equal(a, b)
    # the caps moved with the points: their vertices are the new ones
    assert not np.array_equal(kept_cap[0], capped[0])


def test_changed_faces_or_a_mutated_input_are_not_mistaken():
    v, fi, fo = _tube(64, 40, 1.0)
    memo.clear()
    first, _ = kr.orient(v, fi, fo)
    hits = memo.hits
    other = fi.copy()
    other[[0, 1]] = other[[1, 0]]  # one face turned: not the same faces
    again, _ = kr.orient(v, other, fo)
    assert memo.hits == hits
    assert np.array_equal(again, _fresh(kr.orient, v, other, fo)[0])
    # the memo copied the faces: changing the caller's array afterwards changes nothing kept
    kr.orient(v, fi, fo)
    fi_before = fi.copy()
    fi[:4] = fi[:4][::-1]
    hits = memo.hits
    out, _ = kr.orient(v, fi, fo)
    assert memo.hits == hits  # a miss: fi differs from the faces kept
    fi[:] = fi_before
    assert np.array_equal(kr.orient(v, fi, fo)[0], first)


def test_kept_results_are_read_only_and_small_meshes_skip_it():
    v, fi, fo = _tube(64, 40, 1.0)
    memo.clear()
    kr.orient(v, fi, fo)
    ((_, _, _, value),) = memo._kept["orient"]
    assert all(not a.flags.writeable for a in value if isinstance(a, np.ndarray))
    small = _tube(4, 3, 1.0)
    hits = memo.hits
    kr.orient(*small)
    kr.orient(*small)
    assert memo.hits == hits and "orient" in memo._kept and len(memo._kept["orient"]) == 1
