"""The generator's version (written into every input hash); imports nothing."""

__version__ = "0.1.0"
