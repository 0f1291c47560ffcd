"""Plan stage: expand cuts into the multi-pass laser process (a :class:`~camtube.plan.job.Job`).

``plan_job(pattern_or_dxf, process)`` -> Job; ``job_moves(job)`` -> the move list every
post-processor writes; ``estimate(job)`` -> times; ``camtube.plan.safety.check_job`` -> raises
:class:`~camtube.errors.SafetyError`.
"""
from camtube.plan.job import Job, Pass
from camtube.plan.moves import Estimate, Moves, estimate, job_moves
from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS, plan_job, repeats_for

__all__ = ["Job", "Pass", "plan_job", "repeats_for", "job_moves", "estimate", "Moves", "Estimate",
           "ORDERINGS", "DEFAULT_ORDERING"]
