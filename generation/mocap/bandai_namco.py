"""The Bandai Namco Research Motion Dataset's layout: its takes under a folder, their labels and the held-out split.

Real optical capture by professional actors (Kobayashi et al. 2023, arXiv:2306.08861; CC BY-NC 4.0;
github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset). Both datasets are laid out as
``.../Bandai-Namco-Research-Motiondataset-N/{cfg,data}``: ``data/dataset-N_{content}_{style}_{take}.bvh`` with a
JSON file beside each (``{"content": id, "style": id}``), and ``cfg/content_label.txt`` / ``cfg/style_label.txt``
naming the ids in order, one ``dataset-N_{name}`` a line. :func:`find_takes` reads that layout under any folder
and checks the JSON against the file name; :func:`split_for` is the held-out split (:data:`SPLIT_RULE`).
"""
from __future__ import annotations

import json
import re
import zlib
from dataclasses import dataclass
from pathlib import Path

from protocol.vocabulary import capture_label

DATASET_IDS = {"1": "bandai-namco-1", "2": "bandai-namco-2"}
"""Dataset number in the file name -> the corpus's ``dataset`` value."""

LOCOMOTION_CONTENTS = {"1": ("walk", "walk-left", "walk-right", "walk-back"),
                       "2": ("walk", "walk-turn-left", "walk-turn-right")}
"""Contents imported onto the gait skeleton by default, per dataset."""

FAST_CONTENTS = {"1": ("run", "dash")}
"""Locomotion contents imported onto the gait skeleton only when asked for (``--contents run dash``)."""

GESTURE_CONTENTS = {"1": ("bow", "bye", "byebye", "guide", "respond"),
                    "2": ("wave-both-hands", "wave-left-hand", "wave-right-hand", "raise-up-both-hands",
                          "raise-up-left-hand", "raise-up-right-hand")}
"""Contents imported onto the gesture skeleton, per dataset."""

SINGLE_TAKE_GROUPS = (("walk-left", "walk-right", "walk-back"), ("run", "dash"), ("bow", "bye", "byebye", "guide"))
"""Dataset 1's contents with one take per style, in groups of alike contents: each style holds out one content of
each group (see :data:`SPLIT_RULE`)."""

DATASET1_STYLES = ("normal", "happy", "sad", "angry", "proud", "not-confident", "masculinity", "feminine", "childish",
                   "old", "tired", "active", "musical", "giant", "chimpira")
"""Dataset 1's styles in the order of its ``cfg/style_label.txt``: the rotation of the single-take split."""

SPLIT_RULE = (
    "Held out by take, a pure function of the file name dataset-N_{content}_{style}_{take}. "
    "Dataset 2 (17-104 takes per content and style): take % 5 == 0 -> test, take % 10 == 3 -> val, else train "
    "(20% test, 10% val; every content and style has test and val takes, spread over the recording order). "
    "Dataset 1, contents with two takes (walk, call, punch, slash): take 2 -> test, take 1 -> train. "
    "Dataset 1, one take per style: within each group of alike contents (walk-left/walk-right/walk-back; "
    "run/dash; bow/bye/byebye/guide) the content group[i % len(group)] is test for the style, where i is the "
    "style's place in dataset 1's style list (normal, happy, sad, angry, proud, not-confident, masculinity, "
    "feminine, childish, old, tired, active, musical, giant, chimpira; crc32 of the name for a style not in it), "
    "the others train, so every style has one held-out take per group; other single-take contents (respond, kick, "
    "dance) -> train. Dataset 1 has no val takes (too few).")

NAME_RE = re.compile(r"^dataset-(?P<number>\d+)_(?P<content>[a-z0-9-]+)_(?P<style>[a-z0-9-]+)_(?P<take>\d+)$")

SHIPPED_DIR = Path(__file__).resolve().parents[1] / "data" / "mocap" / "bandai-namco"
"""The real subset shipped in the repository (the upstream layout, with LICENSE, NOTICE.md and CITATION)."""


class LayoutError(ValueError):
    """A file or folder does not follow the dataset's layout; the message names the file and the cause."""


@dataclass(frozen=True)
class TakeName:
    """What a file name ``dataset-N_{content}_{style}_{take}`` says."""

    name: str
    number: str      # "1" or "2"
    content: str
    style: str
    take: int

    @property
    def dataset(self) -> str:
        return DATASET_IDS.get(self.number, f"bandai-namco-{self.number}")


@dataclass(frozen=True)
class Take:
    """One labelled take found on disk.

    Attributes:
        path: the .bvh file.
        dataset, content, style, take: from the file name (the JSON labels agree).
        label: the study vocabulary's name for the style (``protocol.vocabulary.capture_label``).
        split: "train", "val" or "test" (:func:`split_for`).
        skeleton: "gait", "gesture", or None for contents this importer does not take (punch, dance, ...).
    """

    path: Path
    name: str
    dataset: str
    content: str
    style: str
    take: int
    label: str
    split: str
    skeleton: str | None


def parse_name(name: str) -> TakeName:
    """A file name or stem (``dataset-1_walk_happy_001`` or ``...bvh``) -> its parts; LayoutError if it does not
    follow the dataset's pattern."""
    stem = Path(name).name
    if stem.lower().endswith(".bvh"):
        stem = stem[:-4]
    m = NAME_RE.match(stem)
    if m is None:
        raise LayoutError(f"{name}: not a dataset-N_{{content}}_{{style}}_{{take}} file name")
    return TakeName(stem, m["number"], m["content"], m["style"], int(m["take"]))


def _single_take_group(content: str) -> tuple[str, ...] | None:
    return next((g for g in SINGLE_TAKE_GROUPS if content in g), None)


def split_for(name: str) -> str:
    """The held-out split ("train", "val", "test") of a take, from its file name alone (:data:`SPLIT_RULE`)."""
    t = parse_name(name)
    if t.number != "1":
        if t.take % 5 == 0:
            return "test"
        return "val" if t.take % 10 == 3 else "train"
    if t.take >= 2:
        return "test"
    group = _single_take_group(t.content)
    i = DATASET1_STYLES.index(t.style) if t.style in DATASET1_STYLES else zlib.crc32(t.style.encode())
    if group is not None and group[i % len(group)] == t.content:
        return "test"
    return "train"


def skeleton_for(number: str, content: str, extra: tuple[str, ...] = ()) -> str | None:
    """"gait" for locomotion contents (and ``extra`` fast ones asked for), "gesture" for gesture contents, else
    None."""
    if content in LOCOMOTION_CONTENTS.get(number, ()) or content in set(extra) & set(FAST_CONTENTS.get(number, ())):
        return "gait"
    if content in GESTURE_CONTENTS.get(number, ()):
        return "gesture"
    return None


def importable_contents() -> set[str]:
    """Every content name :func:`skeleton_for` can map, over both datasets (fast ones included)."""
    out: set[str] = set()
    for table in (LOCOMOTION_CONTENTS, FAST_CONTENTS, GESTURE_CONTENTS):
        for names in table.values():
            out.update(names)
    return out


def _read_label_file(path: Path, number: str) -> tuple[str, ...]:
    """Names in id order from a cfg label file (``dataset-N_{name}`` a line)."""
    try:
        lines = [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    except OSError as exc:
        raise LayoutError(f"{path}: cannot read ({exc.strerror or exc})") from None
    prefix = f"dataset-{number}_"
    bad = [ln for ln in lines if not ln.startswith(prefix)]
    if bad:
        raise LayoutError(f"{path}: line {lines.index(bad[0]) + 1} ({bad[0]!r}) does not start with {prefix!r}")
    return tuple(ln[len(prefix):] for ln in lines)


def read_cfg(cfg_dir: Path, number: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(content names, style names) in id order from ``cfg_dir``; LayoutError when missing or malformed."""
    return (_read_label_file(cfg_dir / "content_label.txt", number),
            _read_label_file(cfg_dir / "style_label.txt", number))


def _find_cfg(path: Path, root: Path) -> Path | None:
    """The ``cfg`` folder of a data file: beside it or beside its folder (not above ``root``'s parent)."""
    for d in (path.parent, path.parent.parent):
        if (d / "cfg" / "content_label.txt").is_file():
            return d / "cfg"
        if d == root:
            break
    return None


def check_take(path: Path, cfg: tuple[tuple[str, ...], tuple[str, ...]] | None) -> TakeName:
    """Parse the name and check the JSON labels beside the file against it; LayoutError names the cause."""
    t = parse_name(path.name)
    if cfg is None:
        raise LayoutError(f"{path}: no cfg/content_label.txt beside the file or its folder")
    json_path = path.with_suffix(".json")
    try:
        ids = json.loads(json_path.read_text(encoding="utf-8"))
        content_id, style_id = int(ids["content"]), int(ids["style"])
    except OSError:
        raise LayoutError(f"{path}: no readable label file {json_path.name} beside it") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise LayoutError(f"{json_path}: not a {{\"content\": id, \"style\": id}} JSON object ({exc})") from None
    contents, styles = cfg
    for kind, idx, names, expected in (("content", content_id, contents, t.content), ("style", style_id, styles,
                                                                                      t.style)):
        if not 0 <= idx < len(names):
            raise LayoutError(f"{json_path}: {kind} id {idx} is not in cfg ({len(names)} {kind}s)")
        if names[idx] != expected:
            raise LayoutError(f"{json_path}: {kind} id {idx} is {names[idx]!r} in cfg but the file name says "
                              f"{expected!r}")
    return t


def find_takes(root: str | Path, extra_contents: tuple[str, ...] = ()) -> tuple[list[Take], list[tuple[Path, str]]]:
    """Every ``dataset-*.bvh`` under ``root`` (recursively, sorted by path) as a Take, and the bad ones as (path,
    message): a name off the pattern, a missing or malformed JSON or cfg, labels that disagree with the name.
    Takes of every content are returned (``skeleton`` None for those not imported); ``extra_contents`` names fast
    locomotion contents to map onto the gait skeleton. LayoutError when ``root`` is not a folder."""
    root = Path(root)
    if not root.is_dir():
        raise LayoutError(f"{root}: not a folder")
    cfgs: dict[tuple[Path, str], tuple | LayoutError] = {}
    takes, bad = [], []
    for path in sorted(root.rglob("*.bvh")):
        try:
            number = parse_name(path.name).number
            cfg_dir = _find_cfg(path, root)
            cfg = None
            if cfg_dir is not None:
                key = (cfg_dir, number)
                if key not in cfgs:
                    try:
                        cfgs[key] = read_cfg(cfg_dir, number)
                    except LayoutError as exc:
                        cfgs[key] = exc
                if isinstance(cfgs[key], LayoutError):
                    raise cfgs[key]
                cfg = cfgs[key]
            t = check_take(path, cfg)
        except LayoutError as exc:
            bad.append((path, str(exc)))
            continue
        takes.append(Take(path, t.name, t.dataset, t.content, t.style, t.take, capture_label(t.style),
                          split_for(t.name), skeleton_for(t.number, t.content, extra_contents)))
    return takes, bad


def shipped_takes() -> list[Take]:
    """The real takes shipped in the repository (:data:`SHIPPED_DIR`) with their parsed labels; LayoutError if the
    shipped folder is damaged."""
    takes, bad = find_takes(SHIPPED_DIR)
    if bad:
        raise LayoutError("shipped real subset is damaged: " + "; ".join(msg for _, msg in bad))
    return takes
