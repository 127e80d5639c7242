"""Vector-field textures on the GPU: the streaks advected by a compute shader and splatted into an offscreen."""
