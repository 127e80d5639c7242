"""The tessellation preview and the compute-shader apply: instanced refinement patterns whose vertex
shader places each point on the PN, Phong or linear surface (``patch_eval.glsl``)."""
