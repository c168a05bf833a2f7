behavior TadOneOf(index, options):
    """One of a choice of behaviors: the one at the sampled index."""
    do options[index]

behavior TadDelayed(delay, hold, then):
    """Hold still for `delay` seconds, then behave."""
    do hold for delay seconds
    do then

behavior TadTriggered(distance, hold, then):
    """Hold still until the ego vehicle is within `distance` metres, then behave."""
    do hold until (distance from self to ego) < distance
    do then

behavior TadMeet(ownTurn, egoTurn, speed, offset, hold, then):
    """Hold still until the ego's time to where its way first meets ours, measured on the map
    while the scenario runs, falls to our own time to that point at `speed` (plus `offset`
    seconds), then behave: the layout's conflict start on the map's own junction. The ego's
    way is its maneuver `egoTurn` through the junction, or its lane onward without one. A
    vehicle starts from rest: it goes sooner by the time it loses picking up speed at
    TAD_LAUNCH."""
    way = tadWay(ego, egoTurn, follow=True)
    meeting = tadMeeting(tadWay(self, ownTurn), way, (self.width + ego.width) / 2 + TAD_MEET_MARGIN)
    if meeting is not None:
        launch = speed / (2 * TAD_LAUNCH) if self.isCar else 0
        travel = max(meeting[0] / speed + launch + offset, 0)
        do hold until tadTimeTo(ego, way, meeting[1]) <= travel
    do then
