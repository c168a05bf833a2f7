# Prelude test: car following. A car stands 30 m ahead of the ego in its lane; another one,
# 12 m ahead, and the ego drive at 8 m/s (TadDrive) and must queue up behind it without
# touching. Any straight stretch of Town04. Run by
# compiler/backends/scenic/tools/prelude_check.py.
param map = localPath('Town04.xodr')
model scenic.simulators.newtonian.driving_model
#@prelude

tadRoad = dict(shape='straight', behind=4.0, ahead=45.0)
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadAt2 = tadSpot(tadAnchor, 30.0, 1)
leader = new Car at tadAt2[0], facing tadAt2[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'leader'

tadAt1 = tadSpot(tadAnchor, 12.0, 1)
middle = new Car at tadAt1[0], facing tadAt1[1], with regionContainedIn None, with speed 8.0,
    with behavior TadDrive(8.0), with tadName 'middle', with tadCheckBehind leader,
    with tadCheckMoves 5

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadDrive(8.0), with speed 8.0,
    with tadName 'ego', with tadCheckBehind middle, with tadCheckMoves 10
