"""The geometry-nodes group "Tessera Displace": a displacement map in the modifier stack, one group for the three
kinds of map Tessera edits. Numpy reference: `kernels.displacement.tangent_space` (`sample_linear`,
`tangent_offsets`).

Per vertex the map is sampled (Linear, Extend) at the UV of the vertex's first face corner, as Blender's Displace
modifier picks a vertex's UV, and the offset is ``Strength x (value - Mid-Level)`` in the chosen frame:

- Height: the mean of R, G, B (the Displace modifier's intensity of an RGB image) along the vertex normal;
- Object: R, G, B as X, Y, Z in object space (the Displace modifier's RGB to XYZ, Local);
- Tangent (Blender 5.0 and newer, its UV Tangent node): R, G, B along the MikkTSpace tangent made orthogonal to
  the vertex normal, the bitangent (its sign from the orientation of the corner's face in UV space: the sign of
  its UV polygon's area) and the normal.
"""

from ...kernels.common.errors import TesseraError
from ..compat import UV_TANGENT_MESSAGE, has_uv_tangent_node
from ..node_groups import Graph, GroupSpec, ensure_group, register_group, socket

GROUP_NAME = "Tessera Displace"
VERSION = 2  # bump when the graph changes: older groups in a file are rebuilt


def maps():
    """The map kinds this Blender's group offers (Tangent needs the UV Tangent node)."""
    return ("Height", "Object", "Tangent") if has_uv_tangent_node() else ("Height", "Object")


def _interface(tree):
    socket(tree, "Geometry", "NodeSocketGeometry", description="The mesh to displace (it needs a UV map)")
    socket(tree, "Map", "NodeSocketMenu", description="Height along the normal; Object: RGB as XYZ in object "
                                                       "space; Tangent: RGB in the UV map's tangent frame")
    socket(tree, "Image", "NodeSocketImage", description="The displacement map")
    socket(tree, "UV Map", "NodeSocketString", default="UVMap", description="The UV map the image is laid out on")
    socket(tree, "Mid-Level", "NodeSocketFloat", default=0.5, description="The map value that does not move")
    socket(tree, "Strength", "NodeSocketFloat", default=1.0, description="Offset per unit of map value")
    socket(tree, "Geometry", "NodeSocketGeometry", in_out="OUTPUT", description="The displaced mesh")


def _tangent_frame(g, uv, index, corner, normal):
    """Unit tangent and bitangent (each a field) of the vertex's first corner: MikkTSpace's tangent made orthogonal
    to the normal, the sign from the face's UV orientation."""
    tangent = g.node("GeometryNodeUVTangent", [(1, uv)]).outputs[0]
    tangent.node.inputs[0].default_value = "Exact"
    # bitangent sign: the face's UV polygon area, summed over its corners (u_c v_next - u_next v_c)
    nxt = g.node("GeometryNodeOffsetCornerInFace", [(0, index), (1, 1)]).outputs[0]
    uv_next = g.at("CORNER", "FLOAT_VECTOR", uv, nxt)
    cross_z = g.split(g.vec("CROSS_PRODUCT", uv, uv_next))[2]
    area = g.on("FACE", "FLOAT", g.on("CORNER", "FLOAT", cross_z))
    sign = g.math("SUBTRACT", 1.0, g.math("MULTIPLY", g.math("LESS_THAN", area, 0.0), 2.0))
    tangent_v = g.at("CORNER", "FLOAT_VECTOR", tangent, corner)
    sign_v = g.at("CORNER", "FLOAT", sign, corner)
    along = g.vec("SCALE", normal, g.vec("DOT_PRODUCT", normal, tangent_v, out=1))
    t = g.vec("NORMALIZE", g.vec("SUBTRACT", tangent_v, along))
    return t, g.vec("SCALE", g.vec("CROSS_PRODUCT", normal, t), sign_v)


def _build(tree):
    g = Graph(tree)
    _interface(tree)
    gi, go = g.node("NodeGroupInput"), g.node("NodeGroupOutput")
    index = g.input("GeometryNodeInputIndex")
    uv = g.node("GeometryNodeInputNamedAttribute", [(0, gi.outputs["UV Map"])], data_type="FLOAT_VECTOR").outputs[0]
    corner = g.node("GeometryNodeCornersOfVertex", [(0, index), (2, 0)]).outputs[0]  # the vertex's first corner
    uv_v = g.at("CORNER", "FLOAT_VECTOR", uv, corner)
    color = g.node("GeometryNodeImageTexture", [("Image", gi.outputs["Image"]), ("Vector", uv_v)],
                   interpolation="Linear", extension="EXTEND").outputs[0]
    mid = gi.outputs["Mid-Level"]
    d = g.vec("SCALE", g.vec("SUBTRACT", color, g.xyz(mid, mid, mid)), gi.outputs["Strength"])
    c = g.split(d)
    normal = g.input("GeometryNodeInputNormal")
    height = g.vec("SCALE", normal, g.math("DIVIDE", g.math("ADD", g.math("ADD", c[0], c[1]), c[2]), 3.0))
    offsets = {"Height": height, "Object": d}
    if has_uv_tangent_node():
        t, b = _tangent_frame(g, uv, index, corner, normal)
        offsets["Tangent"] = g.vec("ADD", g.vec("ADD", g.vec("SCALE", t, c[0]), g.vec("SCALE", b, c[1])),
                                   g.vec("SCALE", normal, c[2]))
    offset = g.menu("VECTOR", gi.outputs["Map"], [(name, offsets[name]) for name in maps()])
    moved = g.node("GeometryNodeSetPosition", [(0, gi.outputs["Geometry"]), ("Offset", offset)])
    tree.links.new(moved.outputs[0], go.inputs[0])


SPEC = register_group(GroupSpec(GROUP_NAME, VERSION, _build, catalog="Tessera/Displacement",
                                description="Displace a mesh by a height or vector map laid out on its UVs"))


def node_group(kind="Tangent"):
    """The group, built on first use (and rebuilt when an older version is in the file); raises `TesseraError`
    when this Blender's group cannot show maps of ``kind``."""
    if kind not in maps():
        raise TesseraError(UV_TANGENT_MESSAGE)
    return ensure_group(SPEC)
