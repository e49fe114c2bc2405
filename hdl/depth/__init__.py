"""The automatic depth engine (docs/depth.md): census, semi-global aggregation, winner-take-all, median."""

from .engine import DepthEngine, Schedule, schedule
from .ports import ResultReadSignature, SharedReadSignature

__all__ = ["DepthEngine", "Schedule", "schedule", "SharedReadSignature", "ResultReadSignature"]
