"""The tube preview: ring patterns instanced per patch of segments, the anti-aliasing clamp in the vertex
shader (``tube_vert.glsl``)."""
