"""Nailboards drawn on the GPU ([Clua et al., §4.1]): the board's quad, a dependent lookup through the offset map, and
per-texel depth (`draw`)."""
