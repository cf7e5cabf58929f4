"""Writes drawing_plug.dxf with ezdxf (an independent tool: pilgrim only
reads it): a floating drawing plug's full outline in inches ($INSUNITS 1)
on layer PROFILE, its axis on layer AXIS.

Along the drawing's X (the plug's axis): the stem the steady rest rides
(0.94 in across, from X = -12) and a 45 degree shoulder up to X = 0; the
back cylinder (1.4 in across) and its convex corner (R 0.12, a bulge of
an LWPOLYLINE) onto the 11 degree cone, the concave fillet onto the land
(an ARC, R 0.25), the land (a LINE, 1.2 in across), the front nose (a
cubic SPLINE) to the front face. The lower half mirrors the upper.

Run: python3 scripts/examples/drawing_plug_dxf.py scripts/examples/drawing_plug.dxf
"""

import math
import sys

import ezdxf


def outline(sign):
    """The pieces of one half (sign +1 upper, -1 lower) as ezdxf calls."""
    a = math.radians(11.0)
    rb, rl = 0.7, 0.6
    zc, r_corner, r_fillet = 1.0, 0.12, 0.25
    tc = r_corner * math.tan(a / 2.0)
    zf = zc + (rb - rl) / math.tan(a)
    tf = r_fillet * math.tan(a / 2.0)
    ze = zf + tf + 0.8
    # The LWPOLYLINE: the back cylinder, the corner as a bulge (clockwise
    # seen from +Z on the upper half: negative), the cone to the fillet.
    bulge = -math.tan(a / 4.0) * sign
    cone_end = (zf - tf * math.cos(a), rl + tf * math.sin(a))
    poly = [
        (0.0, rb * sign, 0.0),
        (zc - tc, rb * sign, bulge),
        (zc + tc * math.cos(a), (rb - tc * math.sin(a)) * sign, 0.0),
        (cone_end[0], cone_end[1] * sign, 0.0),
    ]
    # The fillet's centre above the land (upper half), its arc from the
    # cone's tangent point to the land's, counter-clockwise.
    centre = (zf + tf, (rl + r_fillet) * sign)
    if sign > 0:
        angles = (270.0 - 11.0, 270.0)
    else:
        angles = (90.0, 90.0 + 11.0)
    land = ((zf + tf, rl * sign), (ze, rl * sign))
    nose = [(ze, rl), (ze + 0.08, rl), (ze + 0.16, rl - 0.04), (ze + 0.22, rl - 0.12)]
    nose = [(z, r * sign) for z, r in nose]
    return poly, (centre, r_fillet, angles), land, nose


def main(path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 1  # inches
    doc.layers.add("PROFILE")
    doc.layers.add("AXIS")
    msp = doc.modelspace()
    ends = []
    for sign in (1, -1):
        poly, (centre, r, angles), land, nose = outline(sign)
        msp.add_lwpolyline(poly, format="xyb", dxfattribs={"layer": "PROFILE"})
        msp.add_arc(centre, r, angles[0], angles[1], dxfattribs={"layer": "PROFILE"})
        msp.add_line(land[0], land[1], dxfattribs={"layer": "PROFILE"})
        msp.add_open_spline(nose, degree=3, dxfattribs={"layer": "PROFILE"})
        ends.append((poly[0][:2], nose[-1]))
        # The stem and its shoulder (LINEs).
        msp.add_line((-12.0, 0.47 * sign), (-0.23, 0.47 * sign), dxfattribs={"layer": "PROFILE"})
        msp.add_line((-0.23, 0.47 * sign), (0.0, 0.7 * sign), dxfattribs={"layer": "PROFILE"})
        ends[-1] = ((-12.0, 0.47 * sign), ends[-1][1])
    # The faces, across the axis.
    msp.add_line(ends[1][0], ends[0][0], dxfattribs={"layer": "PROFILE"})
    msp.add_line(ends[0][1], ends[1][1], dxfattribs={"layer": "PROFILE"})
    msp.add_line((-12.2, 0.0), (ends[0][1][0] + 0.2, 0.0), dxfattribs={"layer": "AXIS"})
    doc.saveas(path)


if __name__ == "__main__":
    main(sys.argv[1])
