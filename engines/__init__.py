"""Engine adapters: MuJoCo and PyBullet models of a `Scene`, returning `Trajectory`."""
