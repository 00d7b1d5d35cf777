"""liganimate.runtime: motions, figures, scenes and the rasterizer."""
