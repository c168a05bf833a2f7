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
        take SetThrottleAction(0.5 if self.speed < speed else 0), SetBrakeAction(0), SetSteerAction(0)

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
