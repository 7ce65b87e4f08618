"""Core maths and the Motion type: quaternions, skeletons, kinematics, IK, features, ground paths."""
