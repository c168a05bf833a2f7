import math as tadMath
from scenic.core.distributions import distributionFunction as tadLazy
from scenic.core.distributions import RejectionException as TadRejection

def tadLanes(section):
    """The lane sections of the road section holding `section`, in TAD lane order: those of its
    direction from the left (TAD 1, 2, ...) and those of the other direction from the centre
    line outwards (TAD -1, -2, ...)."""
    for part in section.road.sections:
        if any(lane is section for lane in part.lanes):
            same = [lane for lane in part.lanes if lane.isForward == section.isForward]
            other = [lane for lane in part.lanes if lane.isForward != section.isForward]
            order = lambda lane: abs(lane.openDriveID)
            return sorted(same, key=order), sorted(other, key=order)
    return [section], []

def tadRuns(network):
    """Stretches of the lanes of ordinary roads over which the lane layout does not change:
    (lane, start, end, lanes this way, lanes the other way, TAD index, sidewalk)."""
    roads = set(network.roads)
    runs = []
    for lane in network.lanes:
        if lane.road not in roads:
            continue
        start = 0.0
        for section in lane.sections:
            same, other = tadLanes(section)
            index = 1 + next(i for i, s in enumerate(same) if s is section)
            key = (len(same), len(other), index, section.group._sidewalk is not None)
            end = start + section.centerline.length
            if runs and runs[-1][0] is lane and runs[-1][3:] == key:
                runs[-1] = (lane, runs[-1][1], end) + key
            else:
                runs.append((lane, start, end) + key)
            start = end
    return runs

def tadHeading(line, arc):
    """The heading of a polyline at `arc` metres from its start."""
    arc = min(max(arc, 0.5), line.length - 0.5)
    return line.pointAlongBy(arc - 0.5).angleTo(line.pointAlongBy(arc + 0.5))

def tadTurning(line, start, end):
    """How much a polyline turns between two arcs, in degrees."""
    turn = tadHeading(line, end) - tadHeading(line, start)
    return abs(tadMath.degrees((turn + tadMath.pi) % (2 * tadMath.pi) - tadMath.pi))

def tadShapeOk(line, start, end, shape):
    if shape == 'straight':
        return tadTurning(line, start, end) < 10
    if shape == 'curved':
        return tadTurning(line, start, end) > 20
    return True

def tadJunctionOk(lane, junction, signalised, maneuver, signs):
    """Whether `lane` ends at a junction of the kind asked for."""
    if not lane.maneuvers:
        return False
    crossing = lane.maneuvers[0].intersection
    if crossing is None:
        return False
    if junction == '4way' and not crossing.is4Way:
        return False
    if junction == '3way' and not crossing.is3Way:
        return False
    if signalised is not None and crossing.isSignalized != signalised:
        return False
    if maneuver is not None and not any(m.type.name == maneuver for m in lane.maneuvers):
        return False
    kinds = {signal.type for signal in crossing.signals}
    return all(sign in kinds for sign in signs)

def tadAnchors(network, same=None, other=None, minSame=0, minOther=0, index=1, sidewalk=False,
               junction=None, signalised=None, maneuver=None, signs=(), shape=None, ahead=10.0,
               behind=10.0, approach=None, step=4.0):
    """Where the ego vehicle can be: (lane, arc) pairs such that the lane layout is the one asked
    for from `behind` metres behind the ego to `ahead` metres in front of it, and, with an
    `approach`, the lane ends `approach` metres ahead at a junction of the kind asked for."""
    found = []
    for lane, start, end, n, m, i, walk in tadRuns(network):
        if (same is not None and n != same) or (other is not None and m != other):
            continue
        if n < minSame or m < minOther or i != index or (sidewalk and not walk):
            continue
        length = lane.centerline.length
        if approach is not None:
            arc = length - approach
            if end >= length - 0.5 and arc - behind >= start and arc >= 0 and \
                    tadJunctionOk(lane, junction, signalised, maneuver, signs):
                found.append((lane, arc))
            continue
        arc = start + behind
        while arc + ahead <= end:
            if tadShapeOk(lane.centerline, arc - behind, arc + ahead, shape):
                found.append((lane, arc))
            arc += step
    return found

def tadRequire(anchors, wanted):
    if not anchors:
        raise RuntimeError('TADSL: no place on this map has the road the scenario needs ('
                           + ', '.join(f'{k}={v!r}' for k, v in wanted.items() if v is not None)
                           + '); build for another map (--map) or relax the road section')
    return anchors

@tadLazy
def tadSpot(anchor, offset, index, place='centre', width=0.0):
    """Where an actor stands: `offset` metres ahead of the ego along its lane, in TAD lane
    `index`. Returns (position, heading of that lane there). `place` is 'centre', 'curb' (at the
    curb side of the lane) or 'sidewalk' (on the sidewalk beside the lane, else at its curb)."""
    lane, arc = anchor
    arc = arc + offset
    if arc < 0 or arc > lane.centerline.length:
        raise TadRejection('actor beyond the end of the lane')
    point = lane.centerline.pointAlongBy(arc)
    section = lane.sectionAt(point) or min(lane.sections, key=lambda s: s.distanceTo(point))
    same, other = tadLanes(section)
    lanes = same if index > 0 else other
    if abs(index) > len(lanes):
        raise TadRejection('no lane with this index here')
    target = lanes[abs(index) - 1]
    position = target.centerline.project(point)
    start, end = target.centerline.nearestSegmentTo(position)
    heading = start.angleTo(end)
    if place != 'centre' and target is lanes[-1]:
        if place == 'sidewalk' and target.group._sidewalk is not None:
            return (target.group._sidewalk.centerline.project(position), heading)
        half = (target.leftEdge.distanceTo(position) + target.rightEdge.distanceTo(position)) / 2
        shift = half + 0.6 if place == 'sidewalk' else max(half - width / 2 - 0.2, 0.0)
        position = position + Vector(shift, 0).rotatedBy(heading)
    return (position, heading)
