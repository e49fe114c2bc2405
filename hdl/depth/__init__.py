"""The automatic depth engine (docs/depth.md): census, semi-global aggregation, winner-take-all, median."""

from hdl.depth.engine import DepthEngine, Schedule, schedule, tag_delay
from hdl.depth.ports import ResultReadSignature, SharedReadSignature

__all__ = ["DepthEngine", "Schedule", "schedule", "tag_delay", "SharedReadSignature", "ResultReadSignature"]
