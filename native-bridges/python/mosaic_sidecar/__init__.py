"""MOSAIC's Python sidecar: runs the Python block's user function in its own process."""

from .protocol import VERSION as PROTOCOL_VERSION

__all__ = ["PROTOCOL_VERSION"]
