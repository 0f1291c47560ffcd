"""Plan stage: expand cuts into the multi-pass laser process (a :class:`~camtube.plan.job.Job`)."""
from camtube.plan.job import Job, Pass

__all__ = ["Job", "Pass"]
