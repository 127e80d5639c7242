"""Nailboards: relief-mapped, depth-correct impostors (seed 003, digest Part B).

`prewarp` is the relief-texture pre-warp (eq. 7 in the corrected convention of digest §B.4) with the
occlusion-compatible traversal, the offset map and two-pass 1-D hole filling; `validity` the sprite resolution
(eq. 8) and the tests that say when a board must be regenerated (§B.6: approach, parallax, resolution eq. 9).
"""
