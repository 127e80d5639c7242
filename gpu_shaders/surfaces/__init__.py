"""One-point parametric surfaces on the GPU ([Nunes 2011, §2.3]): a shared quad-domain pattern drawn once per control
point, the formula evaluated in the vertex shader (`draw`)."""
