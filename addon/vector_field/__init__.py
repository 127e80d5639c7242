"""Vector-field textures in Blender: the operator's settings."""
