"""One-point parametric surfaces on the GPU (seed 000 §2.3): a shared quad-domain pattern drawn once per control
point, the formula evaluated in the vertex shader (`draw`)."""
