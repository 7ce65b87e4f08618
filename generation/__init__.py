"""Motion generation library: skeletons, kinematics, features, motion I/O, generators, renderer.

Plain Python (numpy, torch, pyvista); never imports Django.
"""
