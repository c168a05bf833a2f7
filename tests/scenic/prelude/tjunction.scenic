# Prelude test: a three-way junction asked to have a left and an opposite arm (so never one
# of the T-junctions without them), with a car waiting on each and one leaving on the left
# arm; and one that needs lane 2 on the left arm: tadAnchors' armLanes. Town01's junctions
# are all three-way. Run by compiler/backends/scenic/tools/prelude_check.py.
param map = localPath('Town01.xodr')
model scenic.simulators.newtonian.driving_model
#@prelude

tadRoad = dict(junction='3way', approach=12.0, behind=4.0, ahead=8.0, arms=('left', 'opposite'),
               armLanes={'left': (1, 1)}, armReach={'left': (8.0, 8.0), 'opposite': (6.0, 0.0)})
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadThrough(4.0, 'STRAIGHT'), with tadName 'ego',
    with tadCheckTurn 0, with tadCheckMoves 10

tadAt1 = tadArmSpot(tadAnchor, 'left', 8.0, 1)
leftCar = new Car at tadAt1[0], facing tadAt1[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'leftCar', with tadCheckHeading -90, with tadCheckSide 'left'

tadAt2 = tadArmSpot(tadAnchor, 'opposite', 6.0, 1, 'curb', 1.8)
oppositeCar = new Car at tadAt2[0], facing tadAt2[1], with regionContainedIn None,
    with behavior TadParked(), with tadName 'oppositeCar', with tadCheckHeading 180,
    with tadCheckSide 'ahead'

tadAt3 = tadArmSpot(tadAnchor, 'left', 8.0, -1)
leavingLeft = new Car at tadAt3[0], facing tadAt3[1], with regionContainedIn None,
    with behavior TadDrive(5.0), with tadName 'leavingLeft', with tadCheckHeading 90,
    with tadCheckSide 'left', with tadCheckMoves 10
