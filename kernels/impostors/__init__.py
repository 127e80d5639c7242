"""Nailboards and impostors ([Clua et al.]): the relief pre-warp, when a board must be made again, where it stands, and
the octahedral views of a baked impostor. The module map: ``docs/architecture.md``."""
