"""SVG preview of the unrolled pattern, written from the same contours as the DXF.

No plotting library: the picture is a small, deterministic SVG a README or a
browser shows directly. x runs to the right (from the tip), y upwards (arc
length on the outer surface), like the DXF.
"""
from __future__ import annotations

from xml.sax.saxutils import escape

from camtube.design.contour import outline, sheet_contours
from camtube.design.pattern import Pattern

COLOURS = {"notch": "#c62828", "hole": "#1565c0", "cut": "#2e7d32"}


def _fmt(v: float) -> str:
    return f"{v:.4f}".rstrip("0").rstrip(".")


def unrolled_svg(pattern: Pattern, px_per_mm: float = 40.0, margin_px: float = 60.0) -> str:
    """SVG text of the unrolled sheet of ``pattern`` with its cuts, axes and a legend."""
    t = pattern.tube
    w_mm, h_mm = t.length_mm, t.circumference_mm
    W = w_mm * px_per_mm + 2 * margin_px
    H = h_mm * px_per_mm + 2 * margin_px

    def X(x):
        return _fmt(margin_px + x * px_per_mm)

    def Y(y):
        return _fmt(margin_px + (h_mm - y) * px_per_mm)

    def poly(points, colour, extra="", closed=True):
        pts = " ".join(f"{X(x)},{Y(y)}" for x, y in points)
        if not closed:  # a slit: the beam follows the path
            return f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="1.6"{extra}/>'
        return f'<polygon points="{pts}" fill="{colour}" fill-opacity="0.25" stroke="{colour}" stroke-width="1.2"{extra}/>'

    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_fmt(W)}" height="{_fmt(H)}" '
        f'viewBox="0 0 {_fmt(W)} {_fmt(H)}" font-family="sans-serif" font-size="13">',
        f'<rect width="{_fmt(W)}" height="{_fmt(H)}" fill="white"/>',
        f"<title>{escape(pattern.name)}: unrolled outer surface</title>",
    ]
    o = outline(pattern)
    pts = " ".join(f"{X(x)},{Y(y)}" for x, y in o.points)
    out.append(f'<polygon points="{pts}" fill="#f5f5f5" stroke="#777" stroke-dasharray="6 4" stroke-width="1"/>')
    for con in sheet_contours(pattern):
        out.append(poly(con.points, COLOURS.get(con.kind, COLOURS["cut"]), closed=con.closed))
    # axes: ticks every 1 mm in x, at 0, pi r_o, 2 pi r_o in y
    step = 1.0 if w_mm <= 30 else 5.0
    x = 0.0
    while x <= w_mm + 1e-9:
        out.append(f'<line x1="{X(x)}" y1="{Y(0)}" x2="{X(x)}" y2="{_fmt(float(Y(0)) + 6)}" stroke="#333"/>')
        if abs(x / (step * 2) - round(x / (step * 2))) < 1e-9:
            out.append(f'<text x="{X(x)}" y="{_fmt(float(Y(0)) + 20)}" text-anchor="middle">{_fmt(x)}</text>')
        x += step
    for frac, label in ((0.0, "0"), (0.5, "\u03c0 r\u2092"), (1.0, "2\u03c0 r\u2092")):
        y = frac * h_mm
        out.append(f'<line x1="{X(0)}" y1="{Y(y)}" x2="{_fmt(float(X(0)) - 6)}" y2="{Y(y)}" stroke="#333"/>')
        out.append(f'<text x="{_fmt(float(X(0)) - 9)}" y="{_fmt(float(Y(y)) + 4)}" text-anchor="end">{label}</text>')
    out.append(f'<text x="{_fmt(W / 2)}" y="{_fmt(H - 12)}" text-anchor="middle">x along the tube from the tip (mm)</text>')
    out.append(f'<text x="16" y="{_fmt(H / 2)}" transform="rotate(-90 16 {_fmt(H / 2)})" text-anchor="middle">'
               "y arc length on the outer surface</text>")
    n, hcount = len(pattern.notches), len(pattern.holes)
    out.append(f'<text x="{X(0)}" y="24" font-weight="bold">{escape(pattern.name)}: {n} notches (red), '
               f"{hcount} tendon hole{'s' if hcount != 1 else ''} (blue), r\u2092 = {_fmt(t.outer_radius_mm)} mm"
               "</text>")
    out.append("</svg>")
    return "\n".join(out) + "\n"
