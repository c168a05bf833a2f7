#!/usr/bin/env python3
"""Trace .scenic programs in Scenic's Newtonian simulator: every object's pose at every step.

The measurement side of the fidelity suite. For each FILE it compiles the program once
(Scenic 3.1.1, 2D compatibility mode, the Newtonian driving model, headless), then for
each seed samples a scene and simulates it, recording every object's state at every step.
Prints one JSON line per (file, seed):

  {"file", "seed", "ok", "error", "dt", "steps", "termination", "iterations",
   "compile_s", "sample_s", "sim_s",   (steps: the states recorded after step 0;
                                        iterations: Scenic's rejection-sampling tries)
   "objects": [{"index", "name", "group", "group_index", "class", "length", "width",
                "is_ego"}, ...],
   "states": [[[x, y, heading, speed], ... one per object], ... one per step]}

  objects   the scene's objects in `scene.objects` order (creation order: in TADSL's
            programs the ego first, then each actor group's objects in source order).
            `index` is the position in that list; `name`, `group` and `group_index` are
            the object's `tadName`, `tadGroup` and `tadIndex` properties, or null when the
            program gives none. `class` is the Scenic class (Car, Pedestrian, ...);
            `length` and `width` (metres) size its footprint.
  states    states[0] is the sampled scene before any step (after the simulator created
            the objects), states[k] the state after k steps, so a full run has steps + 1
            entries; `dt` is the length of a step in seconds (0.1 s, the Newtonian
            simulator's default). One [x, y, heading, speed] per object, in `objects` order.
            Objects created during a simulation (none in TADSL's programs) are left out.

Conventions (Scenic's own, not CARLA's): x and y in metres in the map's frame; `heading` in
radians, counter-clockwise from north (the +y axis), so 0 faces +y and pi/2 faces -x; a
footprint's forward axis is (-sin h, cos h), its left axis (-cos h, -sin h). Headings
are normalised to (-pi, pi]. `speed` is the norm of the velocity in m/s (never negative,
also when reversing).

Failures never stop the run: a file that does not compile gives one record per seed with
`ok: false`; a scene that cannot be sampled gives `ok: false` and no states; a simulation
that is rejected (a requirement fails) or raises gives `ok: false` with the error and the
states recorded up to that point. Each seed gets one scene and one simulation (no
resampling after a rejected simulation), seeded as Scenic's own CLI does
(`random.seed` and `numpy.random.seed`, here right before each sample, so a record does
not depend on the other seeds asked for).

Usage, with a Python that has scenic 3.1.1:

  .venv-scenic/bin/python scenic_trace.py [--seeds 0,1,2] [--steps 60] [--map-dir DIR]
      [--map-cache DIR] [--max-iters N] [--model MODEL] FILE.scenic ...

  --seeds       comma-separated seeds, or a range A..B (B excluded); default 0
  --steps       steps to simulate per seed (default 60, i.e. 6 s)
  --map-dir     look the program's map (`param map = '.../TownNN.xodr'`) up by its file
                name in DIR instead of the path the program names
  --map-cache   link the map into DIR and give Scenic that link, so the parsed map
                (TownNN.snet) is cached in DIR and reused; "none" (the default) leaves
                the map where it is (Scenic then caches next to it)
  --max-iters   rejection-sampling iterations per scene (default 2000)
  --model       the world model (default scenic.simulators.newtonian.driving_model)

Exit status: 0 when every record is ok, 1 otherwise, 2 on usage errors (including "scenic
is not importable"). Scenic's own output goes to standard error; standard output has only
the JSON lines.
"""
import argparse
import contextlib
import json
import math
import os
import random
import re
import sys
import time
import warnings

NEWTONIAN_DRIVING = "scenic.simulators.newtonian.driving_model"
MAP_PARAM = re.compile(r"""^param\s+map\s*=\s*(['"])(.*?)\1\s*$""", re.MULTILINE)


def parse_seeds(text):
    text = text.strip()
    if ".." in text:
        start, end = text.split("..", 1)
        return list(range(int(start), int(end)))
    return [int(s) for s in text.split(",") if s.strip()]


def program_map(path):
    """The map path a program names in its `param map = '...'` line, if any."""
    try:
        with open(path, encoding="utf-8") as f:
            found = MAP_PARAM.search(f.read())
    except OSError:
        return None
    return found.group(2) if found else None


def cached_map(xodr, cache_dir):
    """A link to `xodr` inside `cache_dir` (Scenic writes its .snet next to the map file
    it is given, keyed by a hash of the map's bytes, so a stale cache is rebuilt)."""
    if not cache_dir or cache_dir.lower() == "none" or not xodr.endswith(".xodr"):
        return xodr
    try:
        os.makedirs(cache_dir, exist_ok=True)
        link = os.path.join(cache_dir, os.path.basename(xodr))
        if os.path.realpath(link) == os.path.realpath(xodr):
            return link
        if os.path.islink(link):
            os.remove(link)
            snet = os.path.splitext(link)[0] + ".snet"
            if os.path.exists(snet):
                os.remove(snet)
        if not os.path.lexists(link):
            os.symlink(os.path.abspath(xodr), link)
        return link if os.path.realpath(link) == os.path.realpath(xodr) else xodr
    except OSError:
        return xodr


def map_override(path, args):
    """The `map` parameter to give Scenic for the program at `path`, or None to keep its own."""
    if not args.map_dir and (not args.map_cache or args.map_cache.lower() == "none"):
        return None
    named = program_map(path)
    if named is None:
        return None
    xodr = named
    if args.map_dir:
        xodr = os.path.join(args.map_dir, os.path.basename(named))
    if not os.path.isfile(xodr):
        return None  # let Scenic report the missing map as the program names it
    return cached_map(os.path.abspath(xodr), args.map_cache)


def error_text(stage, exc):
    text = str(exc) or type(exc).__name__
    return f"[{stage}] {type(exc).__name__}: {text}"


def number(x, digits=6):
    """A finite float for JSON (NaN and infinities become null)."""
    x = float(x)
    return round(x, digits) if math.isfinite(x) else None


def normalised(angle):
    a = math.remainder(float(angle), 2 * math.pi)  # in [-pi, pi]
    return math.pi if a == -math.pi else a


def describe(scene):
    ego = scene.egoObject
    objects = []
    for i, obj in enumerate(scene.objects):
        def prop(name):
            value = getattr(obj, name, None)
            return None if value is None else value

        group_index = prop("tadIndex")
        objects.append({
            "index": i,
            "name": None if prop("tadName") is None else str(prop("tadName")),
            "group": None if prop("tadGroup") is None else str(prop("tadGroup")),
            "group_index": None if group_index is None else int(group_index),
            "class": type(obj).__name__,
            "length": number(obj.length),
            "width": number(obj.width),
            "is_ego": obj is ego,
        })
    return objects


def state(obj):
    position = obj.position
    return [number(position[0]), number(position[1]), number(normalised(obj.heading)),
            number(obj.speed)]


def tracing_simulator(simulator, sink):
    """Make `simulator` (a NewtonianSimulator) create simulations that record poses.

    A Scenic `Simulation` runs to its end inside its constructor and a rejected one is
    dropped by `Simulator.simulate`, so the simulation registers itself in `sink` first and
    keeps the exception that ended it.
    """
    from scenic.simulators.newtonian.simulator import NewtonianSimulation, NewtonianSimulator

    if not isinstance(simulator, NewtonianSimulator):
        raise RuntimeError(f"not a Newtonian simulator: {type(simulator).__name__}")

    class TracingSimulation(NewtonianSimulation):
        def __init__(self, scene, *rest, **kwargs):
            self.traceObjects = list(scene.objects)
            self.traceError = None
            sink.append(self)
            try:
                super().__init__(scene, *rest, **kwargs)
            except BaseException as exc:
                self.traceError = exc
                raise

        def currentState(self):
            return tuple(state(obj) for obj in self.traceObjects)

    def createSimulation(scene, **kwargs):
        return TracingSimulation(
            scene, simulator.network, simulator.render, simulator.export_gif,
            simulator.debug_render, **kwargs
        )

    simulator.createSimulation = createSimulation
    return simulator


def seed_all(seed):
    random.seed(seed)
    try:
        import numpy
        numpy.random.seed(seed)
    except ImportError:
        pass


def trace_file(path, args, seeds):
    """The records of one file, one per seed."""
    import scenic

    def record(seed):
        return {
            "file": path, "seed": seed, "ok": False, "error": None, "dt": None,
            "steps": None, "termination": None, "iterations": None,
            "compile_s": None, "sample_s": None, "sim_s": None,
            "objects": [], "states": [],
        }

    params = {"render": False}
    chosen = map_override(path, args)
    if chosen is not None:
        params["map"] = chosen

    t0 = time.perf_counter()
    try:
        seed_all(seeds[0] if seeds else 0)
        scenario = scenic.scenarioFromFile(path, params=params, model=args.model, mode2D=True)
    except Exception as exc:
        compile_s = round(time.perf_counter() - t0, 4)
        for seed in seeds:
            rec = record(seed)
            rec["error"] = error_text("compile", exc)
            rec["compile_s"] = compile_s
            yield rec
        return
    compile_s = round(time.perf_counter() - t0, 4)

    simulator = None
    sink = []
    for seed in seeds:
        rec = record(seed)
        rec["compile_s"] = compile_s
        stage = "sample"
        t0 = time.perf_counter()
        try:
            seed_all(seed)
            scene, iterations = scenario.generate(maxIterations=args.max_iters, verbosity=0)
            rec["sample_s"] = round(time.perf_counter() - t0, 4)
            rec["iterations"] = iterations
            rec["objects"] = describe(scene)

            stage = "simulate"
            if simulator is None:
                simulator = tracing_simulator(scenario.getSimulator(), sink)
            sink.clear()
            t0 = time.perf_counter()
            try:
                simulation = simulator.simulate(
                    scene, maxSteps=args.steps, maxIterations=1, verbosity=0,
                    enableReplay=False,
                )
            finally:
                rec["sim_s"] = round(time.perf_counter() - t0, 4)
                if sink:
                    ran = sink[-1]
                    rec["dt"] = ran.timestep
                    rec["states"] = [list(s) for s in ran.trajectory]
                    rec["steps"] = max(len(rec["states"]) - 1, 0)
            if simulation is None:
                ran = sink[-1] if sink else None
                why = ran.traceError if ran is not None else None
                at = ran.currentTime if ran is not None else "?"
                rec["error"] = f"[simulate] rejected at step {at}: " + (
                    f"{type(why).__name__}: {why}" if why is not None else "a requirement failed")
            else:
                result = simulation.result
                rec["termination"] = f"{result.terminationType.name}: {result.terminationReason}"
                rec["ok"] = True
        except Exception as exc:  # Scenic raises many types; report them all
            if stage == "sample" and rec["sample_s"] is None:
                rec["sample_s"] = round(time.perf_counter() - t0, 4)
            rec["error"] = error_text(stage, exc)
        yield rec

    if simulator is not None:
        with contextlib.suppress(Exception):
            simulator.destroy()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--map-dir", default=None)
    ap.add_argument("--map-cache", default=None)
    ap.add_argument("--max-iters", type=int, default=2000)
    ap.add_argument("--model", default=NEWTONIAN_DRIVING)
    ap.add_argument("--show-warnings", action="store_true")
    args = ap.parse_args(argv)
    try:
        seeds = parse_seeds(args.seeds)
    except ValueError:
        ap.error(f"--seeds: not a list of integers: {args.seeds!r}")
    if not seeds:
        ap.error("--seeds: no seed")

    if not args.show_warnings:
        warnings.simplefilter("ignore")
    out = sys.stdout
    try:
        with contextlib.redirect_stdout(sys.stderr):
            import scenic
            scenic.setDebuggingOptions(verbosity=0, fullBacktrace=False)
    except ImportError:
        print(f"scenic_trace: `scenic` is not importable from {sys.executable}", file=sys.stderr)
        return 2

    all_ok = True
    for path in args.files:
        records = trace_file(path, args, seeds)
        while True:
            # Scenic and the scenarios print to stdout; keep it for the JSON lines
            with contextlib.redirect_stdout(sys.stderr):
                try:
                    rec = next(records)
                except StopIteration:
                    break
                except Exception as exc:  # a bug here must not stop the other files
                    print(f"scenic_trace: {path}: {error_text('trace', exc)}", file=sys.stderr)
                    all_ok = False
                    break
            all_ok = all_ok and rec["ok"]
            out.write(json.dumps(rec, separators=(",", ":")) + "\n")
            out.flush()
    return 0 if all_ok else 1


if __name__ == "__main__":
    sys.exit(main())
