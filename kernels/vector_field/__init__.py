"""Vector-field textures: images of streaks that follow a steady 2-D flow, for materials ([Nellmedin 2014,
§5.5.4]). The module map: ``docs/architecture.md``."""
