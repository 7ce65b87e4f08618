"""``python -m generation.mocap import PATH... --skeleton gait|gesture --out DIR``: files and folders -> Motions;
``python -m generation.mocap corpus DIR... --out FILE.npz``: labelled gait Motions -> a corpus for train_gait;
with ``--skeleton gesture --sentences CSV``: gesture takes and their sentences -> a corpus for train_gesture;
``python -m generation.mocap dataset bandai-namco DIR --out CORPUS.npz``: a labelled capture dataset -> the
real-capture corpus (:mod:`generation.mocap.real_corpus`) and ``import_report.csv`` beside it.

Writes ``DIR/<name>.npz`` per input (``Motion.save_npz``; a name used twice gets ``-2``, ``-3``...) and
``DIR/import_report.csv`` (:data:`~generation.mocap.importer.REPORT_COLUMNS`, one row per input, in input order).
Exit status 0 when every input imported, 1 when any failed (the others are still written), 2 for bad arguments
(argparse) or an unreadable labels file / joint map / pattern. ``corpus``: 0 when every Motion was used, 1 when
some were skipped (listed; the corpus is still written), 2 when none gave a window. ``dataset``: 0 when every
selected take imported, 1 when any file failed or none was found (the others are still saved), 2 for bad
arguments.
"""
from __future__ import annotations

import argparse
import csv
import os
import sys
from pathlib import Path

from protocol.vocabulary import GENDERS, MODALITIES

from .bandai_namco import (
    FAST_CONTENTS,
    GESTURE_CONTENTS,
    LOCOMOTION_CONTENTS,
    SPLIT_RULE,
    LayoutError,
    importable_contents,
)
from .corpus import build_captured_gait_corpus, load_motions
from .dataset_import import build_bandai_namco
from .emotion_gait_bml import build_emotion_gait_bml
from .gesture_corpus import build_gesture_corpus, read_sentences, save_gesture_corpus
from .importer import REPORT_COLUMNS, SUFFIXES, ImportOptions, import_file
from .labels import LabelError, compile_pattern, label_for, label_from_pattern, read_labels
from .positions import LAYOUTS
from .real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH, RealCorpora
from .rigs import JOINT_MAP_HELP, RigMapError, load_joint_map


def collect_inputs(paths) -> list[tuple[Path, str]]:
    """(file, as given or found) for files and, recursively and sorted, supported files in folders."""
    out = []
    for given in paths:
        p = Path(given)
        if p.is_dir():
            out += [(f, str(f)) for f in sorted(p.rglob("*")) if f.is_file() and f.suffix.lower() in SUFFIXES]
        else:
            out.append((p, str(given)))
    return out


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m generation.mocap", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    imp = sub.add_parser("import", help="import BVH / joint-position files as Motions",
                         description="Import .bvh, .csv and .npy motion files (folders are searched recursively) "
                                     "onto our gait or gesture skeleton.")
    imp.add_argument("paths", nargs="+", metavar="PATH")
    imp.add_argument("--skeleton", choices=MODALITIES, required=True)
    imp.add_argument("--out", required=True, type=Path, help="output folder (created)")
    imp.add_argument("--labels", type=Path, help="CSV: source + emotion, or source + the gait emotion columns")
    imp.add_argument("--label-pattern", help="regex with a named group (emotion) searched in each file name")
    imp.add_argument("--joint-map", type=Path, help=JOINT_MAP_HELP)
    imp.add_argument("--scale", type=float, help="metres per file unit (default: guessed from the body height)")
    imp.add_argument("--fps", type=float, help="resample every result to this frame rate")
    imp.add_argument("--input-fps", type=float, default=30.0, help="frame rate of position files (default 30)")
    imp.add_argument("--layout", help=f"joint names of position files: {', '.join(LAYOUTS)} or a comma list")
    imp.add_argument("--up", default="auto", choices=("auto", "+y", "-y", "+z", "-z", "+x", "-x"))
    imp.add_argument("--height", type=float, default=1.75, help="our skeleton's height in metres (default 1.75)")
    imp.add_argument("--build", choices=GENDERS, default="male")
    imp.add_argument("--proportions", choices=("ours", "source"), default="ours",
                     help="ours: our skeleton of --height/--build (default); source: the actor's bone lengths")
    imp.add_argument("--max-import-error-cm", type=float, default=3.0,
                     help="a file whose solve misses a source joint by more is an error (default 3)")
    imp.add_argument("--quiet", action="store_true", help="no progress bar or summary")
    cor = sub.add_parser("corpus", help="labelled imported gait Motions -> a gait corpus .npz for train_gait",
                         description="Cut imported, labelled gait Motions (.npz, folders searched recursively) "
                                     "into fixed-length windows and save them as a gait corpus (train_gait "
                                     "--corpus FILE).")
    cor.add_argument("paths", nargs="+", metavar="DIR")
    cor.add_argument("--out", required=True, type=Path, help="corpus .npz to write")
    cor.add_argument("--frames", type=int, default=240, help="window length in frames (default 240)")
    cor.add_argument("--stride", type=int, help="frames between window starts (default: --frames)")
    cor.add_argument("--fps", type=float, default=30.0, help="corpus frame rate (default 30)")
    cor.add_argument("--seed", type=int, default=0, help="seed of the train/val/test split by file")
    cor.add_argument("--skeleton", choices=MODALITIES, default=MODALITIES[0],
                     help="gait (default): windows for train_gait; gesture: one example per take for train_gesture")
    cor.add_argument("--sentences", type=Path, help="gesture corpus: CSV source, sentence, task[, handedness]")
    _add_dataset_parser(sub)
    return ap


def _add_dataset_parser(sub) -> None:

    def names(table):
        return ", ".join(f"dataset {k}: {' '.join(v)}" for k, v in table.items())

    ds = sub.add_parser("dataset", help="a labelled capture dataset -> the real-capture corpus .npz",
                        description="Import every locomotion take onto the gait skeleton and every gesture take "
                                    "onto the gesture skeleton, keeping dataset, content, style, label, take and "
                                    "the held-out split; write the corpus and import_report.csv beside it. "
                                    f"Split: {SPLIT_RULE}")
    ds.add_argument("source", choices=("bandai-namco", "emotion-gait-bml"),
                    help="the dataset's layout (emotion-gait-bml: DIR holds bml_walks.npz, positions only)")
    ds.add_argument("root", type=Path, metavar="DIR", help="folder holding the dataset (searched recursively)")
    ds.add_argument("--out", type=Path, default=None,
                    help=f"corpus .npz to write (default: bandai-namco $REAL_CORPUS, else {DEFAULT_PATH}; "
                         f"emotion-gait-bml $BML_CORPUS, else {DEFAULT_BML_PATH})")
    # where the readers of the corpora look when the same variables are set
    ds.set_defaults(corpora=RealCorpora.from_environ(os.environ))
    ds.add_argument("--contents", nargs="+", choices=sorted(importable_contents()), metavar="CONTENT",
                    help=f"import only these contents (default: locomotion {names(LOCOMOTION_CONTENTS)}; "
                         f"gestures {names(GESTURE_CONTENTS)}; {names(FAST_CONTENTS)} only when named)")
    ds.add_argument("--limit", type=int, help="import at most N of the selected takes (in path order)")
    ds.add_argument("--workers", type=int, default=1, help="import processes (default 1)")
    ds.add_argument("--height", type=float, default=1.75, help="our skeletons' height in metres (default 1.75)")
    ds.add_argument("--build", choices=GENDERS, default="male")
    ds.add_argument("--quiet", action="store_true", help="no progress bar or summary")


def run_dataset(args) -> int:

    if args.limit is not None and args.limit < 1 or args.workers < 1:
        print("error: --limit and --workers must be at least 1", file=sys.stderr)
        return 2
    if args.source == "emotion-gait-bml":
        out = args.out or args.corpora.bml
        return build_emotion_gait_bml(args.root, out, args.height, args.build, args.quiet)
    try:
        return build_bandai_namco(args.root, args.out or args.corpora.bandai, args.contents, args.limit,
                                  args.workers, args.height, args.build, args.quiet)
    except LayoutError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def run_gesture_corpus(args, motions, problems) -> int:

    if args.sentences is None:
        print("error: a gesture corpus needs --sentences CSV (source, sentence, task)", file=sys.stderr)
        return 2
    try:
        arrays, skipped = build_gesture_corpus(motions, read_sentences(args.sentences))
    except (LabelError, ValueError) as exc:
        print("\n".join(f"error: {p}" for p in problems) + f"\nerror: {exc}", file=sys.stderr)
        return 2
    path = save_gesture_corpus(arrays, args.out)
    print(f"wrote {path}: {len(arrays['lengths'])} gesture takes, {int(arrays['lengths'].sum())} frames at "
          f"{float(arrays['fps']):g} fps", file=sys.stderr)
    for p in problems + skipped:
        print(f"  skipped: {p}", file=sys.stderr)
    return 1 if problems or skipped else 0


def run_corpus(args) -> int:
    motions, problems = load_motions(args.paths)
    if args.skeleton == "gesture":
        return run_gesture_corpus(args, motions, problems)
    try:
        corpus, skipped = build_captured_gait_corpus(motions, args.frames, args.fps, args.stride, args.seed)
    except ValueError as exc:
        print("\n".join(f"error: {p}" for p in problems), file=sys.stderr)
        print(f"error: {exc}", file=sys.stderr)
        return 2
    problems += skipped
    path = corpus.save(args.out)
    summary = corpus.summary()
    print(f"wrote {path}: {summary['sequences']} windows of {summary['frames']} frames from "
          f"{len(corpus.metadata['sources'])} files; split {summary['split']}", file=sys.stderr)
    for p in problems:
        print(f"  skipped: {p}", file=sys.stderr)
    return 1 if problems else 0


def run_import(args) -> int:
    try:
        joint_map = load_joint_map(args.joint_map) if args.joint_map else {}
        labels = read_labels(args.labels) if args.labels else None
        pattern = compile_pattern(args.label_pattern) if args.label_pattern else None
    except (RigMapError, LabelError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    options = ImportOptions(skeleton=args.skeleton, height=args.height, build=args.build, scale=args.scale,
                            fps=args.fps, input_fps=args.input_fps, layout=args.layout, joint_map=joint_map,
                            up=args.up, proportions=args.proportions, max_import_error_m=args.max_import_error_cm / 100)
    inputs = collect_inputs(args.paths)
    args.out.mkdir(parents=True, exist_ok=True)
    rows, used = [], set()
    from tqdm import tqdm
    bar = tqdm(inputs, desc="import", unit="file", disable=args.quiet or len(inputs) < 2 or None, file=sys.stderr)
    for file, given in bar:
        label = None
        try:
            if labels is not None:
                label = label_for(labels, file, given)
            if label is None and pattern is not None:
                label = label_from_pattern(pattern, file)
        except LabelError as exc:
            rows.append({**{c: "" for c in REPORT_COLUMNS}, "source": given, "status": "error", "message": str(exc)})
            continue
        result = import_file(file, options, label, given)
        if result.motion is not None:
            name, k = file.stem, 1
            while name in used:
                k += 1
                name = f"{file.stem}-{k}"
            used.add(name)
            result.motion.save_npz(args.out / f"{name}.npz")
        rows.append(result.row)
    with open(args.out / "import_report.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=REPORT_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    failed = [r for r in rows if r["status"] != "ok"]
    if not args.quiet:
        print(f"imported {len(rows) - len(failed)} of {len(rows)} files into {args.out}", file=sys.stderr)
        for r in failed:
            print(f"  error: {r['message']}", file=sys.stderr)
    if not rows:
        print("error: no .bvh, .csv or .npy files found in the given paths", file=sys.stderr)
        return 1
    return 1 if failed else 0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command == "import":
        return run_import(args)
    if args.command == "corpus":
        return run_corpus(args)
    if args.command == "dataset":
        return run_dataset(args)
    return 2  # pragma: no cover - argparse requires a command
