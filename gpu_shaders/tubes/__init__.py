"""The tube preview: ring patterns instanced per patch of segments, the anti-aliasing clamp in the vertex
shader (``tube_vert.glsl``). [Nunes 2011, §4] (eq. 4-2 to 4-8)."""
