"""camtube: design, plan, cut and explain laser-micromachined notched-tube joints.

Stages (one sub-package each, data flows one way):

- :mod:`camtube.design`  pattern YAML -> :class:`~camtube.design.Pattern`, rules, geometry, unrolled contours
- :mod:`camtube.plan`    pattern/contours + process -> :class:`~camtube.plan.Job` (ordered passes)
- :mod:`camtube.export`  contours/jobs -> DXF, G-code, job file (pure writers)
- :mod:`camtube.cad`     pattern/job -> solid and as-cut models, verification
- :mod:`camtube.model`   measurements -> fitted joint model, effects, diagnosis

Heavy libraries (build123d, trimesh, matplotlib) are imported only inside the
modules that need them.
"""
from __future__ import annotations

__version__ = "0.1.0"
