"""The geometry-nodes group that shows tangent-space vector maps (Blender's Displace modifier has object and
world space only). Numpy reference: `kernels.displacement.tangent_space`.

Per vertex, from the vertex's first face corner: the map sampled (Linear, Extend) at that corner's UV, the
MikkTSpace tangent of the UV Tangent node (Blender 5.0 and newer) made orthogonal to the vertex normal, and the
bitangent sign from the orientation of the corner's face in UV space (the sign of its UV polygon's area).
"""

from ...kernels.common.errors import TesseraError
from ..compat import UV_TANGENT_MESSAGE, has_uv_tangent_node
from ..node_groups import Graph, GroupSpec, ensure_group, register_group

GROUP_NAME = "Tessera Tangent Displacement"
INPUTS = (("Image", "NodeSocketImage"), ("UV Map", "NodeSocketString"), ("Mid-Level", "NodeSocketFloat"),
          ("Strength", "NodeSocketFloat"))
_VERSION = 1  # bump when the graph changes: older groups in a file are rebuilt


def _build(tree):
    g = Graph(tree)
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    for name, kind in INPUTS:
        tree.interface.new_socket(name, in_out="INPUT", socket_type=kind)
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gi = g.node("NodeGroupInput")
    go = g.node("NodeGroupOutput")
    index = g.node("GeometryNodeInputIndex").outputs[0]
    uv = g.node("GeometryNodeInputNamedAttribute", [(0, gi.outputs["UV Map"])], data_type="FLOAT_VECTOR").outputs[0]
    tangent = g.node("GeometryNodeUVTangent", [(1, uv)]).outputs[0]
    tangent.node.inputs[0].default_value = "Exact"
    # bitangent sign: the face's UV polygon area, summed over its corners (u_c v_next - u_next v_c)
    nxt = g.node("GeometryNodeOffsetCornerInFace", [(0, index), (1, 1)]).outputs[0]
    uv_next = g.at("CORNER", "FLOAT_VECTOR", uv, nxt)
    cross_z = g.node("ShaderNodeSeparateXYZ", [(0, g.vec("CROSS_PRODUCT", uv, uv_next))]).outputs[2]
    area = g.on("FACE", "FLOAT", g.on("CORNER", "FLOAT", cross_z))
    negative = g.math("LESS_THAN", area, 0.0)
    sign = g.math("SUBTRACT", 1.0, g.math("MULTIPLY", negative, 2.0))
    # the vertex's first corner carries its UV, tangent and sign
    corner = g.node("GeometryNodeCornersOfVertex", [(0, index), (2, 0)]).outputs[0]
    uv_v = g.at("CORNER", "FLOAT_VECTOR", uv, corner)
    tangent_v = g.at("CORNER", "FLOAT_VECTOR", tangent, corner)
    sign_v = g.at("CORNER", "FLOAT", sign, corner)
    normal = g.node("GeometryNodeInputNormal").outputs[0]
    along = g.vec("SCALE", normal, g.vec("DOT_PRODUCT", normal, tangent_v, out=1))
    t = g.vec("NORMALIZE", g.vec("SUBTRACT", tangent_v, along))
    b = g.vec("SCALE", g.vec("CROSS_PRODUCT", normal, t), sign_v)
    color = g.node("GeometryNodeImageTexture", [("Image", gi.outputs["Image"]), ("Vector", uv_v)],
                   interpolation="Linear", extension="EXTEND").outputs[0]
    mid = gi.outputs["Mid-Level"]
    d = g.node("ShaderNodeSeparateXYZ", [(0, g.vec("SUBTRACT", color, g.node(
        "ShaderNodeCombineXYZ", [(0, mid), (1, mid), (2, mid)]).outputs[0]))]).outputs
    strength = gi.outputs["Strength"]
    offset = g.vec("ADD", g.vec("ADD", g.vec("SCALE", t, d[0]), g.vec("SCALE", b, d[1])),
                   g.vec("SCALE", normal, d[2]))
    offset = g.vec("SCALE", offset, strength)
    setpos = g.node("GeometryNodeSetPosition", [(0, gi.outputs["Geometry"]), ("Offset", offset)])
    tree.links.new(setpos.outputs[0], go.inputs[0])


SPEC = register_group(GroupSpec(GROUP_NAME, _VERSION, _build, catalog="Tessera/Displacement",
                                 available=lambda: None if has_uv_tangent_node() else UV_TANGENT_MESSAGE))


def node_group():
    """The group, built on first use (and rebuilt when an older version is in the file)."""
    if not has_uv_tangent_node():
        raise TesseraError(UV_TANGENT_MESSAGE)
    return ensure_group(SPEC)
