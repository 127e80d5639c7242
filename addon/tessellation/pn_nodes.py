"""The geometry-nodes group "Tessera PN Triangles": curved PN triangles (Vlachos et al. 2001, [Nellmedin 2014]) in the
modifier stack, no add-on needed to evaluate it. Numpy reference: `kernels.tessellation.patches.pn_control` with
`cubic_basis`.

Each coarse triangle's ten cubic control points are computed once (from its corners' positions and point normals)
and stored as face attributes; every corner stores its barycentric unit vector. Subdivide Mesh copies the face
attributes to the sub-faces and interpolates the corner ones, so every new corner knows its coarse triangle's
control points and its barycentric coordinates b there, and evaluates the cubic. A new point on a coarse edge
gets the same value from the faces on both sides (a PN edge depends on its two ends only), and points take the
mean of their corners. The result is ``p + a (pn - p)`` with the shape factor a (a field). The normals follow the
kernel's sharp-edge policy (Watertight or Split, `surface_nodes`); the shading is Vlachos's quadratic normal patch
(six more face attributes: the face's own corner normals and its three reflected mid-edge normals), evaluated and
normalised at every corner.
"""

from ..node_groups import Graph, GroupSpec, register_group
from .surface_nodes import CORNER_NORMAL, set_shading, surface_interface

GROUP_NAME = "Tessera PN Triangles"
VERSION = 5
_CONTROL = [f"tessera_pn_{i}" for i in range(10)]  # order of cubic_basis: P1 P2 P3 b210 b120 b021 b012 b102 b201 b111
_NORMAL_CONTROL = [f"tessera_pn_n{i}" for i in range(6)]  # order of quadratic_basis: N1 N2 N3 n110 n011 n101
_BARY = "tessera_pn_bary"


def _build(tree):
    g = Graph(tree)
    gi, go, coarse, normal = surface_interface(g, 1.0, "0: flat triangles; 1: PN triangles; a field, so it can vary "
                                                       "per vertex")

    position = g.node("GeometryNodeInputPosition").outputs[0]
    index = g.node("GeometryNodeInputIndex").outputs[0]
    p, n, own = [], [], []
    for k in range(3):  # the face's corners in order: values on the corner domain, read from the face domain
        corner = g.node("GeometryNodeCornersOfFace", [("Face Index", index), ("Sort Index", k)]).outputs[0]
        p.append(g.at("CORNER", "FLOAT_VECTOR", position, corner))
        n.append(g.at("CORNER", "FLOAT_VECTOR", normal, corner))
        own.append(g.at("CORNER", "FLOAT_VECTOR", g.named(CORNER_NORMAL, "FLOAT_VECTOR"), corner))

    def tangent(i, j):  # (2 Pi + Pj - ((Pj - Pi).Ni) Ni) / 3
        w = g.vec("DOT_PRODUCT", g.vec("SUBTRACT", p[j], p[i]), n[i], out=1)
        s = g.vec("SUBTRACT", g.vec("ADD", g.vec("SCALE", p[i], 2.0), p[j]), g.vec("SCALE", n[i], w))
        return g.vec("SCALE", s, 1.0 / 3.0)

    edges = [tangent(0, 1), tangent(1, 0), tangent(1, 2), tangent(2, 1), tangent(2, 0), tangent(0, 2)]
    e = edges[0]
    for t in edges[1:]:
        e = g.vec("ADD", e, t)
    e = g.vec("SCALE", e, 1.0 / 6.0)
    v = g.vec("SCALE", g.vec("ADD", g.vec("ADD", p[0], p[1]), p[2]), 1.0 / 3.0)
    b111 = g.vec("ADD", e, g.vec("SCALE", g.vec("SUBTRACT", e, v), 0.5))
    controls = [p[0], p[1], p[2], *edges, b111]

    # the shading: the quadratic normal patch (`pn_normal_control`) of the face's own corner normals
    mids = [_reflected_mid_normal(g, p[i], p[j], own[i], own[j]) for i, j in ((0, 1), (1, 2), (2, 0))]

    geometry = coarse
    for name, field in zip((*_CONTROL, *_NORMAL_CONTROL), (*controls, *own, *mids), strict=True):
        geometry = g.node("GeometryNodeStoreNamedAttribute", [(0, geometry), ("Name", name), ("Value", field)],
                          data_type="FLOAT_VECTOR", domain="FACE").outputs[0]
    k = g.node("GeometryNodeFaceOfCorner", [(0, index)]).outputs["Index in Face"]
    one_hot = g.xyz(*(g.node("ShaderNodeMath", [(0, k), (1, float(i)), (2, 0.5)], operation="COMPARE").outputs[0]
                      for i in range(3)))
    geometry = g.node("GeometryNodeStoreNamedAttribute", [(0, geometry), ("Name", _BARY), ("Value", one_hot)],
                      data_type="FLOAT_VECTOR", domain="CORNER").outputs[0]
    fine = g.node("GeometryNodeSubdivideMesh", [(0, geometry), (1, gi.outputs["Subdivisions"])]).outputs[0]

    def read(name):
        return g.node("GeometryNodeInputNamedAttribute", [(0, name)], data_type="FLOAT_VECTOR").outputs[0]

    b = g.split(read(_BARY))
    mul = lambda *xs: _product(g, xs)  # noqa: E731
    weights = [mul(b[0], b[0], b[0]), mul(b[1], b[1], b[1]), mul(b[2], b[2], b[2]),
               mul(3.0, b[0], b[0], b[1]), mul(3.0, b[0], b[1], b[1]), mul(3.0, b[1], b[1], b[2]),
               mul(3.0, b[1], b[2], b[2]), mul(3.0, b[0], b[2], b[2]), mul(3.0, b[0], b[0], b[2]),
               mul(6.0, b[0], b[1], b[2])]
    pn = None
    for w, name in zip(weights, _CONTROL, strict=True):
        term = g.vec("SCALE", read(name), w)
        pn = term if pn is None else g.vec("ADD", pn, term)
    on_points = g.on("CORNER", "FLOAT_VECTOR", pn)  # read from the points: the mean of their corners
    offset = g.vec("SCALE", g.vec("SUBTRACT", on_points, position), gi.outputs["Shape Factor"])
    moved = g.node("GeometryNodeSetPosition", [(0, fine), ("Offset", offset)]).outputs[0]
    quadratic = [mul(b[0], b[0]), mul(b[1], b[1]), mul(b[2], b[2]), mul(b[0], b[1]), mul(b[1], b[2]),
                 mul(b[2], b[0])]
    shading = None
    for w, name in zip(quadratic, _NORMAL_CONTROL, strict=True):
        term = g.vec("SCALE", read(name), w)
        shading = term if shading is None else g.vec("ADD", shading, term)
    shaded = set_shading(g, moved, g.vec("NORMALIZE", shading))
    tree.links.new(g.remove(shaded, (*_CONTROL, *_NORMAL_CONTROL, _BARY, CORNER_NORMAL)), go.inputs[0])


def _reflected_mid_normal(g, pi, pj, ni, nj):
    """normalize(Ni + Nj - v (Pj - Pi)), v = 2 (Pj - Pi).(Ni + Nj) / |Pj - Pi|^2 (0 for a zero-length edge)."""
    d = g.vec("SUBTRACT", pj, pi)
    s = g.vec("ADD", ni, nj)
    v = g.math("DIVIDE", g.math("MULTIPLY", 2.0, g.vec("DOT_PRODUCT", d, s, out=1)), g.vec("DOT_PRODUCT", d, d, out=1))
    return g.vec("NORMALIZE", g.vec("SUBTRACT", s, g.vec("SCALE", d, v)))  # Blender's divide by zero gives 0


def _product(g, factors):
    out = factors[0]
    for f in factors[1:]:
        out = g.math("MULTIPLY", out, f)
    return out


SPEC = register_group(GroupSpec(GROUP_NAME, VERSION, _build, catalog="Tessera/Tessellation",
                                description="Smooth a mesh with PN triangles: finer faces on a cubic surface "
                                            "shaped by the vertex normals"))
