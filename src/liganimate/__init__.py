"""liganimate: a compiler and runtime for LIG ANIMATE (Cachola, 1986)."""

__version__ = "0.1.0"
