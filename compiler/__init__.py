"""liganimate.compiler."""
