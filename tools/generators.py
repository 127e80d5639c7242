"""Deterministic inputs shared by the tests, `tools/` and `bench/`: meshes built with numpy (closed, open, with
seams and holes), random brush dabs and a random height field with its HAM.

Import it as ``tessera.tools.generators`` (the tests, tools and benches all make the source tree importable as the
package ``tessera``). Nothing here needs Blender.
"""

import numpy as np


def octahedron():
    """Closed manifold, 6 vertices, 8 counter-clockwise triangles."""
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float32)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], np.int32)
    return v, f


def torus(major=24, minor=12, r_major=1.0, r_minor=0.35):
    """Closed manifold torus: (major * minor) vertices, 2 * major * minor triangles."""
    u = np.linspace(0, 2 * np.pi, major, endpoint=False)[:, None]
    w = np.linspace(0, 2 * np.pi, minor, endpoint=False)[None, :]
    x = (r_major + r_minor * np.cos(w)) * np.cos(u)
    y = (r_major + r_minor * np.cos(w)) * np.sin(u)
    z = np.broadcast_to(r_minor * np.sin(w), x.shape)
    v = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(major), np.arange(minor), indexing="ij")
    a = i * minor + j
    b = ((i + 1) % major) * minor + j
    c = ((i + 1) % major) * minor + (j + 1) % minor
    d = i * minor + (j + 1) % minor
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.int32)


def random_closed(seed, major=None, minor=None):
    """A randomly jittered torus with randomly permuted vertex ids (so edge directions are mixed)."""
    rng = np.random.default_rng(seed)
    v, f = torus(major or int(rng.integers(3, 9)), minor or int(rng.integers(3, 7)))
    v = v + rng.normal(scale=0.02, size=v.shape).astype(np.float32)
    perm = rng.permutation(len(v))
    inverse = np.argsort(perm)
    return v[perm], inverse[f].astype(np.int32)


def grid(n=4):
    """Open square grid in the z = 0 plane: (n + 1)^2 vertices, 2 n^2 triangles."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    v = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size, np.float32)], 1)
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    f = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    return v, f.astype(np.int32)


def icosahedron():
    """Closed manifold with circumradius 1: 12 vertices of valence 5, 20 counter-clockwise triangles."""
    p = (1 + 5**0.5) / 2
    v = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p], [0, -1, -p], [0, 1, -p],
                  [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], np.float64)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], np.int32)
    return v, f


def bipyramid(n=16):
    """Closed manifold: two apexes of valence ``n`` over an ``n``-gon, 2 n counter-clockwise triangles."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(n)], 1)
    v = np.concatenate([ring, [[0, 0, 1.2], [0, 0, -0.9]]])
    i = np.arange(n)
    j = (i + 1) % n
    f = np.concatenate([np.stack([i, j, np.full(n, n)], 1), np.stack([j, i, np.full(n, n + 1)], 1)])
    return v, f.astype(np.int32)


def random_irregular_closed(seed, splits=12, flips=40):
    """An icosahedron with random face splits (1 -> 3, valence-3 vertices) and random edge flips, vertices
    jittered and ids permuted: a closed, consistently oriented manifold with valences from 3 to about 12."""
    rng = np.random.default_rng(seed)
    v, f = icosahedron()
    v, f = list(v), [list(t) for t in f]
    for _ in range(splits):
        t = int(rng.integers(len(f)))
        a, b, c = f[t]
        v.append((v[a] + v[b] + v[c]) / 3 * 1.05)
        m = len(v) - 1
        f[t] = [a, b, m]
        f += [[b, c, m], [c, a, m]]
    for _ in range(flips):
        t = int(rng.integers(len(f)))
        k = int(rng.integers(3))
        a, b, c = f[t][k], f[t][(k + 1) % 3], f[t][(k + 2) % 3]
        other = [s for s, g in enumerate(f) if s != t and a in g and b in g]
        g = f[other[0]]
        d = [x for x in g if x not in (a, b)][0]
        edges = {frozenset((g2[i], g2[(i + 1) % 3])) for g2 in f for i in range(3)}
        valence = [sum(x in g2 for g2 in f) for x in (a, b)]
        if frozenset((c, d)) in edges or min(valence) <= 3:
            continue
        f[t], f[other[0]] = [c, a, d], [d, b, c]
    v = np.array(v) + rng.normal(scale=0.02, size=(len(v), 3))
    perm = rng.permutation(len(v))
    return v[perm], np.argsort(perm)[np.array(f)].astype(np.int32)


def plane_with_hole(n=6):
    """Open grid with the middle faces removed: an outer and an inner boundary loop."""
    v, f = grid(n)
    centre = v[f].mean(axis=1)
    keep = np.abs(centre[:, :2] - n / 2).max(axis=1) > 1.0
    v = v.astype(np.float64)
    v[:, 2] = 0.1 * np.sin(v[:, 0]) * np.cos(v[:, 1])
    return v, f[keep]


def cup(sides=12, rings=4):
    """A cylinder closed at the bottom (a fan) and open at the top: one boundary loop, a valence-``sides`` apex."""
    a = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    v = [[np.cos(t) * (1 + 0.1 * r), np.sin(t) * (1 + 0.1 * r), r * 0.5] for r in range(rings) for t in a]
    v.append([0, 0, -0.2])
    i, j = np.meshgrid(np.arange(rings - 1), np.arange(sides), indexing="ij")
    p0, p1 = i * sides + j, i * sides + (j + 1) % sides
    q0, q1 = p0 + sides, p1 + sides
    f = np.concatenate([np.stack([p0, p1, q1], -1).reshape(-1, 3), np.stack([p0, q1, q0], -1).reshape(-1, 3)])
    bottom = np.stack([(np.arange(sides) + 1) % sides, np.arange(sides), np.full(sides, len(v) - 1)], 1)
    return np.array(v), np.concatenate([f, bottom]).astype(np.int32)


def random_dabs(rng, channels):
    """Random dabs of every kind of the map kernels over a map of about 64 x 72 texels with ``channels`` channels:
    yields (kind, keyword arguments of ``kernels.displacement.map_edit.apply_dab``) from ``rng``
    (a `numpy.random.Generator`); six rounds of the eight kinds, positions partly outside the map."""
    st = rng.normal(size=(7, 11, channels)).astype(np.float32)
    for _ in range(6):
        pos = rng.uniform(-5, 70, size=2)
        vec = rng.normal(size=4)
        yield "CONTACT", {"pos": pos, "depth": rng.uniform(-1, 1), "radius": rng.uniform(0.5, 20)}
        yield "FORCE", {"pos": pos, "force": (*rng.normal(size=3), rng.uniform(0.5, 8))}
        yield "TEST", {"arg1": (*pos, 0, 0), "arg2": vec, "arg3": (rng.uniform(1, 15), 0, 0, 0)}
        for kind in ("DRAW", "SMOOTH", "FLATTEN", "NOISE"):
            yield kind, {"pos": pos, "radius": rng.uniform(1, 20), "strength": rng.uniform(-1, 1),
                         "falloff": rng.choice(["SMOOTH", "SPHERE", "LINEAR", "SHARP", "CONSTANT"]), "vector": vec,
                         "cell": rng.uniform(0.7, 9), "seed": int(rng.integers(0, 2**32))}
        yield "STAMP", {"stamp": st, "pos": pos, "angle": rng.uniform(0, 6.3), "scale": rng.uniform(0.5, 3),
                        "strength": rng.uniform(-1, 1)}


def random_ham_case():
    """A 150 x 203 random-walk height field, 1.5 world units a texel, and its numpy HAM: (`HeightMap`, (150, 203)
    float32)."""
    from ..kernels.terrain import analysis, heightmap_io

    rng = np.random.default_rng(11)
    h = (rng.normal(0, 20, (150, 203)).cumsum(axis=1) * 0.1).astype(np.float32)
    hm = heightmap_io.from_array(h, texel_size=1.5)
    return hm, analysis.ham(hm.heights() * np.float32(1.0 / 1.5))
