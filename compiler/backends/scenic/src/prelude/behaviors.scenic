behavior TadStop():
    """A vehicle halted in traffic."""
    while True:
        take SetThrottleAction(0), SetBrakeAction(1.0)

behavior TadParked():
    """A vehicle left standing at the curb."""
    while True:
        take SetThrottleAction(0), SetHandBrakeAction(True)

behavior TadStand():
    """A pedestrian or animal standing still."""
    while True:
        take SetWalkingSpeedAction(0)

behavior TadWalk(speed):
    """A pedestrian or animal walking the way it faces (along the road, or across it)."""
    heading = self.heading
    while True:
        take SetWalkingDirectionAction(heading), SetWalkingSpeedAction(speed)

behavior TadRide(speed):
    """A vehicle keeping its heading at a steady speed (a two-wheeler crossing the road)."""
    while True:
        take SetThrottleAction(TAD_RIDE_THROTTLE if self.speed < speed else 0), SetBrakeAction(0), SetSteerAction(0)

behavior TadReverse(speed):
    """A vehicle driving backwards."""
    while True:
        take SetReverseAction(True), SetThrottleAction(0.4 if self.speed < speed else 0), SetSteerAction(0)

behavior TadFollow(speed):
    """Follow the lane the vehicle is in; keep straight on while it is in none (in a junction)."""
    while self._lane is None:
        take SetThrottleAction(0.5 if self.speed < speed else 0), SetBrakeAction(0), SetSteerAction(0)
    do FollowLaneBehavior(target_speed=speed)

behavior TadTurn(speed, maneuver):
    """Follow the lane, then take a maneuver of the given type at the junction it ends at."""
    lane = self._lane
    turns = [] if lane is None else [m for m in lane.maneuvers if m.type.name == maneuver]
    if turns:
        turn = turns[0]
        path = [lane, turn.endLane] if turn.connectingLane is None else [lane, turn.connectingLane, turn.endLane]
        do FollowTrajectoryBehavior(target_speed=speed, trajectory=path)
    do TadFollow(speed)

def tadGapAhead(car, reach):
    """The free distance (metres, bumper to bumper) from `car` to the nearest object ahead of
    it in its path within `reach`, else None. In its path: ahead of its front, and overlapping
    the band of its width (plus 0.3 m each side) along its heading, or in the same lane. An
    adversary (`tadAdversary`) keeps to its timing: the ego is not in its path."""
    forward = Vector(0, 1).rotatedBy(car.heading)
    right = Vector(1, 0).rotatedBy(car.heading)
    best = None
    heedless = getattr(car, 'tadAdversary', False)
    for obj in simulation().objects:
        if obj is car or (heedless and obj is ego):
            continue
        offset = obj.position - car.position
        along = offset.dot(forward)
        if along <= 0 or along > reach + car.length + 10:
            continue
        turn = obj.heading - car.heading
        cos, sin = abs(tadMath.cos(turn)), abs(tadMath.sin(turn))
        gap = along - car.length / 2 - (obj.length * cos + obj.width * sin) / 2
        if gap > reach or (best is not None and gap >= best):
            continue
        aside = abs(offset.dot(right)) - (obj.width * cos + obj.length * sin) / 2
        if aside > car.width / 2 + 0.3:
            lane = car._lane
            if lane is None or getattr(obj, '_lane', None) != lane:
                continue
        best = max(gap, 0.0)
    return best

def tadHeadway(car):
    """The gap `car` keeps to what is ahead of it: 2 m plus 1.5 s at its speed."""
    return 2.0 + 1.5 * (car.speed or 0.0)

def tadTooClose(car):
    """Whether something is ahead of `car` in its path closer than its headway."""
    gap = tadGapAhead(car, tadHeadway(car))
    return gap is not None and gap < tadHeadway(car)

def tadBraking(car):
    """The brake that stops `car` 1.5 m short of what is ahead of it (0.2 to 1)."""
    gap = tadGapAhead(car, tadHeadway(car))
    if gap is None:
        return 0.2
    speed = car.speed or 0.0
    need = speed * speed / (2 * max(gap - 1.5, 0.1))
    return min(1.0, max(0.2, need / 6.8 + 0.1))

behavior TadDrive(speed):
    """Follow the lane at `speed` (straight on through junctions, as `TadFollow`), slowing down
    and stopping behind whatever is ahead in its path (a vehicle, a pedestrian): it keeps a gap
    of 2 m plus 1.5 s at its speed, and drives on when the way is clear."""
    try:
        do TadFollow(speed)
    interrupt when tadTooClose(self):
        take SetThrottleAction(0), SetBrakeAction(tadBraking(self))

behavior TadThrough(speed, maneuver):
    """Follow the lane at `speed`, then take a maneuver of the given type ('STRAIGHT',
    'LEFT_TURN', 'RIGHT_TURN', 'U_TURN') at the junction it ends at (as `TadTurn`), with the
    car following of `TadDrive`."""
    try:
        do TadTurn(speed, maneuver)
    interrupt when tadTooClose(self):
        take SetThrottleAction(0), SetBrakeAction(tadBraking(self))

behavior TadChangeLane(speed, toLeft):
    """Follow the lane for a moment, then change to the adjacent lane of the same direction."""
    do TadFollow(speed) for 1.5 seconds
    section = self._laneSection
    target = None
    if section is not None:
        target = section._laneToLeft if toLeft else section._laneToRight
    if target is not None and target.isForward == section.isForward:
        do LaneChangeBehavior(laneSectionToSwitch=target, target_speed=speed)
    do TadFollow(speed)

behavior TadOvertake(speed):
    """Follow the lane; when something is close ahead in it, pass it in the lane to the left
    (even against the traffic), then return."""
    try:
        do FollowLaneBehavior(target_speed=speed)
    interrupt when withinDistanceToObjsInLane(self, 15):
        section = self._laneSection
        side = None if section is None else section._laneToLeft
        if side is not None:
            against = side.isForward != section.isForward
            do LaneChangeBehavior(laneSectionToSwitch=side, is_oppositeTraffic=against, target_speed=speed)
            do FollowLaneBehavior(target_speed=speed, laneToFollow=side.lane, is_oppositeTraffic=against) for 3 seconds
        else:
            take SetBrakeAction(1.0)

behavior TadYield(speed):
    """Follow the lane, braking while anything is close ahead."""
    try:
        do FollowLaneBehavior(target_speed=speed)
    interrupt when withinDistanceToAnyObjs(self, 10):
        take SetThrottleAction(0), SetBrakeAction(1.0)
