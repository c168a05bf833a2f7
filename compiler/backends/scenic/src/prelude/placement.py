import math as tadMath
from scenic.core.distributions import distributionFunction as tadLazy
from scenic.core.distributions import RejectionException as TadRejection

# A two-wheeler's throttle (TadRide), and how fast a vehicle released from rest picks up
# speed under it (m/s²): half of the Newtonian simulator's 5.6 m/s² at full throttle.
# FollowLaneBehavior's controller starts at full throttle and eases in, about the same.
TAD_RIDE_THROTTLE = 0.5
TAD_LAUNCH = TAD_RIDE_THROTTLE * 5.6
# Two ways meet where they come within half of each one's width plus this (m): the
# layout's `MEET_MARGIN`.
TAD_MEET_MARGIN = 0.3

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

TAD_ARMS = {'left': -90.0, 'right': 90.0, 'opposite': 180.0}

def tadWrap(angle):
    """An angle in degrees brought into [-180, 180)."""
    return (angle + 180.0) % 360.0 - 180.0

def tadEndHeading(lane, atStart=False):
    """The heading (radians) of a lane over its last 4 metres (over its first 4 with
    `atStart`): a chord, so that the curve of a road just before a junction does not count."""
    line = lane.centerline
    span = min(4.0, line.length)
    if atStart:
        return line.pointAlongBy(0).angleTo(line.pointAlongBy(span))
    return line.pointAlongBy(line.length - span).angleTo(line.pointAlongBy(line.length))

def tadArms(lane):
    """The arms of the junction `lane` ends at, by name: 'ego' (the road of `lane`), and
    'left', 'right', 'opposite', classified by the heading of the traffic entering the junction
    from the arm (over its last 4 m) relative to the heading of `lane` at its end: about -90
    degrees (it drives towards the ego's right) is 'left', about +90 'right', about 180
    'opposite' (each within 45 degrees; of two roads in one class, the nearer to the ideal
    angle). An arm whose road only leaves the junction is classified by its outgoing lanes,
    reversed. Each arm is (incoming lanes, outgoing lanes), both ordered from the centre line
    outwards (TAD 1, 2, ... and -1, -2, ...). Empty if `lane` ends at no junction."""
    if not lane.maneuvers or lane.maneuvers[0].intersection is None:
        return {}
    crossing = lane.maneuvers[0].intersection
    base = tadMath.degrees(tadEndHeading(lane))
    found = {}
    for road in crossing.roads:
        ins = [l for l in crossing.incomingLanes if l.road == road]
        outs = [l for l in crossing.outgoingLanes if l.road == road]
        ins.sort(key=lambda l: abs(l.sections[-1].openDriveID))
        outs.sort(key=lambda l: abs(l.sections[0].openDriveID))
        if road == lane.road:
            found['ego'] = (0.0, ins, outs)
            continue
        if ins:
            heading = tadMath.degrees(tadEndHeading(ins[0]))
        elif outs:
            heading = tadMath.degrees(tadEndHeading(outs[0], atStart=True)) + 180.0
        else:
            continue
        turn = tadWrap(heading - base)
        for name, ideal in TAD_ARMS.items():
            miss = abs(tadWrap(turn - ideal))
            if miss < 45.0 and (name not in found or miss < found[name][0]):
                found[name] = (miss, ins, outs)
    return {name: (ins, outs) for name, (miss, ins, outs) in found.items()}

def tadArmLanes(anchor, arm):
    """(incoming, outgoing) lanes of an arm of the junction ahead of the anchor, as in
    `tadArms`; for 'ego' without a junction, the lanes of the ego's road at the end of its
    lane (those of its direction, then none). Raises TadRejection if there is no such arm."""
    if arm not in TAD_ARMS and arm != 'ego':
        raise ValueError(f'TADSL: unknown junction arm {arm!r}')
    lane, arc = anchor
    arms = tadArms(lane)
    if arm == 'ego' and arm not in arms:
        same, other = tadLanes(lane.sections[-1])
        return ([s.lane for s in same], [])
    if arm not in arms:
        raise TadRejection(f'the junction has no {arm} arm')
    return arms[arm]

@tadLazy
def tadArm(anchor, arm):
    """The lane (Scenic `Lane`) entering the junction ahead of the anchor's lane from arm `arm`
    ('left', 'right', 'opposite': see `tadArms`), the one nearest the centre line (TAD lane 1
    of that arm); for 'ego', the anchor's own lane. Raises TadRejection if the junction has no
    such arm (a three-way junction lacks one of them) or the arm has no lane into it."""
    if arm == 'ego':
        return anchor[0]
    ins, outs = tadArmLanes(anchor, arm)
    if not ins:
        raise TadRejection(f'no lane enters the junction from its {arm} arm')
    return ins[0]

def tadOrdinary(lane):
    """Whether `lane` is a lane of an ordinary road (not of a junction's connecting road)."""
    return lane is not None and lane.road in lane.network.roads

def tadBack(lane, before):
    """The point `before` metres before the end of `lane`, walking back over the lanes leading
    into it while they are lanes of ordinary roads: (lane, arc); where they end (at another
    junction) sooner, that end: as far out as the arm goes."""
    arc = lane.centerline.length - before
    seen = {lane.uid}
    while arc < 0:
        prev = lane._predecessor
        if prev is None or not hasattr(prev, 'centerline') or prev.uid in seen or not tadOrdinary(prev) \
                or prev.centerline[-1].distanceTo(lane.centerline[0]) > 1.0:
            return (lane, 0.0)
        seen.add(prev.uid)
        lane = prev
        arc += lane.centerline.length
    return (lane, arc)

def tadOnward(lane, after):
    """The point `after` metres from the start of `lane`, walking on over the lanes it leads
    into while they are lanes of ordinary roads: (lane, arc); where they end sooner, that end."""
    arc = after
    seen = {lane.uid}
    while arc > lane.centerline.length:
        nxt = lane._successor
        if nxt is None or not hasattr(nxt, 'centerline') or nxt.uid in seen or not tadOrdinary(nxt) \
                or nxt.centerline[0].distanceTo(lane.centerline[-1]) > 1.0:
            return (lane, lane.centerline.length)
        seen.add(nxt.uid)
        arc -= lane.centerline.length
        lane = nxt
    return (lane, arc)

def tadReach(lane, onward=False, limit=500.0):
    """How many metres of ordinary road lanes lead into `lane`'s end (with `onward`: lead on
    from its start), up to `limit`: how far `tadBack` (`tadOnward`) can go."""
    total, seen = lane.centerline.length, {lane.uid}
    while total < limit:
        nxt = lane._successor if onward else lane._predecessor
        if nxt is None or not hasattr(nxt, 'centerline') or nxt.uid in seen or not tadOrdinary(nxt):
            break
        gap = nxt.centerline[0].distanceTo(lane.centerline[-1]) if onward \
            else nxt.centerline[-1].distanceTo(lane.centerline[0])
        if gap > 1.0:
            break
        seen.add(nxt.uid)
        lane = nxt
        total += lane.centerline.length
    return min(total, limit)

@tadLazy
def tadArmSpot(anchor, arm, before, index, place='centre', width=0.0):
    """Where an actor on an arm of the junction ahead of the ego stands: (position, heading of
    its lane there). `arm` is 'ego', 'left', 'right' or 'opposite' (see `tadArms`). `index` > 0:
    TAD lane `index` of the lanes driving into the junction on that arm (1 = the one nearest
    the centre line), `before` metres before the arm's stop line (the end of its lane), going
    back over the lanes leading into it on ordinary roads if needed. `index` < 0: lane -`index`
    of the lanes driving away from the junction on that arm (-1 = nearest the centre line),
    `before` metres after the junction exit, heading away. The index counts the lanes where the
    actor stands. `place` and `width` as in `tadSpot` ('curb'/'sidewalk' only move an actor in
    the outermost lane). Raises TadRejection if the junction has no such arm or the lanes are
    too short; ValueError for index 0 or a negative `before`."""
    if index == 0 or before < 0:
        raise ValueError('TADSL: tadArmSpot needs index != 0 and before >= 0')
    ins, outs = tadArmLanes(anchor, arm)
    if index > 0:
        if not ins:
            raise TadRejection(f'no lane enters the junction from its {arm} arm')
        lane, arc = tadBack(ins[0], before)
    else:
        if not outs:
            raise TadRejection(f'no lane leaves the junction on its {arm} arm')
        lane, arc = tadOnward(outs[0], before)
    return tadPlace(lane, arc, abs(index), place, width, clamp=True)

def tadCrossing(lane, arc, beyond, fromRight, extra):
    """The start of a walk across the road of `lane` at `arc` metres along it (and `beyond`
    metres further, straight on past its end): on the sidewalk of that side, 0.5 m in from its
    edge next to the road, else 0.5 m outside the curb; `extra` metres further out; heading
    straight across the road."""
    point = lane.centerline.pointAlongBy(arc)
    heading = tadHeading(lane.centerline, arc)
    right = Vector(1, 0).rotatedBy(heading)
    section = lane.sectionAt(point) or min(lane.sections, key=lambda s: s.distanceTo(point))
    same, other = tadLanes(section)
    side = 1 if fromRight else -1
    outer = same[-1] if fromRight else (other[-1] if other else same[0])
    lateral = lambda q: side * (q - point).dot(right)
    edges = [outer.leftEdge, outer.rightEdge]
    if fromRight or other:
        edges.append(outer.group.curb)
    edge = max(lateral(e.project(point)) for e in edges)
    offset = edge + 0.5
    best = None
    for walk in section.road.sidewalks or ():
        middle = walk.centerline.project(point)
        if abs((middle - point).dot(Vector(0, 1).rotatedBy(heading))) > 2.0 or lateral(middle) < edge:
            continue
        inner = min(lateral(walk.leftEdge.project(point)), lateral(walk.rightEdge.project(point)))
        spot = min(max(inner, edge) + 0.5, lateral(middle))
        if best is None or spot < best:
            best = spot
    if best is not None:
        offset = best
    position = point + Vector(0, beyond).rotatedBy(heading) + right * (side * (offset + extra))
    return (position, heading + side * tadMath.pi / 2)

@tadLazy
def tadCross(anchor, arm, before, fromRight, extra=0.0):
    """Where a pedestrian (or cyclist) who walks across the road of arm `arm` of the junction
    ahead of the ego starts: (position, heading straight across the road). `before` metres
    before that arm's stop line (measured along its lane 1, going back over the lanes leading
    into it if needed; a negative `before` is that many metres past the stop line, straight
    on into the junction). `fromRight`: on the right-hand side of the road as seen by the
    arm's incoming traffic, else on the far left side beyond its outgoing lanes. The spot is
    on the sidewalk there, 0.5 m in from its edge next to the road (at most at its middle),
    else 0.5 m outside the curb (the road's edge, shoulders and parking lanes included);
    `extra` metres further from the road (the 2nd, 3rd ... of a group standing side by side).
    For 'ego' the stop line is the end of the ego's lane (with or without a junction; for a
    spot relative to the ego see `tadCrossAt`). Raises TadRejection if the junction has no
    such arm or its lanes are too short."""
    ins, outs = tadArmLanes(anchor, arm)
    if not ins:
        raise TadRejection(f'no lane enters the junction from its {arm} arm')
    if before >= 0:
        lane, arc = tadBack(ins[0], before)
        return tadCrossing(lane, arc, 0.0, fromRight, extra)
    return tadCrossing(ins[0], ins[0].centerline.length, -before, fromRight, extra)

@tadLazy
def tadCrossAt(anchor, offset, fromRight, extra=0.0):
    """Like `tadCross`, on the ego's road `offset` metres ahead of the ego (negative: behind),
    along its lane as in `tadSpot`: `fromRight` is the ego's right-hand side. Raises
    TadRejection beyond the ends of the ego's lane."""
    lane, arc = anchor
    arc = arc + offset
    if arc < 0 or arc > lane.centerline.length:
        raise TadRejection('crossing beyond the end of the lane')
    return tadCrossing(lane, arc, 0.0, fromRight, extra)

def tadArmsOk(lane, arms, armLanes, armReach):
    """Whether the junction `lane` ends at has the arms `arms`, at least the (incoming,
    outgoing) lanes `armLanes[arm]` and the (incoming, outgoing) metres `armReach[arm]`."""
    if not arms and not armLanes and not armReach:
        return True
    found = tadArms(lane)
    for arm in tuple(arms) + tuple(armLanes or ()) + tuple(armReach or ()):
        if arm not in found or not (found[arm][0] or found[arm][1]):
            return False
    for arm, (nIn, nOut) in (armLanes or {}).items():
        if len(found[arm][0]) < nIn or len(found[arm][1]) < nOut:
            return False
    for arm, (mIn, mOut) in (armReach or {}).items():
        ins, outs = found[arm]
        if mIn > 0 and (not ins or tadReach(ins[0]) < mIn):
            return False
        if mOut > 0 and (not outs or tadReach(outs[0], onward=True) < mOut):
            return False
    return True

def tadAnchors(network, same=None, other=None, minSame=0, minOther=0, index=1, sidewalk=False,
               junction=None, signalised=None, maneuver=None, signs=(), shape=None, ahead=10.0,
               behind=10.0, approach=None, step=4.0, arms=(), armLanes=None, armReach=None):
    """Where the ego vehicle can be: (lane, arc) pairs such that the lane layout is the one asked
    for from `behind` metres behind the ego to `ahead` metres in front of it, and, with an
    `approach`, the lane ends `approach` metres ahead at a junction of the kind asked for.
    With an `approach`, the junction can also be asked to have the arms `arms` (names as in
    `tadArms`: 'ego', 'left', 'right', 'opposite'), at least `armLanes[arm] = (incoming,
    outgoing)` lanes on an arm at the junction, and `armReach[arm] = (incoming, outgoing)`
    metres of ordinary road on the arm before its stop line and after its exit (how far
    `tadArmSpot` and `tadCross` can go). All three are optional. A `shape` holds over the
    whole stretch: with an approach, from `behind` the ego to the junction."""
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
                    tadJunctionOk(lane, junction, signalised, maneuver, signs) and \
                    tadArmsOk(lane, arms, armLanes, armReach) and \
                    tadShapeOk(lane.centerline, arc - behind, length, shape):
                found.append((lane, arc))
            continue
        arc = start + behind
        while arc + ahead <= end:
            if tadShapeOk(lane.centerline, arc - behind, arc + ahead, shape):
                found.append((lane, arc))
            arc += step
    return found

def tadFind(network, wanted):
    """The anchors for the road `wanted` (the keywords of `tadAnchors`); when no junction has
    the reach its arms should have (`armReach`), the junctions with those arms at all, where
    far actors stand as far out as the arm goes."""
    anchors = tadAnchors(network, **wanted)
    if not anchors and wanted.get('armReach'):
        anchors = tadAnchors(network, **dict(wanted, armReach=None))
    return tadRequire(anchors, wanted)

def tadRequire(anchors, wanted):
    if not anchors:
        raise RuntimeError('TADSL: no place on this map has the road the scenario needs ('
                           + ', '.join(f'{k}={v!r}' for k, v in wanted.items() if v is not None and v != () and v != {})
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
    return tadPlace(lane, arc, index, place, width)

def tadPlace(lane, arc, index, place='centre', width=0.0, clamp=False):
    """The spot `arc` metres along `lane` in TAD lane `index` counted from `lane`'s direction
    (positive: lanes of its direction from the left, negative: the others from the centre line
    outwards): (position, heading of that lane there). `place` as in `tadSpot`, or 'shoulder'
    (just outside the outermost lane's edge). With `clamp`, an index beyond the lanes there is
    the outermost lane (a crossing road narrower than the scenario's)."""
    point = lane.centerline.pointAlongBy(arc)
    section = lane.sectionAt(point) or min(lane.sections, key=lambda s: s.distanceTo(point))
    same, other = tadLanes(section)
    lanes = same if index > 0 else other
    if abs(index) > len(lanes):
        if not clamp or not lanes:
            raise TadRejection('no lane with this index here')
        index = len(lanes) if index > 0 else -len(lanes)
    target = lanes[abs(index) - 1]
    position = target.centerline.project(point)
    start, end = target.centerline.nearestSegmentTo(position)
    heading = start.angleTo(end)
    if place != 'centre' and target is lanes[-1]:
        if place == 'sidewalk' and target.group._sidewalk is not None:
            return (target.group._sidewalk.centerline.project(position), heading)
        half = (target.leftEdge.distanceTo(position) + target.rightEdge.distanceTo(position)) / 2
        if place == 'sidewalk':
            shift = half + 0.6
        elif place == 'shoulder':
            shift = half + width / 2 + 0.2
        else:
            shift = max(half - width / 2 - 0.2, 0.0)
        position = position + Vector(shift, 0).rotatedBy(heading)
    return (position, heading)

def tadWay(obj, maneuver, follow=False):
    """The way `obj` goes from where it stands, as a shapely line: as `tadLaneWay` from its
    place in its lane; without a maneuver and with `follow`, along its lane and the ordinary
    lanes it leads into (150 m at most); else straight ahead along its heading for 150 m."""
    from shapely.geometry import LineString, Point
    lane = getattr(obj, '_lane', None)
    if lane is not None and (maneuver is not None or follow):
        arc = lane.centerline.lineString.project(Point(obj.position.x, obj.position.y))
        way = tadLaneWay(lane, arc, maneuver) if maneuver is not None else tadFollowWay(lane, arc, 150.0)
        if way is not None:
            return way
    here = obj.position
    ahead = here + Vector(0, 150).rotatedBy(obj.heading)
    return LineString([(here.x, here.y), (ahead.x, ahead.y)])

def tadFollowWay(lane, arc, length):
    """The way from `arc` metres along `lane` on along it and the ordinary lanes it leads
    into, for `length` metres or to where they end: a shapely line."""
    from shapely.geometry import LineString
    from shapely.ops import substring
    line = lane.centerline.lineString
    points = list(substring(line, arc, line.length).coords)
    total, seen = line.length - arc, {lane.uid}
    while total < length:
        nxt = lane._successor
        if nxt is None or not hasattr(nxt, 'centerline') or nxt.uid in seen or not tadOrdinary(nxt):
            break
        seen.add(nxt.uid)
        lane = nxt
        points.extend(lane.centerline.lineString.coords)
        total += lane.centerline.length
    if len(points) < 2:
        return None
    return LineString([(p[0], p[1]) for p in points])

def tadLaneWay(lane, arc, maneuver):
    """The way from `arc` metres along `lane`, as a shapely line: on to the lane's end, through
    the junction there by its first maneuver of type `maneuver` ('STRAIGHT', 'LEFT_TURN', ...)
    and along the lane after; None if the lane has no maneuver of that type."""
    from shapely.geometry import LineString
    from shapely.ops import substring
    turns = [m for m in lane.maneuvers if m.type.name == maneuver]
    if not turns:
        return None
    line = lane.centerline.lineString
    points = list(substring(line, arc, line.length).coords)
    for part in [p for p in (turns[0].connectingLane, turns[0].endLane) if p is not None]:
        points.extend(part.centerline.lineString.coords)
    return LineString([(p[0], p[1]) for p in points])

@tadLazy
def tadOnTime(anchor, arm, index, ownTurn, egoTurn, egoSpeed, speed, reach, length, before):
    """How far before the stop line of arm `arm` (TAD lane `index`) a vehicle driving at
    `speed` through the junction by maneuver `ownTurn` starts so that it reaches where its
    way first comes within `reach` of the ego's (the ego at `egoSpeed` by `egoTurn`) when the
    ego does: the layout's start rule for an adversary on time, measured again on the map's
    own junction. `before` (the layout's distance) where the ways do not meet on the map;
    never inside the junction (a vehicle of `length`), never farther out than the arm goes."""
    ins, outs = tadArmLanes(anchor, arm)
    if not ins:
        return before
    lane = ins[min(max(index, 1), len(ins)) - 1]
    own = tadLaneWay(lane, lane.centerline.length, ownTurn)
    # (not `ego`: in a Scenic program that name is the ego object)
    egoWay = tadLaneWay(anchor[0], anchor[1], egoTurn)
    meeting = None if own is None or egoWay is None else tadMeeting(own, egoWay, reach)
    if meeting is None:
        return before
    spot = speed * meeting[1] / max(egoSpeed, 0.1) - meeting[0]
    return min(max(spot, length / 2 + 0.5), max(tadReach(ins[0]) - length / 2, length / 2 + 0.5))

def tadMeeting(own, way, reach):
    """The first point of the line `own` within `reach` of the line `way`: its arc along
    each, or None."""
    s = 0.0
    while s <= own.length:
        p = own.interpolate(s)
        if way.distance(p) <= reach:
            return s, way.project(p)
        s += 0.5
    return None

def tadTimeTo(car, way, arc):
    """How long `car` takes to reach `arc` metres along `way` at its speed (at least 0.1 m/s)."""
    from shapely.geometry import Point
    here = way.project(Point(car.position.x, car.position.y))
    return (arc - here) / max(car.speed or 0.0, 0.1)
