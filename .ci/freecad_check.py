# Imports every STL under $PILGRIM_STL_DIR (default target/mesh-check) into
# FreeCAD's Mesh workbench and checks that it is a solid: closed, oriented,
# no non-manifold edges or points; then every STEP file as an exact solid
# (below). Run: freecadcmd .ci/freecad_check.py
# Prints "N passed, M failed" and exits non-zero on any failure.
import glob
import json
import os
import sys

import Mesh
import Part

root = os.environ.get("PILGRIM_STL_DIR", "target/mesh-check")
files = sorted(glob.glob(os.path.join(root, "**", "*.stl"), recursive=True))
failed = 0
for f in files:
    m = Mesh.Mesh(f)
    checks = {
        "solid": m.isSolid(),
        "facets": m.CountFacets > 0,
        "manifold": not m.hasNonManifolds(),
        "oriented": not m.hasNonUniformOrientedFacets(),
        "no self-intersections": not m.hasSelfIntersections(),
    }
    bad = [k for k, v in checks.items() if not v]
    print("%s %s: %d facets, volume %.3f mm^3%s" % (
        "FAIL" if bad else "ok  ", f, m.CountFacets, m.Volume, (" (" + ", ".join(bad) + ")") if bad else ""))
    failed += 1 if bad else 0
if not files:
    print("freecad: no STL files found under " + root)
    failed = 1

# Every STEP file: read by OpenCASCADE (Part.read), a valid shape of exactly
# one closed solid, its volume the one the test that left it found
# independently (<name>.step.json: volume_mm3 within allowed_mm3).
steps = sorted(glob.glob(os.path.join(root, "**", "*.step"), recursive=True))
step_failed = 0
for f in steps:
    bad = []
    try:
        expected = json.load(open(f + ".json"))
    except OSError:
        expected = None
        bad.append("no expected volume beside it")
    shape = Part.read(f)
    if not shape.isValid():
        bad.append("not valid")
    if len(shape.Solids) != 1:
        bad.append("%d solids" % len(shape.Solids))
    elif not all(s.isClosed() for s in shape.Solids[0].Shells):
        bad.append("a shell is open")
    volume = shape.Volume
    if expected and abs(volume - expected["volume_mm3"]) > expected["allowed_mm3"]:
        bad.append("volume %.3f, expected %.3f +- %.3f" % (
            volume, expected["volume_mm3"], expected["allowed_mm3"]))
    # Where the run's STL of the same body lies, the solid lies: their
    # bounding boxes agree within the mesh's chords (0.05 mm).
    stl = f[:-len(".step")] + ".stl"
    if os.path.exists(stl):
        box = shape.optimalBoundingBox()
        mesh_box = Mesh.Mesh(stl).BoundBox
        worst = max(abs(a - b) for a, b in zip(
            (box.XMin, box.YMin, box.ZMin, box.XMax, box.YMax, box.ZMax),
            (mesh_box.XMin, mesh_box.YMin, mesh_box.ZMin,
             mesh_box.XMax, mesh_box.YMax, mesh_box.ZMax)))
        if worst > 0.05:
            bad.append("%.3f mm away from %s" % (worst, os.path.basename(stl)))
    print("%s %s: %d faces, volume %.3f mm^3%s" % (
        "FAIL" if bad else "ok  ", f, len(shape.Faces), volume,
        (" (" + ", ".join(bad) + ")") if bad else ""))
    step_failed += 1 if bad else 0
if not steps:
    print("freecad: no STEP files found under " + root)
    step_failed = 1
failed += step_failed
print("freecad: %d passed, %d failed" % (len(files) + len(steps) - failed, failed))
sys.stdout.flush()
os._exit(1 if failed else 0)
