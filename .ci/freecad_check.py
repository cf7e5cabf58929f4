# Imports every STL under $PILGRIM_STL_DIR (default target/mesh-check) into
# FreeCAD's Mesh workbench and checks that it is a solid: closed, oriented,
# no non-manifold edges or points. Run: freecadcmd .ci/freecad_check.py
# Prints "N passed, M failed" and exits non-zero on any failure.
import glob
import os
import sys

import Mesh

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
print("freecad: %d passed, %d failed" % (len(files) - failed if files else 0, failed))
sys.stdout.flush()
os._exit(1 if failed else 0)
