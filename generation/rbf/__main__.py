"""Command line of the RBF styliser's real-capture data: build the averaged neutral walk and the data features.

    python -m generation.rbf neutral  [--corpus CORPUS] [--out generation/data/rbf/neutral_real.npz]
    python -m generation.rbf features [--corpus CORPUS] [--out generation/data/rbf/data_features.json]
    python -m generation.rbf calibrate [--corpus CORPUS] [--out generation/data/rbf/calibrated_intensities.json]
    python -m generation.rbf extend [--corpus CORPUS] [--out generation/data/rbf/extended_intensities.json]
    python -m generation.rbf extend --pooled [--corpus CORPUS] [--bml-corpus BML] \
        [--out generation/data/rbf/pooled_intensities.json]

CORPUS is the real-capture corpus (``python -m generation.mocap dataset bandai-namco DIR --out CORPUS``; default
$REAL_CORPUS, else ``var/mocap/bandai-namco.npz``). ``neutral`` and ``features`` read the train split only;
``calibrate`` and ``extend`` size on the train split and record the held-out (val, test) differences beside it.
``extend --pooled`` sizes happy and sad from the mean over two sources, each weighing the same: Bandai Namco and the
BML walks of Emotion-Gait (``--bml-corpus``, default ``var/mocap/emotion-gait-bml.npz``, built as docs/mocap.md says;
training actors); the ``pooled`` intensity set.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from generation.core.skeleton import GAIT_JOINTS
from generation.mocap.real_corpus import DEFAULT_BML_PATH, load_real_corpus, real_corpus_path

from .calibrate import calibrate, save_calibration
from .data_features import SHIPPED_PATH as FEATURES_PATH
from .data_features import fit_data_features, save_data_features
from .extended import extend, save_extended
from .observer import load_bml_walks
from .real_neutral import SHIPPED_PATH, build_real_neutral, load_cycle
from .themes import CALIBRATED_PATH, EXTENDED_PATH, POOLED_PATH


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m generation.rbf", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_ in (("neutral", "average real normal-walk cycles into the neutral base cycle"),
                        ("features", "fit data-driven RBF features per theme to real themed walks"),
                        ("calibrate", "calibrate the expert features' intensities on real themed walks"),
                        ("extend", "size the extended intensity set (our rows, stride, cadence) on real themed walks")):
        p = sub.add_parser(name, help=help_)
        p.add_argument("--corpus", type=Path, default=real_corpus_path(os.environ),
                       help="real-capture corpus .npz (default: $REAL_CORPUS, else var/mocap/bandai-namco.npz)")
        p.add_argument("--out", default=None, help="output file (default: the shipped file in generation/data/rbf)")
        if name == "extend":
            p.add_argument("--pooled", action="store_true",
                           help="size happy and sad on Bandai Namco and BML together (the pooled intensity set)")
            p.add_argument("--bml-corpus", type=Path, default=DEFAULT_BML_PATH,
                           help="BML walks of Emotion-Gait for --pooled and the rows both sources size "
                                "(default var/mocap/emotion-gait-bml.npz)")
    args = parser.parse_args(argv)
    if args.command == "neutral":

        cycle = build_real_neutral(args.corpus, args.out or SHIPPED_PATH)
        md = cycle.metadata
        print(f"neutral cycle: {md['n_cycles']} cycles from {md['n_takes']} takes, {cycle.duration:.3f} s, "
              f"stride {md['stride_m'][2]:.3f} m, DTW spread {md['dtw_spread']['before']:.5f} -> "
              f"{md['dtw_spread']['after']:.5f} heights -> {args.out or SHIPPED_PATH}")
        return 0
    if args.command == "calibrate":
        data = calibrate(load_real_corpus(args.corpus, skeleton="gait", contents=["walk"]), load_cycle())
        save_calibration(data, args.out or CALIBRATED_PATH)
        for theme, entry in data["themes"].items():
            print(f"{theme}: factors {[round(r['factor'], 2) for r in entry['features']]}")
        return 0
    if args.command == "extend":
        bml = load_bml_walks(args.bml_corpus) if args.pooled or Path(args.bml_corpus).is_file() else None
        data = extend(load_real_corpus(args.corpus, skeleton="gait", contents=["walk"]), load_cycle(), bml_clips=bml,
                      pooled=args.pooled)
        save_extended(data, args.out or (POOLED_PATH if args.pooled else EXTENDED_PATH))
        for theme, entry in data["themes"].items():
            print(f"{theme}: factors {[round(r['factor'], 2) for r in entry['features']]}, "
                  f"stride {entry['tempo']['stride_per_weight']:+.3f}, "
                  f"cadence {entry['tempo']['cadence_per_weight']:+.3f}")
        return 0
    clips = load_real_corpus(args.corpus, skeleton="gait", split="train", contents=["walk"])
    features = fit_data_features(clips, GAIT_JOINTS)
    save_data_features(features, args.out or FEATURES_PATH)
    for theme, entry in features["themes"].items():
        print(f"{theme}: {len(entry['dofs'])} DOFs, top {entry['features'][:3]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
