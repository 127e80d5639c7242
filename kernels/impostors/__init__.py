"""Nailboards: relief-mapped, depth-correct impostors ([Clua et al.]).

`prewarp` is the relief-texture pre-warp (eq. 7 in the convention of [Clua et al., correction 1]) with the
occlusion-compatible traversal, the offset map and two-pass 1-D hole filling; `validity` the sprite resolution
(eq. 8) and the tests that say when a board must be regenerated ([Clua et al., §5.1]: approach, parallax, resolution eq.
9).
"""
