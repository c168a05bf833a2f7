#!/usr/bin/env python3
"""Check the prelude of the generated Scenic programs against the real Scenic (3.1.1).

Run with the Scenic venv's python, from anywhere:

    .venv-scenic/bin/python compiler/backends/scenic/tools/prelude_check.py \\
        [--map-dir DIR] [--seeds 5] [--steps 60] [--emit DIR] [FILE.scenic ...]

The programs are `tests/scenic/prelude/*.scenic` unless files are given. Each is a small
hand-written Scenic program for Scenic's Newtonian simulator (2D) whose line `#@prelude` is
replaced by the prelude every generated program carries (`src/prelude/placement.py`,
`behaviors.scenic`, `params.scenic`), and whose `param map = localPath('TOWN.xodr')` names a
CARLA town looked up in --map-dir (default $SCENIC_MAP_DIR, else shared/maps/CARLA beside the
repository). Each program is sampled with seeds 0..N-1 and simulated for --steps steps
(0.1 s each; a line `# steps: N` in the program overrides it); then the facts its objects
ask for with properties are checked:

  tadCheckHeading H   at the start, the object's heading relative to the ego's lane at its
                      end (its stop line; over the last 4 m, as the prelude's `tadArms`) is H
                      degrees (within 20): -90 for a car on the left arm, 90 right, 180
                      opposite. (Relative to the ego's own heading, reported too, it differs
                      where the ego's lane bends before the junction.)
  tadCheckSide S      at the start, the object is on the ego's 'left' or 'right' (more than
                      1 m beside its heading line), or 'ahead' of it (more than 5 m)
  tadCheckCross LANE  while simulated, the object crosses the centre line of LANE (a Scenic
                      `Lane`, e.g. `tadArm(tadAnchor, 'ego')`): its signed distance to it
                      changes sign
  tadCheckBehind OBJ  while simulated, the object never overlaps OBJ (its leader): their
                      footprints never intersect; the smallest gap is reported
  tadCheckMoves M     while simulated, the object travels at least M metres
  tadCheckTurn D      while simulated, over its first 35 m of travel (or all of it, if less),
                      the object's heading changes by D degrees (within 30; positive = to
                      the left): 0 straight on, 90 a left turn, -90 right
  tadName N           the object's name in the report (else its class and number)

Prints one JSON line per program and seed with the measured numbers, and a summary; exits 1
if any program fails to compile, sample or simulate, or any fact does not hold. --emit DIR
also writes the assembled programs there (for `scenic_check.py` or the Scenic CLI).
"""
import argparse
import json
import math
import os
import random
import re
import sys
import tempfile
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", "..", ".."))
PRELUDE = os.path.join(HERE, "..", "src", "prelude")
PROGRAMS = os.path.join(REPO, "tests", "scenic", "prelude")
STEPS_LINE = re.compile(r"^# steps: ([0-9]+)\s*$", re.M)
MAP_LINE = re.compile(r"^param map = localPath\('([A-Za-z0-9_]+)\.xodr'\)\s*$", re.M)
RECORD = "\nrecord [(o.position.x, o.position.y, o.heading) for o in simulation().objects] as tadStates\n"


def prelude():
    """The prelude as the printer embeds it (placement, behaviors, parameters)."""
    parts = []
    for name in ("placement.py", "behaviors.scenic", "params.scenic"):
        with open(os.path.join(PRELUDE, name), encoding="utf-8") as f:
            parts.append(f.read().rstrip())
    return "\n\n".join(parts) + "\n"


def assemble(path):
    """The program with the prelude in place, the town it names, and its steps (or None)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    town = MAP_LINE.search(text)
    if town is None:
        raise SystemExit(f"{path}: no `param map = localPath('TOWN.xodr')` line")
    if "#@prelude\n" not in text:
        raise SystemExit(f"{path}: no `#@prelude` line")
    steps = STEPS_LINE.search(text)
    return text.replace("#@prelude\n", prelude(), 1) + RECORD, town.group(1), steps and int(steps.group(1))


def map_path(town, map_dir, cache_dir):
    """The town's .xodr, linked into cache_dir so that Scenic caches the parsed map there."""
    xodr = os.path.join(map_dir, town + ".xodr")
    if not os.path.isfile(xodr):
        raise SystemExit(f"map {xodr} not found")
    os.makedirs(cache_dir, exist_ok=True)
    link = os.path.join(cache_dir, town + ".xodr")
    if not os.path.lexists(link):
        os.symlink(os.path.abspath(xodr), link)
    return link if os.path.realpath(link) == os.path.realpath(xodr) else xodr


def relative(angle):
    """Radians as degrees in [-180, 180)."""
    return (math.degrees(angle) + 180.0) % 360.0 - 180.0


def footprint(x, y, heading, obj):
    from shapely.geometry import Polygon

    forward = (-math.sin(heading), math.cos(heading))
    right = (math.cos(heading), math.sin(heading))
    hl, hw = obj.length / 2, obj.width / 2
    corners = [(sl * hl, sw * hw) for sl, sw in ((1, 1), (1, -1), (-1, -1), (-1, 1))]
    return Polygon([(x + a * forward[0] + b * right[0], y + a * forward[1] + b * right[1]) for a, b in corners])


def check_scene(scene, states):
    """The facts the objects ask for, as (name, ok, measured) triples."""
    objects = list(scene.objects)
    ego = scene.egoObject
    start = states[0]
    ex, ey, eh = start[objects.index(ego)]
    forward = (-math.sin(eh), math.cos(eh))
    right = (math.cos(eh), math.sin(eh))
    from scenic.core.vectors import Vector

    lane = scene.workspace.network.laneAt(Vector(ex, ey))
    line = lane.centerline
    span = min(4.0, line.length)
    stop = line.pointAlongBy(line.length - span).angleTo(line.pointAlongBy(line.length))
    facts = []
    for i, obj in enumerate(objects):
        props = obj._dynamicProperties if hasattr(obj, "_dynamicProperties") else {}
        name = getattr(obj, "tadName", None) or f"{type(obj).__name__}#{i}"
        x, y, h = start[i]
        dx, dy = x - ex, y - ey
        ahead, aside = dx * forward[0] + dy * forward[1], dx * right[0] + dy * right[1]
        want = getattr(obj, "tadCheckHeading", None)
        if want is not None:
            turn = relative(h - stop)
            miss = abs((turn - want + 180.0) % 360.0 - 180.0)
            facts.append((f"{name} heading {want:+.0f}", miss <= 20.0, [round(turn, 1), round(relative(h - eh), 1)]))
        side = getattr(obj, "tadCheckSide", None)
        if side is not None:
            ok = {"left": aside < -1.0, "right": aside > 1.0, "ahead": ahead > 5.0}[side]
            facts.append((f"{name} {side}", ok, [round(ahead, 1), round(aside, 1)]))
        lane = getattr(obj, "tadCheckCross", None)
        if lane is not None:
            sides = [lane.centerline.signedDistanceTo(Vector(s[i][0], s[i][1])) for s in states]
            crossed = min(sides) < 0 < max(sides)
            facts.append((f"{name} crosses {lane.uid}", crossed, [round(sides[0], 2), round(sides[-1], 2)]))
        leader = getattr(obj, "tadCheckBehind", None)
        if leader is not None:
            j = objects.index(leader)
            gaps = [
                footprint(*s[i], obj).distance(footprint(*s[j], leader))
                if not footprint(*s[i], obj).intersects(footprint(*s[j], leader)) else -1.0
                for s in states
            ]
            facts.append((f"{name} behind {getattr(leader, 'tadName', None) or j}", min(gaps) > 0.0, [round(gaps[0], 2), round(min(gaps), 2), round(gaps[-1], 2)]))
        moves = getattr(obj, "tadCheckMoves", None)
        if moves is not None:
            travelled = sum(math.hypot(b[i][0] - a[i][0], b[i][1] - a[i][1]) for a, b in zip(states, states[1:]))
            facts.append((f"{name} moves {moves}", travelled >= moves, round(travelled, 1)))
        turn = getattr(obj, "tadCheckTurn", None)
        if turn is not None:
            travelled, last = 0.0, states[-1]
            for a, b in zip(states, states[1:]):
                travelled += math.hypot(b[i][0] - a[i][0], b[i][1] - a[i][1])
                if travelled >= 35.0:
                    last = b
                    break
            change = relative(last[i][2] - states[0][i][2])
            facts.append((f"{name} turns {turn:+.0f}", abs((change - turn + 180.0) % 360.0 - 180.0) <= 30.0,
                          round(change, 1)))
    return facts


def run(path, args, cache_dir, emit_dir):
    import scenic

    text, town, steps = assemble(path)
    program = os.path.join(emit_dir, os.path.basename(path))
    with open(program, "w", encoding="utf-8") as f:
        f.write(text)
    params = {"map": map_path(town, args.map_dir, cache_dir), "render": False}
    results = []
    scenario = scenic.scenarioFromFile(program, params=params, mode2D=True)
    for seed in range(args.seeds):
        record = {"file": os.path.basename(path), "seed": seed, "ok": False}
        random.seed(seed)
        import numpy

        numpy.random.seed(seed)
        try:
            scene, iterations = scenario.generate(maxIterations=args.max_iters, verbosity=0)
            record["iterations"] = iterations
            simulator = scenario.getSimulator()
            simulation = simulator.simulate(scene, maxSteps=steps or args.steps, maxIterations=1, verbosity=0)
            if simulation is None:
                record["error"] = "simulation rejected"
            else:
                states = [value for _, value in simulation.result.records["tadStates"]]
                facts = check_scene(scene, states)
                record["steps"] = len(states) - 1
                record["facts"] = {n: m for n, ok, m in facts}
                record["failed"] = [n for n, ok, m in facts if not ok]
                record["ok"] = not record["failed"]
        except Exception as exc:  # report everything Scenic raises
            record["error"] = f"{type(exc).__name__}: {exc}"
        results.append(record)
        print(json.dumps(record), flush=True)
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="*")
    ap.add_argument("--map-dir", default=os.environ.get("SCENIC_MAP_DIR")
                    or os.path.join(REPO, "..", "shared", "maps", "CARLA"))
    ap.add_argument("--map-cache", default=os.environ.get("SCENIC_MAP_CACHE")
                    or os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "scenic-maps"))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--max-iters", type=int, default=2000)
    ap.add_argument("--emit", default=None, help="also keep the assembled programs in this folder")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    import scenic

    scenic.setDebuggingOptions(verbosity=0, fullBacktrace=False)
    files = args.files or sorted(
        os.path.join(PROGRAMS, f) for f in os.listdir(PROGRAMS) if f.endswith(".scenic"))
    emit_dir = args.emit or tempfile.mkdtemp(prefix="tad-prelude-")
    os.makedirs(emit_dir, exist_ok=True)
    results = []
    for path in files:
        try:
            results += run(path, args, args.map_cache, emit_dir)
        except Exception as exc:
            record = {"file": os.path.basename(path), "ok": False, "error": f"{type(exc).__name__}: {exc}"}
            print(json.dumps(record), flush=True)
            results.append(record)
    bad = [r for r in results if not r["ok"]]
    print(f"prelude_check: {len(results) - len(bad)}/{len(results)} runs passed", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
