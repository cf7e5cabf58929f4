"""LinuxCNC's own interpreter on every program the tests left.

For each directory under the given root holding program.ngc and
program.json (tests/common `leave_for_rs274`, and the mutation test's
sample of edited programs the reader read): `rs274 -g` reads the
program; it must say nothing but "executing", its canonical output must
end the program, and every spindle-synchronised move
(START_SPEED_FEED_SYNC then STRAIGHT_FEED) must have the lead and the
place (X as a radius where the program is on diameter, G7) of the axis
program's thread blocks, in order, within the program's 0.001 mm; and
every move, rapid or cut, must be the axis program's block in order (a
threading cycle's moves, G76, as LinuxCNC makes them), with the dwells
(G4) before it the block's `dwell_s`. Each axis is
found in the canonical call by its name (X Y Z A B C, the order rs274
writes them). An axis standalone rs274 does not have (the mandrel
grinder's steady rest U: its axis mask is X Y Z A B C, whatever the INI
says) is read as a rotary letter the program leaves free, its words
renamed in the program's code (never in comments): rs274 passes a
rotary axis's values through unchanged, so the places compare alike.
"""
import json
import re
import pathlib
import subprocess
import sys
import tempfile


def args(line):
    inner = line[line.index("(") + 1 : line.rindex(")")]
    return [float(v) for v in inner.split(",")]


CANON = "XYZABC"


def stand_ins(program):
    """Each axis rs274 lacks, and the free rotary letter read in its place."""
    names = [a["name"] for a in program["axes"]]
    free = [c for c in "ABC" if c not in names]
    lacking = [n for n in names if n not in CANON]
    if len(lacking) > len(free):
        raise SystemExit(f"rs274 check: axes {lacking} and too few free letters {free}")
    return dict(zip(lacking, free))


def renamed(text, instead):
    """The program's text with each lacking axis's words renamed, in code only."""
    if not instead:
        return text
    out = []
    for line in text.split("\n"):
        parts = re.split(r"(\([^)]*\))", line)
        for i in range(0, len(parts), 2):
            for old, new in instead.items():
                parts[i] = re.sub(rf"(?i)(?<![A-Z]){old}(?=\s*[-+.0-9])", new, parts[i])
        out.append("".join(parts))
    return "\n".join(out)


def places(program):
    """(name, index in the canonical call, scale to it) of each axis."""
    setup = program.get("setup", {})
    diameter = setup.get("radial") == "diameter"
    instead = stand_ins(program)
    out = []
    for a in program["axes"]:
        name = a["name"]
        scale = 0.5 if diameter and name == setup.get("radial_axis", "X") else 1.0
        out.append((name, CANON.index(instead.get(name, name)), scale))
    return out


def check(d):
    program = json.loads((d / "program.json").read_text())
    axes = places(program)
    ix = {name: (i, k, scale) for i, (name, k, scale) in enumerate(axes)}
    threads = [b for b in program["blocks"] if b["motion"]["type"] == "thread"]
    with tempfile.TemporaryDirectory() as tmp:
        canon_path = pathlib.Path(tmp) / "canon.txt"
        ngc = pathlib.Path(tmp) / "program.ngc"
        ngc.write_text(renamed((d / "program.ngc").read_text(), stand_ins(program)))
        run = subprocess.run(
            ["rs274", "-g", str(ngc), str(canon_path)],
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=120,
        )
        said = [l for l in (run.stdout + run.stderr).splitlines() if l.strip() not in ("", "executing")]
        if said:
            return f"rs274 said: {said[:5]}"
        canon = canon_path.read_text().splitlines()
    if not any("PROGRAM_END()" in l for l in canon):
        return "no PROGRAM_END in the canonical output"
    synced = 0
    for k, line in enumerate(canon):
        if "START_SPEED_FEED_SYNC(" not in line:
            continue
        if synced >= len(threads):
            return f"more synchronised moves than thread blocks ({len(threads)})"
        move = canon[k + 1]
        if "STRAIGHT_FEED(" not in move:
            return f"synchronised move is not a straight feed: {move}"
        lead = args(line)[0]
        got = args(move)
        x, z = got[0], got[2]
        b = threads[synced]
        want_lead = b["motion"]["lead"]
        want_x = b["values"][ix["X"][0]] * ix["X"][2]
        want_z = b["values"][ix["Z"][0]]
        if abs(lead - want_lead) > 1e-4 or abs(x - want_x) > 1e-3 or abs(z - want_z) > 1e-3:
            return (
                f"synchronised move {synced + 1}: lead {lead}, x {x}, z {z}; "
                f"the axis program says lead {want_lead}, x {want_x}, z {want_z}"
            )
        synced += 1
    if synced != len(threads):
        return f"{synced} synchronised moves for {len(threads)} thread blocks"
    # Every move, rapid or cut, in order: a threading cycle's (G76) as the
    # axis program's blocks hold the moves it makes. An axis a block keeps
    # (not yet written) stands where it is.
    moves = [l for l in canon if "STRAIGHT_TRAVERSE(" in l or "STRAIGHT_FEED(" in l]
    blocks = program["blocks"]
    # Every dwell (G4, DWELL(seconds)): its seconds stand before the next
    # move, as the axis program's block's dwell_s.
    dwelt, n = 0.0, 0
    for line in canon:
        if "DWELL(" in line:
            dwelt += args(line)[0]
        elif "STRAIGHT_TRAVERSE(" in line or "STRAIGHT_FEED(" in line:
            if n < len(blocks) and abs(dwelt - blocks[n].get("dwell_s", 0.0)) > 1e-6:
                return f"move {n + 1}: a dwell of {dwelt} s before it, the axis program's block {n + 1} says {blocks[n].get('dwell_s', 0.0)}"
            dwelt, n = 0.0, n + 1
    if dwelt > 0.0:
        return f"a dwell of {dwelt} s after the last move"
    if len(moves) != len(blocks):
        return f"{len(moves)} moves read, the axis program has {len(blocks)} blocks"
    for n, (line, b) in enumerate(zip(moves, blocks)):
        rapid = "STRAIGHT_TRAVERSE(" in line
        if rapid != (b["motion"]["type"] == "rapid"):
            return f"move {n + 1} is {'a rapid' if rapid else 'a feed'}, the axis program's block {n + 1} a {b['motion']['type']}"
        got_all = args(line)
        keep = b.get("keep", [])
        for name, (i, k, scale) in ix.items():
            got, want = got_all[k], b["values"][i] * scale
            if name not in keep and abs(got - want) > 1e-3:
                return f"move {n + 1}: {name} {got}, the axis program's block {n + 1} says {want}"
    return None


def main():
    root = pathlib.Path(sys.argv[1])
    dirs = sorted(p.parent for p in root.glob("*/program.ngc"))
    if not dirs:
        print(f"rs274: no programs under {root}")
        return 1
    failed = 0
    for d in dirs:
        problem = check(d)
        if problem:
            failed += 1
            print(f"FAIL  rs274 {d.name}: {problem}")
        else:
            print(f"ok    rs274 {d.name}: every move, rapid or cut, and every synchronised one as the axis program says")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
