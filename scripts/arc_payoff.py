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

``--run`` (LinuxCNC installed): the check on the controller itself. One slot of the slotted drawing
(0.4 x 3 mm, 0.2 mm half-circles) cut 10 times round without a stop, written twice by hand: as ``G1``
lines and ``G3`` arcs (G93, ``F`` the inverse of each move's minutes at 25 mm/s), and as the chords a pass
path gets (``simplify_closed``, 1 um); both run with ``camtube.motion.linuxcnc.run_program`` on the
machine, beside the chords' estimate and the arc model for the same 10 loops.
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
    """Time (s) of segments joined at the lower of their speed limits, from rest to rest (the estimate's passes)."""
    from camtube.machine.motion_time import chain_times

    return float(chain_times(L, vmax, a, np.ones(len(L), bool))[0].sum())


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


def run_slot(profile, loops: int = 10, v: float = 25.0) -> None:
    """The ``--run`` check (module docstring): print LinuxCNC's run time of the slot as arcs and as chords."""
    import tempfile

    from camtube.machine.motion_time import estimate_program
    from camtube.motion.linuxcnc import run_program
    from camtube.plan.paths import simplify_closed

    x0, x1, y0, y1, r = 1.6, 2.0, 1.0, 3.6, 0.2  # the straight sides x = x0, x1 from y0 to y1; half-circles r
    xc = 0.5 * (x0 + x1)
    pre = ["G21 G90 G17 G40 G49 G80", "G61", "M65 P0", "G93", "G0 Z0"]
    post = ["M63 P0", "M65 P0", "G94", "M2"]
    f = lambda L: f"F{60.0 * v / L:.3f}"  # noqa: E731  (G93: 1 / minutes of the move)
    arcs = pre + [f"G0 X{x1:.6f} Y{y0:.6f}", "M62 P0", "G64 P0.001"]
    for k in range(loops):
        arcs += [f"G1 X{x1:.6f} Y{y1:.6f} {f(y1 - y0)}", f"G3 X{x0:.6f} Y{y1:.6f} I{-r:.6f} J0 {f(math.pi * r)}",
                 f"G1 X{x0:.6f} Y{y0:.6f} {f(y1 - y0)}"] + (["G61"] if k == loops - 1 else []) + [
                 f"G3 X{x1:.6f} Y{y0:.6f} I{r:.6f} J0 {f(math.pi * r)}"]
    t = np.linspace(0.0, math.pi, 4000)  # the slot flattened finely (25 nm), then as a pass path's chords
    ring = np.vstack([[x1, y0], np.column_stack([xc + r * np.cos(t), y1 + r * np.sin(t)]),
                      np.column_stack([xc - r * np.cos(t), y0 - r * np.sin(t)])[:-1]])
    pts = simplify_closed(ring, 0.001, 0.0)
    loop = np.vstack([pts[1:], pts[:1]])
    chords = pre + [f"G0 X{pts[0, 0]:.6f} Y{pts[0, 1]:.6f}", "M62 P0", "G64 P0.001"]
    prev = pts[0]
    for k in range(loops):
        for j, q in enumerate(loop):
            if k == loops - 1 and j == len(loop) - 1:
                chords.append("G61")
            chords.append(f"G1 X{q[0]:.6f} Y{q[1]:.6f} {f(math.dist(prev, q))}")
            prev = q
    a = min(profile.axis(c).max_acceleration for c in profile.axes[:2])
    L = np.array([y1 - y0, math.pi * r] * 2 * loops)
    model = chain_time_s(L, np.array([v, min(v, math.sqrt(NORMAL_SHARE * a * r))] * 2 * loops),
                         np.array([a, TANGENTIAL_SHARE * a] * 2 * loops))
    with tempfile.TemporaryDirectory() as tmp:
        for name, lines in (("arcs", arcs), ("chords", chords)):
            path = Path(tmp) / f"slot-{name}.ngc"
            text = "\n".join(lines + post) + "\n"
            path.write_text(text)
            run = run_program(path, profile).run_time_s
            extra = (f", estimate {estimate_program(text, profile).total_s:.3f} s" if name == "chords"
                     else f", arc model {model:.3f} s")
            print(f"{profile.name}: the slot {loops} times round as {name}: LinuxCNC {run:.3f} s{extra}", flush=True)


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
    ap.add_argument("--run", action="store_true",
                    help="also run one slot as G2/G3 arcs and as chords on LinuxCNC (real time, about 10 s)")
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
    if args.run:
        from camtube.motion.linuxcnc import unavailable_reason

        why = unavailable_reason()
        if why:
            print(why, file=sys.stderr)
            return 2
        run_slot(profile)
    return 0


if __name__ == "__main__":
    sys.exit(main())
