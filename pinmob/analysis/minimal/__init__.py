"""Minimal closures: the closures with exactly their independent equations, and the mechanism so fixed."""

from pinmob.analysis.minimal.proposal import MinimalClosure, MinimalClosures, minimal_closures

__all__ = ["MinimalClosure", "MinimalClosures", "minimal_closures"]
