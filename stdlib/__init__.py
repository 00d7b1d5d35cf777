"""liganimate.stdlib."""
