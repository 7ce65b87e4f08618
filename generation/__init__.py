"""Motion generation library, plain Python (numpy, torch, pyvista); never imports Django.

Layers, each importing only those above it:
    core/        maths and the Motion type: quaternions, skeletons, kinematics, IK, features, ground paths, rigging
    formats/     motion files: BVH, DeepMimic JSON, the shipped captured walks
    procedural/  SYNTHETIC procedural walks and seated gestures, emotion mappings, the synthetic corpus
    rbf/         seed 004 Gaussian RBF styles: features, themes, the neutral base walk, stylisation
    gait/        seed 000 affect-based autoregression gait network
    gesture/     seed 003 text-to-gesture transformer
    render/      PyVista offscreen renderer -> MP4/WebM + poster
    plans/       stimulus plans, plan entry -> Motion (clipgen), the clip catalogue
The study vocabulary comes from the top-level ``study_protocol`` module.
"""
