# Prelude test: a pedestrian walks across the ego's road 45 m ahead of it from the far left
# side (tadCrossAt, no junction); the ego drives at 8 m/s with car following (TadDrive) and
# must stop for the pedestrian without touching them, then drive on. Any straight stretch of
# Town10HD with a lane each way. Run by compiler/backends/scenic/tools/prelude_check.py.
param map = localPath('Town10HD.xodr')
model scenic.simulators.newtonian.driving_model
#@prelude

tadRoad = dict(same=1, other=1, shape='straight', behind=4.0, ahead=50.0)
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadAt1 = tadCrossAt(tadAnchor, 45.0, False)
walker = new Pedestrian at tadAt1[0], facing tadAt1[1], with regionContainedIn None,
    with behavior TadWalk(2.0), with tadName 'walker', with tadCheckHeading -90,
    with tadCheckSide 'left', with tadCheckCross tadArm(tadAnchor, 'ego')

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadDrive(8.0), with speed 8.0,
    with tadName 'ego', with tadCheckBehind walker, with tadCheckMoves 10
