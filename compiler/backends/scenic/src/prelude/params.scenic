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
