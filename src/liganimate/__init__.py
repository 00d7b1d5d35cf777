"""liganimate: a compiler and runtime for LIG ANIMATE (Cachola, 1986)."""

__version__ = "0.1.0"

__all__ = ["__version__", "load"]


def __getattr__(name: str):
    # liganimate.load is liganimate.api.load, imported on first use so that
    # `import liganimate` (which every command does) stays light.
    if name == "load":
        from liganimate.api import load

        return load
    raise AttributeError(f"module 'liganimate' has no attribute {name!r}")
