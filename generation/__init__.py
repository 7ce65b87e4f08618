"""Motion generation library, plain Python (numpy, torch, pyvista); never imports Django.

Packages, bottom layer first; each imports only the packages listed before it (tests/test_layers.py checks it):
    core/        maths and the Motion type: quaternions, skeletons, kinematics, IK, features, paths, windows, digest
    formats/     motion files: BVH, DeepMimic JSON, the shipped captured walks
    procedural/  SYNTHETIC procedural walks and seated gestures, emotion mappings, the synthetic corpus
    render/      PyVista offscreen renderer -> MP4/WebM + poster
    gesture/     seed 003 text-to-gesture transformer
    mocap/       bring your own capture: rigs, retargeting, importers, the labelled real corpora
    gait/        seed 000 affect-based autoregression gait network
    rbf/         seed 004 Gaussian RBF styles: features, themes, the neutral base walk, stylisation
    quality/     per-clip measures, the observers, realism, the quality gate
    plans/       the generator registry, stimulus plans, plan entry -> Motion (clipgen), the clip catalogue
    pipeline/    the plan runner: jobs, workers, Dask, plan QA
    imports/     researchers' own clips from a manifest (videos and motion files)
The study vocabulary comes from the top-level ``protocol.vocabulary`` module.
"""
