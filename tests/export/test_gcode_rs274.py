"""G-code read back through LinuxCNC's own interpreter (rs274 canonical commands).

Independent truth: rs274 parses the file; we replay its canonical commands
(STRAIGHT_TRAVERSE / STRAIGHT_FEED with X Y Z A B C, SET_FEED_RATE, the gate
bits/spindle) and check them against the pattern's cuts and the process, not
against the planner's own data.
"""
from __future__ import annotations

import math
import re
import subprocess

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.export.dialects import GRBL, LINUXCNC
from camtube.export.gcode import gcode
from camtube.plan import plan_job
from tests.conftest import PATTERNS, require_tool

CANON = re.compile(r"^\s*\d+\s+N\.+\s+([A-Z_0-9]+)\((.*)\)\s*$")
RS274_DECIMALS_TOL = 1.5e-4  # rs274 prints 4 decimals


def canonical(path) -> list[tuple[str, str]]:
    exe = require_tool("rs274")
    r = subprocess.run([exe, "-g", str(path)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "error" not in r.stderr.lower(), r.stderr
    out = []
    for line in r.stdout.splitlines():
        m = CANON.match(line)
        if m:
            out.append((m.group(1), m.group(2)))
    assert out, r.stdout[:2000]
    return out


def replay(cmds, dialect, ro):
    """Segments (kind, start(x, y_mm, z), end, gate_on, seconds) from canonical commands."""
    pos = np.zeros(4)  # x, y-axis value (mm or deg), z, a
    feed = 0.0
    gate = False
    segs = []
    gate_count = 0
    for name, args in cmds:
        if name in ("SET_MOTION_OUTPUT_BIT", "SET_AUX_OUTPUT_BIT") and args.strip() == "0":
            assert dialect is LINUXCNC
            gate, gate_count = True, gate_count + 1
        elif name in ("CLEAR_MOTION_OUTPUT_BIT", "CLEAR_AUX_OUTPUT_BIT") and args.strip() == "0":
            gate = False
        elif name in ("START_SPINDLE_CLOCKWISE", "START_SPINDLE_COUNTERCLOCKWISE"):
            assert dialect is GRBL
            gate, gate_count = True, gate_count + 1
        elif name == "STOP_SPINDLE_TURNING":
            gate = False
        elif name == "SET_FEED_RATE":
            feed = float(args)
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            v = [float(t) for t in args.split(",")]
            new = np.array([v[0], v[1], v[2], v[3]])
            dx, dy, dz, da = new - pos
            if dialect.rotary:
                assert abs(dy) < 1e-9, "no Y axis on the rotary stage"
                lin = math.hypot(dx, dz)
                surf = math.hypot(dx, math.radians(da) * ro)
                minutes = (lin if lin > 0 else abs(da)) / feed if name == "STRAIGHT_FEED" else float("nan")
                y0, y1 = math.radians(pos[3]) * ro, math.radians(new[3]) * ro
            else:
                assert abs(da) < 1e-9
                surf = math.hypot(dx, dy)
                minutes = math.sqrt(dx * dx + dy * dy + dz * dz) / feed if name == "STRAIGHT_FEED" else float("nan")
                y0, y1 = pos[1], new[1]
            segs.append((name, (pos[0], y0, pos[2]), (new[0], y1, new[2]), gate, surf, minutes * 60.0))
            pos = new
    return segs, gate_count


def inside_some_cut(pattern, x, y, tol):
    ro = pattern.tube.outer_radius_mm
    c = pattern.tube.circumference_mm
    for cut in pattern.cuts:
        yc = cut.y_center_mm(ro)
        dy = (y - yc + c / 2) % c - c / 2
        if cut.x_start_mm - tol <= x <= cut.x_end_mm + tol and abs(dy) <= cut.arc_mm / 2 + tol:
            return True
    return False


def expected_cut_length(pattern, repeats):
    pr = pattern.process
    total = 0.0
    for cut in pattern.cuts:
        for d in range(pr.drill_passes):
            o = pr.kerf_mm / 2 + d * pr.drill_offset_mm
            total += 2 * ((cut.width_mm - 2 * o) + (cut.arc_mm - 2 * o))
    return total * 2 * repeats


@pytest.mark.parametrize("name,repeats", [("tube1", 4), ("tube2", 6), ("tube3", 8), ("tube1-bidirectional", 4)])
@pytest.mark.parametrize("dialect", [LINUXCNC, GRBL], ids=lambda d: d.name)
def test_rs274_reads_back_a_safe_job(tmp_path, name, repeats, dialect):
    pattern = load_pattern(PATTERNS / f"{name}.yaml")
    job = plan_job(pattern)
    path = tmp_path / f"{name}{dialect.suffix}"
    path.write_text(gcode(job, dialect))
    segs, gates = replay(canonical(path), dialect, pattern.tube.outer_radius_mm)
    pr = pattern.process
    assert gates == len(pattern.cuts) * pr.drill_passes * 2 * repeats
    zs_on = set()
    cut_len = 0.0
    n_feed = 0
    for name_, a, b, on, surf, secs in segs:
        if name_ == "STRAIGHT_TRAVERSE":
            assert not on, f"laser on during a traverse to {b}"
            continue
        if abs(a[2] - b[2]) > 1e-9:
            assert not on, "laser on during a focus move"
            continue
        n_feed += 1
        assert on, f"feed move with the laser off to {b}"
        assert surf > 0
        speed = surf / secs
        assert speed == pytest.approx(pr.scan_speed_mm_s, rel=0.01), (a, b, speed)
        for x, y, _ in (a, b):
            assert inside_some_cut(pattern, x, y, RS274_DECIMALS_TOL), (x, y)
        assert 0 <= a[0] <= pattern.tube.length_mm
        zs_on.add(round(b[2], 4))
        cut_len += surf
    assert n_feed > 0
    assert sorted(zs_on) == pytest.approx([-pr.defocus_mm, 0.0])
    assert cut_len == pytest.approx(expected_cut_length(pattern, repeats), rel=1e-4)


def test_rs274_rejects_what_it_cannot_run(tmp_path):
    # guards the harness: a broken file must make canonical() fail, not pass silently
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21\nG93\nG1 X1 A2\nM2\n")
    with pytest.raises(AssertionError):
        canonical(bad)
