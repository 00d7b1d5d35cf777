"""liganimate.lang."""
