"""Verification report: the CAD models and the simulated cut against the design.

Checks (each pass/fail with measured value, expected value and tolerance):

- ``design.stl.watertight``; ``design.stl.volume`` within 0.5 % of the
  analytic volume ``pi (r_o^2 - r_i^2) L - sum_cuts (arc / r_o) / 2 (r_o^2 - r_i^2) width``
  (a drawn cut: its sheet area mapped radially, ``area / r_o (r_o^2 - r_i^2) / 2``);
- ``design.step.volume`` (B-rep) within 0.2 % of the analytic volume, and
  ``design.step.reimport``: the STEP file read back has the same volume within 0.2 %;
- per rectangular notch (drawn outlines are covered by the volume checks and
  named in the report's note), from sections of the design mesh: ``notch[i].phi`` (backbone
  angle at ``x = x_c``) within 1 % of ``(2 pi r_o - s) / r_o``; ``notch[i].width``
  (empty ``x`` interval on the half-plane at the notch angle) within 1 % of h;
- per cut, from the kerf simulation (:mod:`camtube.cad.ascut`):
  ``cut[i].slug`` freed (or ablated), ``cut[i].overcut`` / ``cut[i].undercut``
  depth within the allowance, with the place named;
- ``ascut.stl.watertight``; ``ascut.stl.volume`` within 0.5 % of the tube
  volume minus the removed sheet area mapped radially (area / r_o * (r_o^2 - r_i^2) / 2);
- ``notch[i].phi.as_cut``: the as-cut mesh's backbone angle within 1 % of the
  design plus the expected kerf overcut (2 allowance / r_o);
- ``min_web``: the narrowest as-cut bridge between two cuts >= ``rules.min_web``, within ``TOL.rule`` as the
  design rules. A job without kerf compensation thins every web by the kerf (half on each side): a web designed
  at the limit fails, and the check says so and what to change (the design rules warn of it first).

The report is plain data (:class:`Report`); :func:`report_text` and
:func:`report_json` render it deterministically.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from camtube.design.geometry import backbone_angle_rad
from camtube.design.pattern import Pattern
from camtube.tol import TOL

STL_VOLUME_RTOL = 0.005
STEP_VOLUME_RTOL = 0.002
PHI_RTOL = 0.01
WIDTH_RTOL = 0.01


@dataclass(frozen=True)
class Check:
    """One verification check.

    Attributes
    ----------
    name : str
        e.g. ``notch[3].phi``.
    passed : bool
    measured, expected : float | str
        In ``unit``.
    tolerance : str
        The criterion, human readable.
    unit : str
    detail : str
        What was measured and where (for failures: the cut and the place).
    """

    name: str
    passed: bool
    measured: float | str
    expected: float | str
    tolerance: str
    unit: str = ""
    detail: str = ""


@dataclass(frozen=True)
class Report:
    """Verification of one pattern/job."""

    name: str
    checks: tuple[Check, ...]
    summary: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def failures(self) -> tuple[Check, ...]:
        return tuple(c for c in self.checks if not c.passed)


def analytic_volume_mm3(pattern: Pattern) -> float:
    """Volume (mm^3) of the tube minus radial-walled cuts.

    A rectangle removes the annular sector ``(arc / r_o) / 2 (r_o^2 - r_i^2) width``;
    a drawn outline (or a slit's kerf region) its sheet area mapped radially
    (:func:`sheet_area_volume_mm3`), which is exact for radial walls.
    """
    from camtube.cad.mesh import design_regions, region_area_mm2

    t = pattern.tube
    ring = t.outer_radius_mm**2 - t.inner_radius_mm**2
    regions = design_regions(pattern) if any(c.is_drawn for c in pattern.cuts) else None
    cut = 0.0
    for i, c in enumerate(pattern.cuts):
        if c.is_drawn:
            cut += sheet_area_volume_mm3(region_area_mm2(regions[i]), t.outer_radius_mm, t.inner_radius_mm)
        else:
            cut += (c.arc_mm / t.outer_radius_mm) / 2.0 * ring * c.width_mm
    return math.pi * ring * t.length_mm - cut


def sheet_area_volume_mm3(area_mm2: float, outer_radius_mm: float, inner_radius_mm: float) -> float:
    """Volume (mm^3) of a radial-walled cut whose sheet area (at r_o) is ``area_mm2``."""
    return area_mm2 / outer_radius_mm * (outer_radius_mm**2 - inner_radius_mm**2) / 2.0


def _rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b) if b else abs(a - b)


def verify(pattern: Pattern, *, design_mesh=None, ascut=None, ascut_mesh=None, solid_volume_mm3: float | None = None,
           step_volume_mm3: float | None = None, segments: int | None = None) -> Report:
    """Run every check whose inputs are given.

    Parameters
    ----------
    pattern : Pattern
        The design (cuts indexed as in ``Job.design``).
    design_mesh, ascut_mesh : trimesh.Trimesh, optional
        Meshes from :mod:`camtube.cad.mesh` (tube along X, see :mod:`camtube.cad.frame`).
    ascut : camtube.cad.ascut.AsCut, optional
        Kerf simulation of the job.
    solid_volume_mm3, step_volume_mm3 : float, optional
        Volume of the build123d solid, and of its STEP file read back.
    segments : int, optional
        Sides of the meshes' polygonal circles (default :func:`camtube.cad.mesh.auto_segments`).
    """
    from camtube.cad.mesh import auto_segments

    seg = segments or auto_segments(len(pattern.cuts))
    t = pattern.tube
    ro = t.outer_radius_mm
    v_ana = analytic_volume_mm3(pattern)
    checks: list[Check] = []
    summary: dict = {"analytic_volume_mm3": v_ana, "tube": asdict(t), "cuts": len(pattern.cuts),
                     "notches": len(pattern.notches)}
    # sections at x_c measure a rectangle's phi and width; a drawn outline is checked by volume instead
    notch_idx = [i for i, c in enumerate(pattern.cuts) if c.kind == "notch" and not c.is_drawn]
    drawn = [i for i, c in enumerate(pattern.cuts) if c.is_drawn]
    if drawn:
        summary["not_rectangles"] = (f"{len(drawn)} drawn cut(s) ({', '.join(f'cut[{i}]' for i in drawn[:8])}"
                                     f"{', ...' if len(drawn) > 8 else ''}) are not rectangles: their phi and width "
                                     "are not measured from sections; the volume checks cover them")

    if design_mesh is not None:
        v = float(design_mesh.volume)
        summary["design_stl_volume_mm3"] = v
        checks.append(Check("design.stl.watertight", bool(design_mesh.is_watertight), str(bool(design_mesh.is_watertight)),
                            "True", "trimesh is_watertight", "", f"{len(design_mesh.faces)} triangles"))
        checks.append(Check("design.stl.volume", _rel(v, v_ana) <= STL_VOLUME_RTOL, v, v_ana,
                            f"<= {STL_VOLUME_RTOL:.1%}", "mm^3", f"rel. error {_rel(v, v_ana):.2e}"))
        xs = [pattern.cuts[i].x_mm for i in notch_idx]
        phis = _phi(design_mesh, xs, seg)
        widths = _widths(design_mesh, pattern, notch_idx, seg)
        for k, i in enumerate(notch_idx):
            c = pattern.cuts[i]
            want = backbone_angle_rad(ro, c.arc_mm)
            where = f"section x = {c.x_mm:.4f} mm"
            checks.append(Check(f"notch[{i}].phi", bool(_rel(phis[k], want) <= PHI_RTOL), math.degrees(phis[k]),
                                math.degrees(want), f"<= {PHI_RTOL:.0%}", "deg", where))
            checks.append(Check(f"notch[{i}].width", bool(_rel(widths[k], c.width_mm) <= WIDTH_RTOL), widths[k],
                                c.width_mm, f"<= {WIDTH_RTOL:.0%}", "mm",
                                f"half-plane at {c.angle_deg:.2f} deg around x = {c.x_mm:.4f} mm"))
    if solid_volume_mm3 is not None:
        summary["design_step_volume_mm3"] = solid_volume_mm3
        checks.append(Check("design.step.volume", _rel(solid_volume_mm3, v_ana) <= STEP_VOLUME_RTOL, solid_volume_mm3,
                            v_ana, f"<= {STEP_VOLUME_RTOL:.1%}", "mm^3",
                            f"rel. error {_rel(solid_volume_mm3, v_ana):.2e}"))
    if step_volume_mm3 is not None and solid_volume_mm3 is not None:
        summary["design_step_reimport_volume_mm3"] = step_volume_mm3
        checks.append(Check("design.step.reimport", _rel(step_volume_mm3, solid_volume_mm3) <= STEP_VOLUME_RTOL,
                            step_volume_mm3, solid_volume_mm3, f"<= {STEP_VOLUME_RTOL:.1%}", "mm^3",
                            "STEP read back with build123d import_step"))

    if ascut is not None:
        _ascut_checks(pattern, ascut, checks, summary)
    if ascut_mesh is not None and ascut is not None:
        _ascut_mesh_checks(pattern, ascut, ascut_mesh, notch_idx, seg, checks, summary)
    return Report(pattern.name, tuple(checks), summary)


def _phi(mesh, xs, seg) -> np.ndarray:
    from camtube.cad.measure import backbone_angles_rad

    return backbone_angles_rad(mesh, xs, seg) if xs else np.zeros(0)


def _widths(mesh, pattern: Pattern, idx, seg) -> np.ndarray:
    from camtube.cad.measure import gap_widths_mm

    out = np.full(len(idx), np.nan)
    by_angle: dict[float, list[int]] = {}
    for k, i in enumerate(idx):
        by_angle.setdefault(pattern.cuts[i].angle_deg, []).append(k)
    for ang, ks in sorted(by_angle.items()):
        out[ks] = gap_widths_mm(mesh, math.radians(ang), [pattern.cuts[idx[k]].x_mm for k in ks], seg)
    return out


def _ascut_checks(pattern: Pattern, a, checks: list[Check], summary: dict) -> None:
    summary.update({
        "kerf_mm": a.kerf_mm, "kerf_from_process": a.kerf_from_process,
        "overcut_mm2": a.overcut_mm2, "undercut_mm2": a.undercut_mm2,
        "allow_overcut_mm": a.allow_overcut_mm, "allow_undercut_mm": a.allow_undercut_mm,
        "overcut": [asdict(r) for r in a.overcut], "undercut": [asdict(r) for r in a.undercut],
        "cut_results": [asdict(c) for c in a.cuts],
    })
    for c in a.cuts:
        x0, y0, x1, y1 = a.design[c.index].bounds
        label = f"{c.kind} at x {x0:.3f}..{x1:.3f} mm, angle {math.degrees(0.5 * (y0 + y1) / a.outer_radius_mm) % 360:.1f} deg"
        ok = c.status in ("slug freed", "ablated")
        detail = f"{label}: {c.status}"
        if c.status == "not freed":
            un = [r for r in a.undercut if r.cut_index == c.index]
            detail += ("; the kerf ring does not enclose the design area: " + un[0].describe()) if un else ""
        checks.append(Check(f"cut[{c.index}].slug", ok, c.status, "slug freed | ablated", "freed or ablated", "",
                            detail))
        for kind, regs, allow in (("overcut", a.overcut, a.allow_overcut_mm),
                                  ("undercut", a.undercut, a.allow_undercut_mm)):
            mine = [r for r in regs if r.cut_index == c.index]
            depth = max((r.depth_mm for r in mine), default=0.0)
            area = sum(r.area_mm2 for r in mine)
            worst = max(mine, key=lambda r: r.depth_mm, default=None)
            checks.append(Check(f"cut[{c.index}].{kind}", depth <= allow, depth, 0.0, f"depth <= {allow * 1000:.1f} um",
                                "mm", f"{label}: {area:.5f} mm^2" + (f"; {worst.describe()}" if worst else "")))
    w = a.min_web
    if w is not None:
        summary["min_web_mm"] = w.as_cut_mm
        summary["min_web_design_mm"] = w.design_mm
        # rules.min_web is the bridge the part needs, as cut: a job without kerf compensation cuts each side of a web
        # half a kerf wide, so a web designed at the limit fails here, and says why (the design rules warn of it)
        need = pattern.rules.min_web_mm
        thinned = a.expected_overcut_mm > 0 and w.design_mm >= need - TOL.rule > w.as_cut_mm
        why = (f"; thinned by the kerf ({2.0 * a.expected_overcut_mm:g} mm simulated): process.kerf = 0 (no kerf "
               f"compensation); fix: set process.kerf to the beam's kerf, or design the web "
               f">= {need + 2.0 * a.expected_overcut_mm:g} mm" if thinned else "")
        checks.append(Check("min_web", w.as_cut_mm >= need - TOL.rule, w.as_cut_mm, need, ">= rules.min_web", "mm",
                            f"between cut[{w.a}] and cut[{w.b}] at x {w.where[0]:.3f} mm, y {w.where[1]:.3f} mm "
                            f"(design {w.design_mm:.4f} mm){why}"))


def _ascut_mesh_checks(pattern, a, mesh, notch_idx, seg, checks: list[Check], summary: dict) -> None:
    import shapely

    from camtube.cad.ascut import wrap_sheet

    t = pattern.tube
    ro, ri = t.outer_radius_mm, t.inner_radius_mm
    v = float(mesh.volume)
    sheet = shapely.intersection(wrap_sheet(a.removed, a.circumference_mm),
                                 shapely.box(0.0, -1.0, t.length_mm, a.circumference_mm + 1.0))
    want = math.pi * (ro**2 - ri**2) * t.length_mm - sheet_area_volume_mm3(sheet.area, ro, ri)
    summary["ascut_stl_volume_mm3"] = v
    summary["ascut_expected_volume_mm3"] = want
    checks.append(Check("ascut.stl.watertight", bool(mesh.is_watertight), str(bool(mesh.is_watertight)), "True",
                        "trimesh is_watertight", "", f"{len(mesh.faces)} triangles"))
    checks.append(Check("ascut.stl.volume", _rel(v, want) <= STL_VOLUME_RTOL, v, want, f"<= {STL_VOLUME_RTOL:.1%}",
                        "mm^3", "expected: tube minus the removed sheet area mapped radially"))
    xs = [pattern.cuts[i].x_mm for i in notch_idx]
    phis = _phi(mesh, xs, seg)
    slack = 2.0 * a.allow_overcut_mm / ro
    for k, i in enumerate(notch_idx):
        c = pattern.cuts[i]
        design = backbone_angle_rad(ro, c.arc_mm)
        tol = PHI_RTOL * design + slack
        checks.append(Check(f"notch[{i}].phi.as_cut", bool(abs(phis[k] - design) <= tol), math.degrees(phis[k]),
                            math.degrees(design), f"within {math.degrees(tol):.3f} deg (1 % + kerf allowance)", "deg",
                            f"as-cut mesh, section x = {c.x_mm:.4f} mm"))


def _num(v):
    if isinstance(v, float):
        return float(f"{v:.9g}") if math.isfinite(v) else str(v)
    if isinstance(v, dict):
        return {k: _num(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_num(x) for x in v]
    return v


def report_json(report: Report) -> str:
    """Deterministic JSON text (``camtube.cad-verify/1``) of a report."""
    doc = {"format": "camtube.cad-verify/1", "name": report.name, "passed": report.passed,
           "failed": len(report.failures), "checks": [_num(asdict(c)) for c in report.checks],
           "summary": _num(report.summary)}
    return json.dumps(doc, indent=1, sort_keys=False) + "\n"


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def report_text(report: Report) -> str:
    """Readable text of a report: failures first, then every check."""
    s = report.summary
    lines = [f"camtube CAD verification: {report.name}",
             f"result: {'PASS' if report.passed else 'FAIL'} ({len(report.checks) - len(report.failures)}/"
             f"{len(report.checks)} checks passed)", ""]
    facts = [("analytic volume", "analytic_volume_mm3", "mm^3"), ("design STL volume", "design_stl_volume_mm3", "mm^3"),
             ("design STEP volume", "design_step_volume_mm3", "mm^3"),
             ("STEP re-imported", "design_step_reimport_volume_mm3", "mm^3"),
             ("as-cut STL volume", "ascut_stl_volume_mm3", "mm^3"), ("simulated kerf", "kerf_mm", "mm"),
             ("overcut (total)", "overcut_mm2", "mm^2"), ("undercut (total)", "undercut_mm2", "mm^2"),
             ("min web as cut", "min_web_mm", "mm"), ("min web designed", "min_web_design_mm", "mm")]
    for label, key, unit in facts:
        if key in s:
            lines.append(f"  {label:<20} {_fmt(s[key])} {unit}")
    if "not_rectangles" in s:
        lines.append(f"  note: {s['not_rectangles']}")
    if "kerf_from_process" in s and not s["kerf_from_process"]:
        lines.append("  (process.kerf is 0: the simulation assumes this beam kerf; the job overcuts by half of it)")
    lines.append("")
    if report.failures:
        lines.append("FAILED:")
        for c in report.failures:
            lines.append(f"  {c.name}: measured {_fmt(c.measured)} {c.unit}, expected {_fmt(c.expected)} {c.unit} "
                         f"({c.tolerance}) -- {c.detail}")
        lines.append("")
    lines.append("checks:")
    for c in report.checks:
        lines.append(f"  [{'ok' if c.passed else 'FAIL'}] {c.name}: {_fmt(c.measured)} {c.unit} "
                     f"(expected {_fmt(c.expected)}, {c.tolerance}) {c.detail}".rstrip())
    return "\n".join(lines) + "\n"
