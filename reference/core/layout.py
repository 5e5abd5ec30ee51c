"""The layout of a state vector y (13 doubles), the one place that knows it: the
position of the centre of mass x (world), the attitude quaternion q = (w, x, y, z)
body → world, the velocity v of the centre of mass (world) and the angular velocity ω
(world).  The core indexes states by these names (y[VZ]: the vertical velocity); the
time derivative of a state (held.held_rhs, the DOP853 stages) has the same layout.
Python reads the parts by the slices (y[QUATERNION])."""

X, Y, Z = 0, 1, 2  # position of the centre of mass
QW, QX, QY, QZ = 3, 4, 5, 6  # attitude quaternion, body → world
VX, VY, VZ = 7, 8, 9  # velocity of the centre of mass
WX, WY, WZ = 10, 11, 12  # angular velocity, world frame
STATE_SIZE = 13

POSITION = slice(X, Z + 1)
QUATERNION = slice(QW, QZ + 1)
VELOCITY = slice(VX, VZ + 1)
ANGULAR_VELOCITY = slice(WX, WZ + 1)
POSE = slice(X, QZ + 1)  # (x, q): MuJoCo's qpos
VELOCITIES = slice(VX, WZ + 1)  # (v, ω): what an impulse or an acceleration changes
