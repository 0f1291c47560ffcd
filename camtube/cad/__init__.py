"""CAD stage: 3-D models of the cut tube, as designed and as the job will cut it, and their verification.

- :mod:`camtube.cad.solid`: exact build123d B-rep of the design -> STEP (mm).
- :mod:`camtube.cad.mesh`: fast manifold3d mesh (design or any removed sheet region) -> STL.
- :mod:`camtube.cad.ascut`: kerf simulation of a Job in the unrolled frame (slugs, overcut, undercut, webs).
- :mod:`camtube.cad.measure`: section measurements on a mesh (backbone angle, notch width).
- :mod:`camtube.cad.verify`: the verification report (text + JSON).
- :mod:`camtube.cad.render`: PNG pictures (3-D tube, unrolled sheet).
- :mod:`camtube.cad.outputs`: :func:`build_outputs` writes all of it (``camtube cad``, ``camtube build``).

Frame (see :mod:`camtube.cad.frame`): tube axis X, x = 0 at the tip; rotary angle y / r_o about +X,
0 on +Y, 90 deg on +Z. Heavy libraries are imported inside the functions that use them.
"""
from __future__ import annotations


def build_outputs(pattern, job, outdir, **kwargs):
    """Write the CAD models, pictures and verification report of ``pattern``/``job`` into ``outdir``.

    See :func:`camtube.cad.outputs.build_outputs`; returns the written paths.
    """
    from camtube.cad.outputs import build_outputs as _build

    return _build(pattern, job, outdir, **kwargs)


__all__ = ["build_outputs"]
