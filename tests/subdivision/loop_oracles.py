"""Oracles for Loop subdivision: OpenSubdiv's Loop scheme (tools/osd_oracle, built by tools/setup.sh), trimesh's
``subdivide_loop``, and matching of vertices and faces between two subdivided meshes."""

import sys
from pathlib import Path

import numpy as np
from conftest import tier_unavailable

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools" / "osd_oracle"))
import osd_oracle  # noqa: E402


def opensubdiv():
    """The `osd_oracle` module with its library loaded (skip locally / fail in CI when it is not built)."""
    try:
        osd_oracle.load()
    except OSError as err:
        tier_unavailable(str(err))
    return osd_oracle


def match_vertices(ours, theirs, tol=1e-9):
    """Index map ``m`` with ``ours[i] ~ theirs[m[i]]`` (nearest point, within ``tol``): (V, D) float arrays of the
    same distinct points in two orders. Raises AssertionError when the point sets differ."""
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    a, b = np.asarray(ours[:, :3], np.float64), np.asarray(theirs[:, :3], np.float64)
    m = np.empty(len(a), np.int64)
    near = np.empty(len(a))
    bb = (b * b).sum(axis=1)
    for lo in range(0, len(a), 512):
        chunk = a[lo : lo + 512]
        d2 = bb[None, :] - 2.0 * chunk @ b.T + (chunk * chunk).sum(axis=1)[:, None]
        m[lo : lo + 512] = np.argmin(d2, axis=1)
    near = np.linalg.norm(a - b[m], axis=1)
    assert near.max() <= tol * max(1.0, float(np.abs(b).max())), f"a vertex is {near.max():.3g} from the other mesh"
    assert len(np.unique(m)) == len(m), "two vertices matched the same point"
    return m


def face_keys(triangles):
    """Rows of sorted vertex ids, for comparing face sets: (F, 3) -> (F, 3) int64."""
    return np.sort(np.asarray(triangles, np.int64), axis=1)


def match_faces(ours, theirs):
    """Index map ``m`` with face ``i`` of ``ours`` the same vertex set as ``theirs[m[i]]`` (ids already mapped)."""
    ka, kb = face_keys(ours), face_keys(theirs)
    oa, ob = np.lexsort(ka.T[::-1]), np.lexsort(kb.T[::-1])
    assert np.array_equal(ka[oa], kb[ob]), "the two meshes do not have the same faces"
    m = np.empty(len(ours), np.int64)
    m[oa] = ob
    return m


def rel_err(a, b):
    scale = max(1.0, float(np.abs(b).max()))
    return float(np.abs(np.asarray(a, np.float64) - b).max()) / scale
