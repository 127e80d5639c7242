"""Drawing Loop-subdivided meshes (the viewport preview): `draw.LoopDrawData`."""
