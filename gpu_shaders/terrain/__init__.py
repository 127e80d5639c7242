"""The terrain preview: tile patterns instanced per selected tile, heights fetched in the vertex shader
(``terrain_vert.glsl``). Seed 000 §5."""
