"""The terrain preview: tile patterns instanced per selected tile, heights fetched in the vertex shader
(``terrain_vert.glsl``). [Nunes 2011, §5]."""
