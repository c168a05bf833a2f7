# Prelude test: pedestrians who walk across the road (TadWalk) from where tadCross puts them:
# two in a row on the right-hand side of the ego's road 3 m before its stop line, one from
# the far side of the left arm's road; the ego waits. Each crosses the centre line of the
# lane 1 of its road. Run by compiler/backends/scenic/tools/prelude_check.py.
param map = localPath('Town10HD.xodr')
model scenic.simulators.newtonian.driving_model
#@prelude

tadRoad = dict(junction='4way', approach=17.0, behind=4.0, ahead=10.0, arms=('left',),
               armReach={'left': (3.0, 0.0)})
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadStop()

tadAt1 = tadCross(tadAnchor, 'ego', 3.0, True)
walker1 = new Pedestrian at tadAt1[0], facing tadAt1[1], with regionContainedIn None,
    with behavior TadWalk(2.0), with tadName 'walker1', with tadCheckHeading 90,
    with tadCheckSide 'right', with tadCheckCross tadArm(tadAnchor, 'ego')

tadAt2 = tadCross(tadAnchor, 'ego', 3.0, True, 1.0)
walker2 = new Pedestrian at tadAt2[0], facing tadAt2[1], with regionContainedIn None,
    with behavior TadWalk(2.0), with tadName 'walker2', with tadCheckHeading 90,
    with tadCheckSide 'right', with tadCheckCross tadArm(tadAnchor, 'ego')

tadAt3 = tadCross(tadAnchor, 'left', 2.0, False)
walker3 = new Pedestrian at tadAt3[0], facing tadAt3[1], with regionContainedIn None,
    with behavior TadWalk(2.0), with tadName 'walker3', with tadCheckHeading 180,
    with tadCheckSide 'left', with tadCheckCross tadArm(tadAnchor, 'left')
