# Prelude test: cars on the arms of a Town04 four-way junction (any of them: the seeds pick
# different ones): the left-arm car drives straight across (TadThrough), the right-arm car
# turns right (into the far side of the opposite arm), the opposite car and the ego wait.
# Run by compiler/backends/scenic/tools/prelude_check.py.
param map = localPath('Town04.xodr')
model scenic.simulators.newtonian.driving_model
# steps: 120
#@prelude

tadRoad = dict(junction='4way', approach=20.0, behind=4.0, ahead=10.0,
               arms=('left', 'right', 'opposite'),
               armReach={'left': (12.0, 0.0), 'right': (12.0, 0.0), 'opposite': (15.0, 0.0)})
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadStop(), with tadName 'ego'

tadAt1 = tadArmSpot(tadAnchor, 'left', 12.0, 1)
leftCar = new Car at tadAt1[0], facing tadAt1[1], with regionContainedIn None,
    with behavior TadThrough(6.0, 'STRAIGHT'), with tadName 'leftCar', with tadCheckTurn 0,
    with tadCheckHeading -90, with tadCheckSide 'left', with tadCheckMoves 15

tadAt2 = tadArmSpot(tadAnchor, 'right', 12.0, 1)
rightCar = new Car at tadAt2[0], facing tadAt2[1], with regionContainedIn None,
    with behavior TadThrough(5.0, 'RIGHT_TURN'), with tadName 'rightCar', with tadCheckTurn -90,
    with tadCheckHeading 90, with tadCheckSide 'right', with tadCheckMoves 10

tadAt3 = tadArmSpot(tadAnchor, 'opposite', 15.0, 1)
oppositeCar = new Car at tadAt3[0], facing tadAt3[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'oppositeCar',
    with tadCheckHeading 180, with tadCheckSide 'ahead'
