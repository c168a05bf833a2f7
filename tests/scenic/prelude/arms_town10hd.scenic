# Prelude test: an actor on every arm of Town10HD's four-way junction, 17 m before the ego's
# stop line, all standing. Run by
# compiler/backends/scenic/tools/prelude_check.py, which puts the prelude at `#@prelude` and
# checks the `tadCheck...` properties (see its docstring).
param map = localPath('Town10HD.xodr')
model scenic.simulators.newtonian.driving_model
#@prelude

tadRoad = dict(junction='4way', approach=17.0, behind=4.0, ahead=10.0,
               arms=('left', 'right', 'opposite'), armReach={'left': (5.0, 5.0), 'opposite': (10.0, 0.0)})
tadAnchor = Uniform(*tadRequire(tadAnchors(network, **tadRoad), tadRoad))

tadEgoAt = tadSpot(tadAnchor, 0.0, 1)
ego = new Car at tadEgoAt[0], facing tadEgoAt[1], with behavior TadStop()

tadAt1 = tadArmSpot(tadAnchor, 'left', 5.0, 1)
leftCar = new Car at tadAt1[0], facing tadAt1[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'leftCar', with tadCheckHeading -90, with tadCheckSide 'left'

tadAt2 = tadArmSpot(tadAnchor, 'right', 10.0, 2)
rightCar = new Car at tadAt2[0], facing tadAt2[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'rightCar', with tadCheckHeading 90, with tadCheckSide 'right'

tadAt3 = tadArmSpot(tadAnchor, 'opposite', 10.0, 1)
oppositeCar = new Car at tadAt3[0], facing tadAt3[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'oppositeCar', with tadCheckHeading 180, with tadCheckSide 'ahead'

tadAt4 = tadArmSpot(tadAnchor, 'left', 5.0, -1)
leavingLeft = new Car at tadAt4[0], facing tadAt4[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'leavingLeft', with tadCheckHeading 90, with tadCheckSide 'left'

tadAt5 = tadArmSpot(tadAnchor, 'ego', 12.0, -1)
oncoming = new Car at tadAt5[0], facing tadAt5[1], with regionContainedIn None,
    with behavior TadStop(), with tadName 'oncoming', with tadCheckHeading 180, with tadCheckSide 'left'
