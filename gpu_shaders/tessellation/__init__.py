"""The tessellation preview and the compute-shader apply: instanced refinement patterns whose vertex
shader places each point on the PN, Phong or linear surface (``patch_eval.glsl``). Seeds 000 §2-3 and 001 §5
(the tessellator's patterns and surfaces), done without a tessellation stage (Boubekeur & Schlick's instanced
refinement patterns)."""
