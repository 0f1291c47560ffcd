"""Plan stage: expand cuts into the multi-pass laser process (a :class:`~camtube.plan.job.Job`).

``plan_job(pattern_or_contours, process)`` -> Job (passes kept as arrays, ``job.packed``);
``iter_moves(job)`` -> the move list every post-processor writes, in chunks of passes
(``job_moves(job)`` all at once, for small jobs); ``estimate(job)`` -> times;
``time_warning(job, estimate)`` -> a warning above ``process.max_time_h``;
``camtube.plan.safety.check_job`` -> raises :class:`~camtube.errors.SafetyError`;
``camtube.export.outputs.toolpath_streams`` / ``write_toolpaths`` -> the files, streamed.
"""
from camtube.plan.job import Job, Pass
from camtube.plan.moves import Estimate, Moves, estimate, iter_moves, job_moves, time_warning
from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS, plan_job, repeats_for

__all__ = ["Job", "Pass", "plan_job", "repeats_for", "job_moves", "iter_moves", "estimate", "time_warning", "Moves",
           "Estimate", "ORDERINGS", "DEFAULT_ORDERING"]
