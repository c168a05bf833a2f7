#!/usr/bin/env python3
"""Which junction arms the CARLA maps offer the prelude's `tadArms` (a report, not a table).

Run with the Scenic venv's python:

    .venv-scenic/bin/python compiler/backends/scenic/tools/junction_arms.py MAP_DIR [TOWN ...]

MAP_DIR holds the towns' .xodr files and must be writable (Scenic caches the parsed map
there). For every lane of an ordinary road that ends at a junction (a place `tadAnchors` can
put the ego with an `approach`), the arms of that junction are classified by the very code of
the generated programs (`src/prelude/placement.py`). Prints, per town and junction kind, each
set of arms with how many such ego lanes (and junctions) have it, and over them, for each
arm, the largest number of incoming/outgoing lanes and the shortest-longest reach before its
stop line (incoming lane 1) and after its exit (outgoing lane -1), in metres, as
`tadAnchors(armReach=...)` measures it.
"""
import collections
import os
import sys
import warnings

warnings.simplefilter("ignore")
from scenic.core.vectors import Vector  # noqa: E402
from scenic.domains.driving.roads import Network  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
TOWNS = ["Town10HD", "Town04", "Town07", "Town06", "Town01", "Town02"]

namespace = {"Vector": Vector}
with open(os.path.join(HERE, "..", "src", "prelude", "placement.py"), encoding="utf-8") as f:
    exec(f.read(), namespace)
tadArms, tadReach = namespace["tadArms"], namespace["tadReach"]


def main():
    map_dir = sys.argv[1]
    for town in sys.argv[2:] or TOWNS:
        network = Network.fromFile(os.path.join(map_dir, town + ".xodr"))
        rows = collections.defaultdict(lambda: {"lanes": 0, "junctions": set(), "arms": {}})
        for crossing in network.intersections:
            kind = "4way" if crossing.is4Way else "3way" if crossing.is3Way else f"{len(crossing.roads)}-road"
            for lane in crossing.incomingLanes:
                if lane.road not in network.roads:
                    continue
                arms = tadArms(lane)
                names = tuple(a for a in ("left", "right", "opposite") if a in arms)
                row = rows[(kind, names)]
                row["lanes"] += 1
                row["junctions"].add(crossing.uid)
                for name in ("ego",) + names:
                    ins, outs = arms.get(name, ([], []))
                    best = row["arms"].setdefault(name, [0, 0, [], []])
                    best[0] = max(best[0], len(ins))
                    best[1] = max(best[1], len(outs))
                    best[2].append(tadReach(ins[0]) if ins else 0.0)
                    best[3].append(tadReach(outs[0], onward=True) if outs else 0.0)
        print(f"{town}:")
        for (kind, names), row in sorted(rows.items()):
            arms = "; ".join(
                f"{name} {v[0]} in/{v[1]} out, reach {min(v[2]):.0f}-{max(v[2]):.0f} in, "
                f"{min(v[3]):.0f}-{max(v[3]):.0f} out" for name, v in row["arms"].items())
            print(f"  {kind} {'+'.join(names) or 'no arms'}: {row['lanes']} ego lanes at "
                  f"{len(row['junctions'])} junctions; {arms}")


if __name__ == "__main__":
    main()
