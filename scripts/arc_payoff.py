"""What G2/G3 arcs would buy on a blended profile: each pass path's time as arcs against as chords (issue 21).

    python scripts/arc_payoff.py                                   # the three curved drawings, linuxcnc-path
    python scripts/arc_payoff.py --machine linuxcnc-path-airbearing --preset elliptical

For every distinct pass path of a curved drawing (one per cut and drill offset), from rest to rest:

- **chords**: the estimate of its chords (``TOL.path`` = 1 um) as written, blended by LinuxCNC within
  ``G64 P`` (:func:`camtube.machine.motion_time.trajectory_time`, within 0.5 % of LinuxCNC's runs);
- **arcs**: the same path as exact circular arcs, each of the finely flattened offset contour's (25 nm)
  vertices a piece of circle with that vertex's curvature, joined tangentially at speed, under LinuxCNC
  2.9's limits for circular moves (``pmCircleActualMaxVel``: ``v <= sqrt(0.866 a R)``;
  ``tpGetScaledAccel``: tangential acceleration ``0.5 a``) and lines at ``a``: an ideal fit (every
  curve an arc, no stops), so an upper bound of what G2/G3 output could gain;
- **bound**: the same with the whole acceleration normal and tangential (the time-optimal bound's model).

Prints per drawing the sum over its passes (every pass of the job) and the ratio arcs / chords.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

#: A piece of the fine ring whose ends both curve less than this (1/mm: radius 50 mm) is a line.
LINE_CURVATURE = 0.02
#: LinuxCNC 2.9 (tp.c, blendmath.c): the normal and tangential shares of the acceleration on a circle.
NORMAL_SHARE, TANGENTIAL_SHARE = math.sqrt(0.75), 0.5


def chain_time_s(L: np.ndarray, vmax: np.ndarray, a: np.ndarray) -> float:
    """Time (s) of segments joined at the lower of their speed limits, from rest to rest."""
    m = len(L)
    vj = np.minimum(vmax, np.concatenate((vmax[1:], [0.0])))
    vj[-1] = 0.0
    vl, Ll, al = vj.tolist(), L.tolist(), a.tolist()
    nxt = 0.0
    for i in range(m - 1, -1, -1):
        if vl[i] > 0:
            vl[i] = min(vl[i], math.sqrt(nxt * nxt + 2 * al[i + 1] * Ll[i + 1]))
        nxt = vl[i]
    prev = 0.0
    for i in range(m):
        if vl[i] > 0:
            vl[i] = min(vl[i], math.sqrt(prev * prev + 2 * al[i] * Ll[i]))
        prev = vl[i]
    v1 = np.array(vl)
    v0 = np.concatenate(([0.0], v1[:-1]))
    vp = np.sqrt(a * L + 0.5 * (v0 ** 2 + v1 ** 2))
    vc = np.minimum(vp, vmax)
    cruise = np.maximum(L - (vc ** 2 - v0 ** 2) / (2 * a) - (vc ** 2 - v1 ** 2) / (2 * a), 0.0)
    return float(((vc - v0) / a + (vc - v1) / a + np.where(vc > 0, cruise / vc, 0.0)).sum())


def arc_time_s(ring: np.ndarray, v: float, a: float, normal: float, tangential: float) -> float:
    """A closed fine ring (n, 2) cut as circle pieces of its vertices' curvature, from rest to rest."""
    p = np.asarray(ring, float)
    nxt = np.roll(p, -1, axis=0)
    L = np.hypot(*(nxt - p).T)
    d_in, d_out = p - np.roll(p, 1, axis=0), nxt - p
    turn = np.abs(np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0], np.einsum("ij,ij->i", d_in, d_out)))
    k = turn / (0.5 * (L + np.roll(L, 1)))  # curvature at each vertex (1/mm)
    k_seg = np.minimum(k, np.roll(k, -1))    # of each piece: a line's ends turn only where it meets a curve
    curved = k_seg > LINE_CURVATURE          # a circle piece, else a line
    with np.errstate(divide="ignore"):
        vmax = np.where(curved, np.minimum(v, np.sqrt(normal * a / k_seg)), v)
    acc = np.where(curved, tangential * a, a)
    return chain_time_s(L, vmax, acc)


def main() -> int:
    from run_motion import DRAWINGS, load_job

    from camtube.export.dialects import dialect_from_profile
    from camtube.machine import load_profile
    from camtube.machine.kinematics import machine_moves
    from camtube.machine.motion_time import estimate_machine_moves
    from camtube.plan.moves import job_moves
    from camtube.plan.planner import offset_contour, pass_offsets_mm

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machine", default="linuxcnc-path")
    ap.add_argument("--preset", action="append", help=f"drawing(s) (default {', '.join(DRAWINGS)})")
    args = ap.parse_args()
    profile = load_profile(args.machine)
    dialect = dialect_from_profile(profile)
    a = min(profile.axis(c).max_acceleration for c in profile.axes[:2])
    print(f"machine {profile.name}: a = {a:g} mm/s^2 in the plane; every pass from rest to rest")
    print("| drawing | passes | chords (estimate) s | arcs (LinuxCNC's circle limits) s | arcs / chords | "
          "bound model s |")
    print("|---|---|---|---|---|---|")
    for name in args.preset or DRAWINGS:
        job = load_job(name, (), "interleaved")  # passes entered by rapids: each from rest to rest
        pk = job.packed
        offsets = pass_offsets_mm(job.process)
        # each distinct (cut, drill) path, weighted by how many passes cut it
        count: dict[tuple[int, int], int] = {}
        first: dict[tuple[int, int], int] = {}
        for p, (c, d) in enumerate(zip(pk.pass_cut.tolist(), pk.pass_drill.tolist())):
            count[(c, d)] = count.get((c, d), 0) + 1
            first.setdefault((c, d), p)
        v = job.process.scan_speed_mm_s
        chords = arcs = bound = 0.0
        for (c, d), n in count.items():
            p = first[(c, d)]
            mv = job_moves(job, p, p + 1)
            cut = mv.rows(int(np.flatnonzero(mv.laser)[0]), len(mv))  # the pass's beam-on moves, from rest
            chords += n * estimate_machine_moves(machine_moves(job, profile, cut), profile).total_s
            ring = np.asarray(offset_contour(job.design[c], offsets[d], c).points)
            arcs += n * arc_time_s(ring, v, a, NORMAL_SHARE, TANGENTIAL_SHARE)
            bound += n * arc_time_s(ring, v, a, 1.0, 1.0)
        print(f"| {name} | {len(job.passes)} | {chords:.2f} | {arcs:.2f} | {arcs / chords:.3f} | {bound:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
