"""Design rules on drawn cuts (web, overlap, nesting, backbone of a slanted notch), layers, seam slits.

Each drawing is small and made here with ezdxf; expectations are checked
against shapely on the same shapes.
"""
from __future__ import annotations

import math

import pytest
from shapely.geometry import Point, box

from camtube.design.drawing import load_drawing
from camtube.design.rules import section_arc_mm
from camtube.design.source import DrawingOptions
from camtube.errors import PatternError
from examples.dxf.make_examples import C, MID, Sheet, draw_outline, draw_polygon


def save(sheet, tmp_path, name="t.dxf"):
    path = tmp_path / name
    sheet.doc.saveas(path)
    return path


def test_web_between_a_circle_hole_and_a_notch_is_measured_on_the_outlines(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, MID - 1.5), (3.5, MID - 1.5), (3.5, MID + 1.5), (3.0, MID + 1.5)], "NOTCHES")
    # a hole 0.05 mm from the notch's edge (shapely says so): the bounding boxes would say the same,
    # but only the true outline distance is reported
    s.msp.add_circle(s.at(3.7, MID), 0.15, dxfattribs={"layer": "HOLES"})
    d = box(3.0, MID - 1.5, 3.5, MID + 1.5).distance(Point(3.7, MID).buffer(0.15, quad_segs=256))
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    text = str(err.value)
    assert "CIRCLE #" in text and "layer HOLES" in text and "LWPOLYLINE #" in text
    assert f"web {d:.4g} mm" in text


def test_a_hole_drawn_inside_a_notch_is_an_overlap(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, MID - 1.5), (3.5, MID - 1.5), (3.5, MID + 1.5), (3.0, MID + 1.5)], "NOTCHES")
    s.msp.add_circle(s.at(3.25, MID), 0.1, dxfattribs={"layer": "HOLES"})
    path = save(s, tmp_path)
    # the notch encloses every other cut too: which rectangle is the tube is ambiguous, never guessed
    with pytest.raises(PatternError, match="2 nested rectangles could each be the tube outline"):
        load_drawing(path, [], DrawingOptions())
    with pytest.raises(PatternError, match=r"CIRCLE #\w+ on layer HOLES and LWPOLYLINE .* collides with"):
        load_drawing(path, [], DrawingOptions(outer_radius_mm=1.0))


def test_a_frame_around_the_outline_is_not_taken_for_it(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("BORDER")
    draw_polygon(s, [(-5.0, -5.0), (20.0, -5.0), (20.0, 12.0), (-5.0, 12.0)], "BORDER")  # a drawing frame
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    path = save(s, tmp_path)
    with pytest.raises(PatternError, match="nested rectangles could each be the tube outline"):
        load_drawing(path, [], DrawingOptions())
    # the radius says which; the frame, on a layer that cuts by default, is then refused as a cut outside the tube
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer BORDER: notch .* outside the tube"):
        load_drawing(path, [], DrawingOptions(outer_radius_mm=1.0))
    p = load_drawing(path, [], DrawingOptions(outer_radius_mm=1.0, layers=(("BORDER", "ignore"),))).pattern
    assert p.tube.length_mm == pytest.approx(10.0) and len(p.cuts) == 1


def test_an_outline_drawn_twice_is_one_outline(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_outline(s, layer="0")
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1 and "1 (outline drawn again)" in loaded.summary


def test_drawn_cuts_that_clear_the_web_are_accepted_even_when_their_boxes_would_clash(tmp_path):
    """Two triangles nested like teeth: boxes overlap, outlines are 0.2 mm apart (shapely)."""
    s = Sheet()
    draw_outline(s)
    a = [(3.0, MID - 1.0), (4.0, MID - 1.0), (3.0, MID + 1.0)]
    b = [(4.2, MID - 1.0), (4.2, MID + 1.0), (3.2, MID + 1.0)]
    draw_polygon(s, a, "NOTCHES")
    draw_polygon(s, b, "NOTCHES")
    p = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern
    assert len(p.notches) == 2 and all(c.is_drawn for c in p.notches)


def test_backbone_of_a_slanted_notch_is_its_widest_section(tmp_path):
    """A parallelogram whose box is nearly a full turn but whose every section leaves a 1 mm backbone."""
    s = Sheet()
    draw_outline(s)
    h = C - 1.0  # every section x = const cuts this much
    pts = [(3.0, 0.2), (3.5, 0.8), (3.5, 0.8 + h), (3.0, 0.2 + h)]
    draw_polygon(s, pts, "NOTCHES")
    p = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern
    (cut,) = p.notches
    assert cut.arc_mm == pytest.approx(h + 0.6)  # the bounding box: backbone 0.4 mm by it
    assert section_arc_mm(cut) == pytest.approx(h, abs=1e-6)
    # the rule uses the section: with a 0.5 mm backbone rule, accepted; with 1.1 mm, refused naming the entity
    load_drawing(save(s, tmp_path), ["rules.min_backbone_arc=0.5"], DrawingOptions())
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer NOTCHES: backbone arc .* = 1\.0000 mm"):
        load_drawing(save(s, tmp_path), ["rules.min_backbone_arc=1.1"], DrawingOptions())


def test_cut_outside_the_tube_names_the_entity(tmp_path):
    s = Sheet()  # no outline: the tube is given, the drawing's origin is the tip
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    draw_polygon(s, [(9.8, 1.0), (10.3, 1.0), (10.3, 2.0), (9.8, 2.0)], "NOTCHES")
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer NOTCHES: notch .* outside the tube"):
        load_drawing(save(s, tmp_path), [], DrawingOptions(outer_radius_mm=1.0, length_mm=10.0))


def test_hidden_and_construction_layers_are_set_aside_and_counted(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("OLD").off()
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    draw_polygon(s, [(5.0, 1.0), (5.5, 1.0), (5.5, 2.0), (5.0, 2.0)], "OLD")
    draw_polygon(s, [(6.0, 1.0), (6.5, 1.0), (6.5, 2.0), (6.0, 2.0)], "CONSTRUCTION")
    s.msp.add_mtext("note", dxfattribs={"layer": "NOTCHES", "insert": s.at(1, 1)})
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1
    assert "from 5 entities" in loaded.summary
    for phrase in ("1 (annotation)", "1 (hidden layer)", "1 (ignored layer)"):
        assert phrase in loaded.summary
    # the user can switch a hidden layer back on for camtube
    again = load_drawing(save(s, tmp_path), [], DrawingOptions(layers=(("OLD", "notch"),)))
    assert len(again.pattern.cuts) == 2


def test_a_non_plotting_layer_is_set_aside_as_cad_programs_leave_it_off_the_print(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("REF").dxf.plot = 0      # reference geometry: shown on screen, never printed
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    draw_polygon(s, [(5.0, 1.0), (5.5, 1.0), (5.5, 2.0), (5.0, 2.0)], "REF")
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1
    assert "1 (non-plotting layer)" in loaded.summary
    # mapped to a role by the user, it is cut
    again = load_drawing(save(s, tmp_path), [], DrawingOptions(layers=(("REF", "notch"),)))
    assert len(again.pattern.cuts) == 2


@pytest.mark.parametrize("hide", ["off", "plot"])
def test_cuts_only_on_a_layer_set_aside_are_named_with_the_way_to_cut_them(tmp_path, hide):
    s = Sheet()
    draw_outline(s)
    layer = s.doc.layers.add("CUTS")
    if hide == "off":
        layer.off()
    else:
        layer.dxf.plot = 0
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "CUTS")
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    text = str(err.value)
    assert "the drawing has no cuts" in text
    assert "layer CUTS" in text and "--layer CUTS=notch" in text
    assert ("hidden layer" if hide == "off" else "non-plotting layer") in text


def test_a_t_of_three_slits_is_one_line_naming_all_three(tmp_path):
    """The bad-input search: a T drawn as three slits printed three lines, one per overlapping pair."""
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("SLITS")
    for a, b in [((3.0, MID - 1.0), (3.0, MID)), ((3.0, MID), (3.0, MID + 1.0)), ((3.0, MID), (4.0, MID))]:
        s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": "SLITS"})
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    lines = str(err.value).splitlines()
    assert len(lines) == 1, lines
    assert "3 slits meet or cross" in lines[0] and lines[0].count("LINE #") == 3, lines[0]
    assert "fix: draw each slit as one path" in lines[0]


def test_two_crossing_slits_are_still_one_line_for_the_pair(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("SLITS")
    s.msp.add_line(s.at(3.0, MID - 1.0), s.at(3.0, MID + 1.0), dxfattribs={"layer": "SLITS"})
    s.msp.add_line(s.at(2.5, MID), s.at(3.5, MID), dxfattribs={"layer": "SLITS"})
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    lines = str(err.value).splitlines()
    assert len(lines) == 1 and " overlaps " in lines[0] and lines[0].count("LINE #") == 2, lines
    assert "fix: move the two cuts apart in the drawing, or delete one" in lines[0]


@pytest.mark.parametrize("c", [0.01, 0.03])
def test_a_notch_with_small_chamfered_corners_is_cut_as_drawn_not_square(tmp_path, c):
    """The bad-input search: a 0.5 x 2.5 mm notch with 0.03 mm chamfers (its eight vertices on the bounding box's
    edges, its missing area within the rectangle test's tolerance) was cut as the plain rectangle: every pass ran
    through the square corners, 21 um outside the drawn cut."""
    from shapely.geometry import Polygon

    s = Sheet()
    draw_outline(s)
    x0, y0, x1, y1 = 3.0, 1.0, 3.5, 3.5
    pts = [(x0 + c, y0), (x1 - c, y0), (x1, y0 + c), (x1, y1 - c), (x1 - c, y1), (x0 + c, y1), (x0, y1 - c),
           (x0, y0 + c)]
    draw_polygon(s, pts, "NOTCHES")
    cut = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern.cuts[0]
    assert cut.outline is not None and len(cut.outline) >= 8, cut
    drawn = Polygon(pts)
    assert Polygon(cut.outline).area == pytest.approx(drawn.area, abs=1e-9)


def _headerless(k: float) -> str:
    """A DXF of an ENTITIES section only (as scripts and old CAM exporters write): a tube of r_o 0.75 mm and two notches,
    drawn at ``k`` drawing units per mm; no $INSUNITS anywhere."""
    def line(a, b, layer):
        return f"0\nLINE\n8\n{layer}\n10\n{a[0] * k}\n20\n{a[1] * k}\n11\n{b[0] * k}\n21\n{b[1] * k}\n"

    def rect(x0, y0, x1, y1, layer):
        return (line((x0, y0), (x1, y0), layer) + line((x1, y0), (x1, y1), layer) + line((x1, y1), (x0, y1), layer)
                + line((x0, y1), (x0, y0), layer))

    ent = rect(0, 0, 14.0, 2 * math.pi * 0.75, "CONSTRUCTION") + rect(2, 1, 2.5, 3.5, "NOTCHES")
    return "0\nSECTION\n2\nENTITIES\n" + ent + "0\nENDSEC\n0\nEOF\n"


def test_a_drawing_without_a_header_asks_for_its_unit_and_takes_units(tmp_path):
    """The bad-input search: ezdxf gives a file without a HEADER section its default header (unit m): a tube drawn in
    inches was cut 39x too large with exit 0, and --units inch was refused quoting a $INSUNITS the file does not hold."""
    path = tmp_path / "inch.dxf"
    path.write_text(_headerless(1 / 25.4))
    with pytest.raises(PatternError) as err:
        load_drawing(path, [], DrawingOptions())
    assert "does not say its unit (no $INSUNITS in the file" in str(err.value) and "--units" in str(err.value)
    loaded = load_drawing(path, [], DrawingOptions(units="inch"))
    assert loaded.pattern.tube.outer_radius_mm == pytest.approx(0.75, abs=1e-6)


def test_inf_in_a_whole_number_code_is_one_line_not_a_traceback(tmp_path):
    path = tmp_path / "inf.dxf"
    text = _headerless(1.0).replace("0\nLINE\n8\nNOTCHES\n", "0\nLINE\n8\nNOTCHES\n62\ninf\n", 1)
    path.write_text(text)
    with pytest.raises(PatternError, match="not a valid DXF file"):
        load_drawing(path, [], DrawingOptions(units="mm"))


def test_a_block_reference_on_a_frozen_layer_is_set_aside_whole(tmp_path):
    """The bad-input search: an INSERT on a frozen layer, its block's outline on layer NOTCHES, was cut, though
    AutoCAD shows none of it. (An INSERT on a layer that is only off hides its layer-0 entities alone.)"""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    block = s.doc.blocks.new("N")
    block.add_lwpolyline([(0, 0), (0.5, 0), (0.5, 1.0), (0, 1.0)], close=True, dxfattribs={"layer": "NOTCHES"})
    s.doc.layers.add("FROZEN").freeze()
    s.msp.add_blockref("N", s.at(6.0, 1.0), dxfattribs={"layer": "FROZEN"})
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1 and "1 (hidden layer)" in loaded.summary, loaded.summary
    again = load_drawing(save(s, tmp_path), [], DrawingOptions(layers=(("FROZEN", "notch"),)))
    assert len(again.pattern.cuts) == 2


@pytest.mark.parametrize("extra_mm", [0.0, 1.0])
def test_a_slit_all_the_way_round_the_tube_is_refused(tmp_path, extra_mm):
    """The bad-input search: a LINE slit at one x as long as the circumference (or longer) was accepted with exit 0:
    it cuts the tube in two (and the longer one cuts part of itself twice); a notch of that arc is refused."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(6.0, 1.0), (6.5, 1.0), (6.5, 2.0), (6.0, 2.0)], "NOTCHES")
    s.doc.layers.add("SLITS")
    s.msp.add_line(s.at(3.0, 0.5), s.at(3.0, 0.5 + C + extra_mm), dxfattribs={"layer": "SLITS"})
    with pytest.raises(PatternError, match=r"LINE #\w+ on layer SLITS: slit at x=3 mm.* runs all the way round the tube"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_a_slit_winding_more_than_one_turn_is_refused_naming_it(tmp_path):
    """The bad-input search: a helical slit of several turns was refused only by the G-code's safety check ("143 unsafe
    moves"), naming no entity, after the summary said it was imported."""
    s = Sheet()   # (no outline drawn: the tube given, as a drawing of a helix unrolled past the sheet is)
    s.doc.layers.add("SLITS")
    s.msp.add_line(s.at(3.0, 0.5), s.at(6.0, 0.5 + 2.5 * C), dxfattribs={"layer": "SLITS"})
    with pytest.raises(PatternError, match=r"LINE #\w+ on layer SLITS: slit at .* winds 2.50 turns around the tube"):
        load_drawing(save(s, tmp_path), [], DrawingOptions(outer_radius_mm=1.0, length_mm=10.0))


@pytest.mark.parametrize("layer", ["0", "CONSTRUCTION"])
def test_an_outline_of_lines_that_overshoot_the_corners_is_named(tmp_path, layer):
    """The bad-input search: the outline drawn as four LINEs extended 0.1 mm past each corner (as CAD leaves them) was
    not closed, and the only notch was named "the tube outline" with a LINE "outside it"."""
    s = Sheet()
    e = 0.1
    for a, b in [((-e, 0.0), (10.0 + e, 0.0)), ((10.0, -e), (10.0, C + e)), ((10.0 + e, C), (-e, C)),
                 ((0.0, C + e), (0.0, -e))]:
        s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": layer})
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    text = str(err.value)
    assert "cross one another near their ends instead of meeting" in text and text.count("LINE #") == 4, text
    assert "TRIM" in text and "would be the tube outline" not in text


def test_construction_lines_that_cross_beside_a_drawn_outline_are_no_matter(tmp_path):
    s = Sheet()
    draw_outline(s)
    e = 0.1
    for a, b in [((2.0 - e, 0.5), (4.0 + e, 0.5)), ((4.0, 0.5 - e), (4.0, 2.5 + e)), ((4.0 + e, 2.5), (2.0 - e, 2.5)),
                 ((2.0, 2.5 + e), (2.0, 0.5 - e))]:
        s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": "CONSTRUCTION"})
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    assert len(load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern.cuts) == 1


def test_a_slit_across_the_seam_is_joined(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.msp.add_line(s.at(4.0, C - 0.5), s.at(4.0, C), dxfattribs={"layer": "SLITS"})
    s.msp.add_line(s.at(4.0, 0.0), s.at(4.0, 0.7), dxfattribs={"layer": "SLITS"})
    p = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern
    (slit,) = p.slits
    assert slit.arc_mm == pytest.approx(1.2) and slit.width_mm == 0.0
    assert math.radians(slit.angle_deg) == pytest.approx(0.1, abs=1e-9)  # centre 0.1 mm past the seam, r_o = 1


def test_a_closed_outline_on_a_slit_layer_is_refused(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "SLITS")
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer SLITS: a closed outline on a slit layer"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_unreadable_entities_are_refused_on_cut_layers_and_set_aside_elsewhere(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.msp.add_3dface([(5, 1, 0), (5.5, 1, 0), (5.5, 2, 0), (5, 2, 0)], dxfattribs={"layer": "NOTCHES"})
    with pytest.raises(PatternError, match=r"3DFACE #\w+ on layer NOTCHES: a 3DFACE cannot be read as a cut"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    s2 = Sheet()
    draw_outline(s2)
    draw_polygon(s2, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s2.msp.add_3dface([(5, 1, 0), (5.5, 1, 0), (5.5, 2, 0), (5, 2, 0)], dxfattribs={"layer": "CONSTRUCTION"})
    loaded = load_drawing(save(s2, tmp_path, "u.dxf"), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1 and "1 (ignored layer)" in loaded.summary


def test_not_a_dxf_is_one_clear_error(tmp_path):
    bad = tmp_path / "bad.dxf"
    bad.write_text("this is not a drawing\n")
    with pytest.raises(PatternError, match="not a valid DXF"):
        load_drawing(bad, [], DrawingOptions())
    with pytest.raises(PatternError, match="cannot read the drawing"):
        load_drawing(tmp_path / "missing.dxf", [], DrawingOptions())


def test_a_drawing_cut_short_anywhere_is_one_clear_error_or_read(tmp_path):
    """A DXF file cut short (a copy that did not finish) was a StopIteration traceback where it ends inside the
    header; cut anywhere, it is read, or refused as not a valid DXF file."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    whole = save(s, tmp_path).read_bytes()
    cut = tmp_path / "cut.dxf"
    refused = 0
    for k in [50, 51, 200, 1000] + [int(f * len(whole)) for f in (0.1, 0.3, 0.5, 0.7, 0.9, 0.99)]:
        cut.write_bytes(whole[:k])
        try:
            load_drawing(cut, [], DrawingOptions())
        except PatternError as exc:
            assert "not a valid DXF" in str(exc) or "cannot" in str(exc), str(exc)
            refused += 1
    assert refused >= 1
    cut.write_bytes(whole[:50])
    with pytest.raises(PatternError, match="it ends inside a section"):
        load_drawing(cut, [], DrawingOptions())


@pytest.mark.parametrize("radius, layer", [(-0.1, "HOLES"), (float("nan"), "HOLES"), (float("nan"), "CONSTRUCTION")])
def test_a_circle_whose_radius_is_negative_or_nan_is_refused_on_a_cut_layer(tmp_path, radius, layer):
    """A radius of nan was dropped without a word (the drawing then 'has no cuts', or cut nothing there); a
    negative one was cut as a hole of its size."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.msp.add_circle(s.at(5.0, MID), 0.15, dxfattribs={"layer": layer}).dxf.radius = radius
    if layer == "CONSTRUCTION":   # set aside there, as any entity of an ignored layer
        assert len(load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern.cuts) == 1
        return
    with pytest.raises(PatternError, match=rf"CIRCLE #\w+ on layer HOLES: has a radius of {radius:g}, not a number"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_an_inf_vertex_or_angle_is_refused_not_dropped(tmp_path):
    """The bad-input search: an LWPOLYLINE vertex of inf was dropped by ezdxf's path and the notch cut as a triangle; an
    ARC's start angle of inf made the arc vanish ("zero length"): both with exit 0."""
    s = Sheet()
    draw_outline(s)
    pl = s.msp.add_lwpolyline([s.at(3.0, 1.0), s.at(3.5, 1.0), s.at(3.5, 2.0), s.at(3.0, 2.0)], close=True,
                              dxfattribs={"layer": "NOTCHES"})
    pts = list(pl.get_points("xyseb"))
    pts[1] = (float("inf"),) + tuple(pts[1][1:])
    pl.set_points(pts, "xyseb")
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer NOTCHES: one of its vertices is not a finite"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.doc.layers.add("SLITS")
    s.msp.add_arc(s.at(6.0, MID), 0.5, 0.0, 90.0, dxfattribs={"layer": "SLITS"}).dxf.start_angle = float("inf")
    with pytest.raises(PatternError, match=r"ARC #\w+ on layer SLITS: its start angle \(start_angle\) is not a finite"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_an_ellipse_of_axis_ratio_zero_is_one_line_on_a_cut_layer_and_set_aside_elsewhere(tmp_path):
    """The bad-input search: an ELLIPSE whose ratio (group 40) is 0.0, as a program other than ezdxf writes a flat one,
    was a ZeroDivisionError traceback on any layer (ezdxf clamps the ratio on saving: the text is patched here)."""
    import re

    for layer in ("HOLES", "CONSTRUCTION"):
        s = Sheet()
        draw_outline(s)
        draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
        s.msp.add_ellipse(s.at(6.0, MID), (0.2, 0, 0), 0.5, dxfattribs={"layer": layer})
        path = save(s, tmp_path)
        text = path.read_text()
        patched = re.sub(r"(AcDbEllipse\n(?:.*\n)*? 40\n)0\.5\n", r"\g<1>0.0\n", text, count=1)
        assert patched != text
        path.write_text(patched)
        if layer == "CONSTRUCTION":
            assert len(load_drawing(path, [], DrawingOptions()).pattern.cuts) == 1
        else:
            with pytest.raises(PatternError, match=r"ELLIPSE #\w+ on layer HOLES: cannot be read as a curve \(an ellipse "
                               "of axis ratio 0"):
                load_drawing(path, [], DrawingOptions())


def test_an_old_style_polyline_with_a_width_is_refused_as_an_lwpolyline_is(tmp_path):
    s = Sheet()
    draw_outline(s)
    pl = s.msp.add_polyline2d([s.at(3.0, 1.0), s.at(3.5, 1.0), s.at(3.5, 2.0), s.at(3.0, 2.0)], close=True,
                              dxfattribs={"layer": "NOTCHES"})
    pl.dxf.default_start_width = 0.1
    pl.dxf.default_end_width = 0.1
    with pytest.raises(PatternError, match=r"POLYLINE #\w+ on layer NOTCHES: is a polyline with a width"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_a_pattern_without_cuts_is_one_line_for_every_job_not_a_traceback(tmp_path):
    """The bad-input search: notch.count 0 and no holes was ValueError (max() of an empty sequence) in toolpath,
    build and cad."""
    from tests.test_cli_errors import camtube

    for cmd in ("toolpath", "build", "cad"):
        out = tmp_path / cmd
        r = camtube(cmd, "tube1", "--set", "notch.count=0", "--set", "holes=[]", "-o", str(out))
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert "the pattern has no cuts" in r.stderr and "fix: set notch.count to 1 or more" in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and not out.exists()


@pytest.mark.parametrize("value", ["true", "abc"])
def test_a_tube_radius_set_on_a_drawing_that_is_not_a_number_is_refused(value):
    """The bad-input search: --set tube.outer_radius=true on a drawing was a tube of 1 mm (a bool is an int), exit 0;
    a YAML pattern refuses it."""
    from tests.conftest import ROOT
    from tests.test_cli_errors import camtube

    r = camtube("design", str(ROOT / "examples" / "dxf" / "blocks.dxf"), "--set", f"tube.outer_radius={value}", "-q")
    assert r.returncode == 2 and "tube.outer_radius: the outer radius must be a positive number" in r.stderr, r.stderr


def test_a_spline_fit_polyline_is_cut_along_its_fit_points(tmp_path):
    """The bad-input search: a POLYLINE smoothed by PEDIT Spline (its frame's corners, vertex flag 16, and the curve's
    fit points, flag 8, in one list) was refused as "the outline crosses itself"; CAD programs show the fit points'
    curve."""
    from shapely.geometry import Polygon

    s = Sheet()
    draw_outline(s)
    p = s.msp.add_polyline2d([s.at(2, 3), s.at(3, 3), s.at(3, 4), s.at(2, 4)], close=True,
                             dxfattribs={"layer": "NOTCHES"})
    p.dxf.flags = p.dxf.flags | 4
    for v in p.vertices:
        v.dxf.flags = 16
    fit = [(2.5 + 0.45 * math.cos(2 * math.pi * k / 24), 3.5 + 0.45 * math.sin(2 * math.pi * k / 24))
           for k in range(24)]
    p.append_vertices([s.at(x, y) for x, y in fit], dxfattribs={"flags": 8})
    cut = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern.cuts[0]
    assert cut.outline is not None and len(cut.outline) == 24
    assert Polygon(cut.outline).area == pytest.approx(Polygon(fit).area, rel=1e-9)


@pytest.mark.parametrize("layer", ["NOTCHES", "SLITS"])
def test_a_line_pasted_twice_is_named_as_a_copy(tmp_path, layer):
    """The bad-input search: a notch of four LINEs with one pasted twice was refused as three open paths ("close the
    outline", which was closed); a slit LINE pasted twice as "a closed outline on a slit layer"."""
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("SLITS")
    if layer == "NOTCHES":
        pts = [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)]
        for a, b in zip(pts, pts[1:] + pts[:1]):
            s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": layer})
        s.msp.add_line(s.at(*pts[0]), s.at(*pts[1]), dxfattribs={"layer": layer})
    else:
        draw_polygon(s, [(6.0, 1.0), (6.5, 1.0), (6.5, 2.0), (6.0, 2.0)], "NOTCHES")
        for _ in range(2):
            s.msp.add_line(s.at(3.0, 1.0), s.at(3.0, 2.0), dxfattribs={"layer": layer})
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    lines = str(err.value).splitlines()
    assert len(lines) == 1 and "the same path drawn twice" in lines[0] and lines[0].count("LINE #") == 2, lines


def test_a_notch_of_lines_pasted_twice_is_one_line(tmp_path):
    """A notch of four LINEs pasted twice whole printed one line per LINE (four); it is one line naming the copies."""
    s = Sheet()
    draw_outline(s)
    pts = [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)]
    handles = []
    for copy in range(2):
        for a, b in zip(pts, pts[1:] + pts[:1]):
            handles.append(s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": "NOTCHES"}).dxf.handle)
    with pytest.raises(PatternError) as err:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    lines = str(err.value).splitlines()
    assert len(lines) == 1, lines
    assert "4 paths drawn twice" in lines[0] and all(f"#{h}" in lines[0] for h in handles[4:]), lines


def test_a_bad_tag_is_named_on_one_line(tmp_path):
    s = Sheet()
    draw_outline(s)
    text = save(s, tmp_path).read_text().splitlines(keepends=True)
    at = next(k for k, ln in enumerate(text) if ln.strip() == "LWPOLYLINE")
    text[at - 1] = "abc\n"   # the entity's group code 0 replaced
    bad = tmp_path / "bad.dxf"
    bad.write_text("".join(text))
    with pytest.raises(PatternError) as err:
        load_drawing(bad, [], DrawingOptions())
    assert "not a valid DXF" in str(err.value) and "\n" not in str(err.value).strip()


def test_fills_are_set_aside_only_when_their_boundary_is_drawn(tmp_path):
    s = Sheet()
    draw_outline(s)
    pts = [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)]
    draw_polygon(s, pts, "NOTCHES")
    s.msp.add_hatch(dxfattribs={"layer": "NOTCHES"}).paths.add_polyline_path([s.at(*p) for p in pts])
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1 and "1 (fill of a drawn outline)" in loaded.summary
    # a hatch alone (the only trace of a hole) is not dropped silently
    s.msp.add_hatch(dxfattribs={"layer": "HOLES"}).paths.add_polyline_path(
        [s.at(6.0, 1.0), s.at(6.3, 1.0), s.at(6.3, 1.3), s.at(6.0, 1.3)])
    with pytest.raises(PatternError, match=r"HATCH #\w+ on layer HOLES: a filled area .* not drawn"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_thick_polylines_and_xrefs_are_refused(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.msp.add_lwpolyline([s.at(3.0, 1.0), s.at(3.0, 2.0)], dxfattribs={"layer": "SLITS", "const_width": 0.05})
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer SLITS: is a polyline with a width"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.doc.add_xref_def("other.dxf", "OTHER")
    s.msp.add_blockref("OTHER", s.at(5, 1), dxfattribs={"layer": "NOTCHES"})
    with pytest.raises(PatternError, match=r"INSERT #\w+ on layer NOTCHES: places an external reference"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


def test_an_arc_with_a_mirrored_extrusion_is_placed_where_it_is_drawn(tmp_path):
    """AutoCAD's MIRROR gives circles extrusion (0, 0, -1) with the centre in OCS: (-x, y) is drawn at (x, y)."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(5.0, 1.0), (5.5, 1.0), (5.5, 2.0), (5.0, 2.0)], "NOTCHES")
    s.msp.add_circle((-3.0, MID), 0.15, dxfattribs={"layer": "HOLES", "extrusion": (0, 0, -1)})
    p = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern
    (h,) = p.holes
    assert h.x_mm == pytest.approx(3.0, abs=1e-9) and h.angle_deg == pytest.approx(180.0, abs=1e-6)


def test_a_circle_in_a_block_scaled_unevenly_and_turned_is_the_ellipse_it_shows(tmp_path):
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(6.0, 1.0), (6.5, 1.0), (6.5, 2.0), (6.0, 2.0)], "NOTCHES")
    blk = s.doc.blocks.new("ROUND")
    blk.add_circle((0.0, 0.0), 0.1)
    s.msp.add_blockref("ROUND", s.at(3.0, MID), dxfattribs={"layer": "HOLES", "xscale": 2.0, "yscale": 1.0,
                                                             "rotation": 90.0})
    p = load_drawing(save(s, tmp_path), [], DrawingOptions()).pattern
    (h,) = p.holes
    from shapely.geometry import Polygon

    assert Polygon(h.outline).area == pytest.approx(math.pi * 0.2 * 0.1, rel=5e-4)
    assert (h.width_mm, h.arc_mm) == pytest.approx((0.2, 0.4), abs=1e-6)  # turned 90 deg: the long axis is y
    assert h.x_mm == pytest.approx(3.0, abs=1e-9) and h.angle_deg == pytest.approx(180.0, abs=1e-6)


def test_an_outline_that_misses_a_cut_is_not_replaced_by_the_drawing_origin(tmp_path):
    s = Sheet(origin=(0.0, 5.0))  # outline drawn 5 mm up: taking the drawing origin would turn every cut
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    draw_polygon(s, [(10.2, 1.0), (10.7, 1.0), (10.7, 2.0), (10.2, 2.0)], "NOTCHES")  # past the tube's end
    with pytest.raises(PatternError, match=r"is the size of the tube outline but does not enclose every cut; "
                                           r"LWPOLYLINE #\w+ on layer NOTCHES lies outside it"):
        load_drawing(save(s, tmp_path), [], DrawingOptions(outer_radius_mm=1.0, length_mm=10.0))


def test_a_spline_by_fit_points_only_is_refused(tmp_path):
    s = Sheet()
    draw_outline(s)
    s.msp.add_spline([(3, 1), (3.5, 1.5), (3, 2), (2.5, 1.5), (3, 1)], dxfattribs={"layer": "NOTCHES"})
    with pytest.raises(PatternError, match=r"SPLINE #\w+ on layer NOTCHES: is a SPLINE given by fit points only"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())


@pytest.mark.parametrize("add,words", [
    (lambda s: s.msp.add_circle(s.at(5.0, 3.0), 2e4, dxfattribs={"layer": "HOLES"}),
     r"CIRCLE #\w+ on layer HOLES: is 4e\+04 mm across, far larger than any tube"),
    (lambda s: s.msp.add_line(s.at(3.0, 1.0), s.at(3.0, 1e5), dxfattribs={"layer": "SLITS"}),
     r"LINE #\w+ on layer SLITS: is 1e\+05 mm across"),
    (lambda s: s.msp.add_arc(s.at(5.0, 3.0), 1e12, 0.0, 1e-7, dxfattribs={"layer": "SLITS"}),
     r"ARC #\w+ on layer SLITS: lies at \(1e\+12, .*\) mm, too far from the origin"),
    (lambda s: s.msp.add_hatch(dxfattribs={"layer": "HOLES"}).paths.add_edge_path().add_arc(
        s.at(5.0, 3.0), 2e4, 0.0, 360.0), r"HATCH #\w+ on layer HOLES: is 4e\+04 mm across"),
], ids=["circle", "line", "arc", "hatch"])
def test_an_entity_far_larger_than_any_tube_is_refused_before_it_is_flattened(tmp_path, add, words):
    """A CIRCLE of radius 1e12 mm on a cut layer was flattened to 25 nm chords: the kernel killed camtube (out of
    memory, no message); 1e9 mm took 4 GB and then 'out of memory'. Refused from its control points now (the sizes
    here are small enough to flatten without the fix; test_mistakes runs the 1e12 mm circle)."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    add(s)
    with pytest.raises(PatternError, match=words + ".*fix: ") as exc:
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(exc.value.issues) == 1


def test_a_drawing_far_from_the_origin_is_refused_naming_the_entities(tmp_path):
    """A drawing at 1e15 mm (where a float64 resolves 0.125 mm) was read with r_o = 0.9947 mm for 1."""
    s = Sheet(origin=(1e15, 1e15))
    draw_outline(s, layer="0")
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer 0: lies at \(1e\+15, 1e\+15\) mm, too far "
                       r"from the origin.*fix: move the drawing near the origin"):
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    s = Sheet(origin=(5e4, -5e4))  # 50 m away: read as drawn
    draw_outline(s, layer="0")
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    loaded = load_drawing(save(s, tmp_path, "near.dxf"), [], DrawingOptions())
    assert loaded.pattern.tube.outer_radius_mm == pytest.approx(1.0, abs=1e-9)


def test_curves_on_an_ignored_layer_are_set_aside_without_being_flattened(tmp_path, monkeypatch):
    """A CIRCLE of radius 1e9 mm on layer CONSTRUCTION was flattened (4 GB) before it was set aside; a curve there
    cannot be the tube outline (a rectangle), so no curve of an ignored layer is flattened at all."""
    from ezdxf.path import Path as EzPath

    flattened: list[int] = []
    original = EzPath.flattening

    def counting(self, *args, **kwargs):
        pts = list(original(self, *args, **kwargs))
        flattened.append(len(pts))
        return iter(pts)

    monkeypatch.setattr(EzPath, "flattening", counting)
    s = Sheet()
    draw_outline(s)
    s.doc.layers.add("OLD").off()
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.msp.add_circle(s.at(5.0, 3.0), 2e4, dxfattribs={"layer": "CONSTRUCTION"})  # larger than any tube
    s.msp.add_circle(s.at(5.0, 3.0), 1000.0, dxfattribs={"layer": "CONSTRUCTION"})
    s.msp.add_ellipse(s.at(5.0, 3.0), (500.0, 0.0, 0.0), 0.5, dxfattribs={"layer": "OLD"})
    s.msp.add_line(s.at(0.0, 0.0), (1e300, 1e300), dxfattribs={"layer": "CONSTRUCTION"})
    loaded = load_drawing(save(s, tmp_path), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1
    assert "3 (ignored layer)" in loaded.summary and "1 (hidden layer)" in loaded.summary
    assert max(flattened) < 100, flattened  # the outline and the notch, never the circles


@pytest.mark.parametrize("add,words", [
    (lambda s: s.msp.add_lwpolyline([s.at(5.0, 2.0), s.at(5.0, 2.0), s.at(5.0, 4.5), s.at(5.0, 4.5)], close=True,
                                    dxfattribs={"layer": "NOTCHES"}), r"LWPOLYLINE #\w+ on layer NOTCHES: NOAREA"),
    # (two LINEs drawn over each other are one path drawn twice: named so, since the bad-input search of issue 19)
    (lambda s: (s.msp.add_line(s.at(5.0, 2.0), s.at(5.0, 4.5), dxfattribs={"layer": "HOLES"}),
                s.msp.add_line(s.at(5.0, 4.5), s.at(5.0, 2.0), dxfattribs={"layer": "HOLES"})),
     r"LINE #\w+ on layer HOLES and LINE #\w+ on layer HOLES: the same path drawn twice \(pasted twice\?\); fix: "
     r"delete one of the two"),
    (lambda s: s.msp.add_open_spline([s.at(5.0, 2.0), s.at(5.0, 4.5), s.at(5.0, 2.0)], degree=1,
                           dxfattribs={"layer": "NOTCHES"}), r"SPLINE #\w+ on layer NOTCHES: NOAREA"),
], ids=["rectangle-0-wide", "two-lines-over-each-other", "degree-1-spline-out-and-back"])
def test_a_closed_outline_with_a_length_but_no_area_is_refused(tmp_path, add, words):
    """A rectangle 0 mm wide and 2.5 mm long on NOTCHES was set aside as 'zero length' (exit 0) though docs/dxf.md
    refuses an outline with no area (a flat ELLIPSE was refused); two LINEs drawn over each other were a shapely
    ValueError traceback. A closed path of one point (a zero-radius CIRCLE) stays set aside as of zero length."""
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    add(s)
    with pytest.raises(PatternError, match=words.replace("NOAREA", "the closed outline encloses no area; fix: delete "
                                                           "it or redraw it")):
        load_drawing(save(s, tmp_path), [], DrawingOptions())
    s = Sheet()
    draw_outline(s)
    draw_polygon(s, [(3.0, 1.0), (3.5, 1.0), (3.5, 2.0), (3.0, 2.0)], "NOTCHES")
    s.msp.add_circle(s.at(5.0, 3.0), 0.0, dxfattribs={"layer": "NOTCHES"})
    s.msp.add_line(s.at(5.0, 2.0), s.at(6.0, 4.5), dxfattribs={"layer": "CONSTRUCTION"})  # drawn over each other on
    s.msp.add_line(s.at(6.0, 4.5), s.at(5.0, 2.0), dxfattribs={"layer": "CONSTRUCTION"})  # an ignored layer: aside
    loaded = load_drawing(save(s, tmp_path, "aside.dxf"), [], DrawingOptions())
    assert len(loaded.pattern.cuts) == 1 and "1 (zero length)" in loaded.summary
