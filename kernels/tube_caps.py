"""End caps of open tubes: one n-gon (FLAT) or a hemisphere of rings closed by a triangle fan (ROUND).

Caps reuse the end ring of the body, so a capped open tube is a closed, manifold surface. Vertex and edge
ids follow the body's layout in `tubes._tube_group` (ring k, side j: vertex ``k*n + j``, ring edge
``k*n + j`` from side j to j+1); corner edges list the edge from each corner to the next.
"""

import numpy as np



def add_caps(group, lines, n, t, nrm, bin_, radius, settings):
    """Append cap faces (and ROUND cap vertices) to ``group`` for every open curve of ``lines``."""
    open_curves = np.nonzero(~lines.cyclic & (lines.counts >= 2))[0]
    if len(open_curves) == 0:
        return
    starts = lines.offsets[open_curves]
    ends = lines.offsets[open_curves + 1] - 1
    mat = lines.material_index[open_curves]
    if settings.caps == "FLAT":
        _flat(group, n, starts, ends, t, mat, settings.uvs)
    else:
        _round(group, lines, n, starts, ends, t, nrm, bin_, radius, mat, settings.uvs)


def _disk_uv(cos_t, sin_t, scale=1.0):
    return np.stack((0.5 + 0.5 * scale * cos_t, 0.5 + 0.5 * scale * sin_t), axis=-1)


def _flat(group, n, starts, ends, t, mat, uvs):
    j = np.arange(n)
    rev = (-j) % n  # start cap faces -T: reversed ring order
    start_faces = starts[:, None] * n + rev
    start_edges = starts[:, None] * n + (rev - 1) % n  # the ring edge from side rev-1 to rev, walked backwards
    end_faces = ends[:, None] * n + j
    end_edges = ends[:, None] * n + j
    group["faces"] += [start_faces, end_faces]
    group["corner_edges"] += [start_edges, end_edges]
    group["face_material"] += [mat, mat]
    group["corner_normals"] += [np.repeat(-t[starts], n, axis=0).astype(np.float32),
                                np.repeat(t[ends], n, axis=0).astype(np.float32)]
    if uvs:
        theta = 2 * np.pi * j / n
        disk = _disk_uv(np.cos(theta), np.sin(theta)).astype(np.float32)
        group["uvs"] += [np.tile(disk[rev], (len(starts), 1)), np.tile(disk, (len(ends), 1))]


def _round(group, lines, n, starts, ends, t, nrm, bin_, radius, mat, uvs):
    m = max(1, n // 4)  # latitude steps from the body ring (φ = 0) to the pole (φ = π/2)
    j = np.arange(n)
    j1 = (j + 1) % n
    theta = 2 * np.pi * j / n
    phi = (np.pi / 2) * np.arange(1, m) / m
    per_end_v = (m - 1) * n + 1
    per_end_e = (2 * (m - 1) + 1) * n
    v_base = len(group["positions"])
    e_base = sum(len(e) for e in group["edges"])
    for side, rings in ((-1.0, starts), (1.0, ends)):
        count = len(rings)
        vb = v_base + np.arange(count)[:, None] * per_end_v  # (E, 1)
        eb = e_base + np.arange(count)[:, None] * per_end_e
        # new vertices: latitude rings 1..m-1 then the pole
        cphi, sphi = np.cos(phi), np.sin(phi)
        radial = (np.cos(theta)[None, None, :, None] * nrm[rings][:, None, None, :]
                  + np.sin(theta)[None, None, :, None] * bin_[rings][:, None, None, :])  # (E, 1, n, 3)
        along = side * t[rings][:, None, None, :]
        dirs = cphi[None, :, None, None] * radial + sphi[None, :, None, None] * along  # (E, m-1, n, 3)
        dirs = np.concatenate((dirs.reshape(count, -1, 3), along[:, 0]), axis=1)  # (E, per_end_v, 3)
        centre = lines.points[rings][:, None, :]
        pos = centre + radius[rings][:, None, None] * dirs
        group["positions"] = np.concatenate((group["positions"], pos.reshape(-1, 3).astype(np.float32)))
        group["normals"] = np.concatenate((group["normals"], dirs.reshape(-1, 3).astype(np.float32)))
        v_base += count * per_end_v

        def vert(i, jj, rings=rings, vb=vb):
            return rings[:, None] * n + jj if i == 0 else vb + (i - 1) * n + jj

        def ring_edge(i, jj, rings=rings, eb=eb):
            return rings[:, None] * n + jj if i == 0 else eb + (i - 1) * n + jj

        def long_edge(i, jj, eb=eb):
            return eb + (m - 1) * n + (i - 1) * n + jj

        pole = vb + (m - 1) * n + 0 * j
        new_edges = []
        for i in range(1, m):
            new_edges.append(np.stack((vert(i, j), vert(i, j1)), axis=-1))
        for i in range(1, m):
            new_edges.append(np.stack((vert(i - 1, j), vert(i, j)), axis=-1))
        new_edges.append(np.stack((vert(m - 1, j), pole), axis=-1))
        # edges must be stored per end contiguously: (E, blocks * n, 2)
        group["edges"].append(np.concatenate(new_edges, axis=1).reshape(-1, 2))
        e_base += count * per_end_e
        for i in range(1, m):
            a, b = vert(i - 1, j), vert(i, j)
            a1, b1 = vert(i - 1, j1), vert(i, j1)
            ra, rb, lj, lj1 = ring_edge(i - 1, j), ring_edge(i, j), long_edge(i, j), long_edge(i, j1)
            if side > 0:
                f, ce = (a, a1, b1, b), (ra, lj1, rb, lj)
            else:
                f, ce = (b, b1, a1, a), (rb, lj1, ra, lj)
            group["faces"].append(np.stack(f, axis=-1).reshape(-1, 4))
            group["corner_edges"].append(np.stack(ce, axis=-1).reshape(-1, 4))
            group["face_material"].append(np.repeat(mat, n))
            if uvs:
                group["uvs"].append(_quad_uv(theta, phi, i, m, side, count))
        a, a1 = vert(m - 1, j), vert(m - 1, j1)
        ra = ring_edge(m - 1, j)
        pe, pe1 = eb + 2 * (m - 1) * n + j, eb + 2 * (m - 1) * n + j1
        if side > 0:
            f, ce = (a, a1, pole), (ra, pe1, pe)
        else:
            f, ce = (pole, a1, a), (pe1, ra, pe)
        group["faces"].append(np.stack(f, axis=-1).reshape(-1, 3))
        group["corner_edges"].append(np.stack(ce, axis=-1).reshape(-1, 3))
        group["face_material"].append(np.repeat(mat, n))
        if uvs:
            group["uvs"].append(_fan_uv(theta, m, side, count))


def _lat_uv(theta, scale):
    return _disk_uv(np.cos(theta), np.sin(theta), scale)


def _quad_uv(theta, phi, i, m, side, count):
    th1 = np.roll(theta, -1)
    th1[-1] = 2 * np.pi
    sa, sb = np.cos((np.pi / 2) * (i - 1) / m), np.cos((np.pi / 2) * i / m)
    a, a1, b, b1 = _lat_uv(theta, sa), _lat_uv(th1, sa), _lat_uv(theta, sb), _lat_uv(th1, sb)
    corners = (a, a1, b1, b) if side > 0 else (b, b1, a1, a)
    uv = np.stack(corners, axis=1)  # (n, 4, 2)
    return np.tile(uv.reshape(-1, 2), (count, 1)).astype(np.float32)


def _fan_uv(theta, m, side, count):
    th1 = np.roll(theta, -1)
    th1[-1] = 2 * np.pi
    s = np.cos((np.pi / 2) * (m - 1) / m)
    a, a1 = _lat_uv(theta, s), _lat_uv(th1, s)
    centre = np.full_like(a, 0.5)
    corners = (a, a1, centre) if side > 0 else (centre, a1, a)
    return np.tile(np.stack(corners, axis=1).reshape(-1, 2), (count, 1)).astype(np.float32)
