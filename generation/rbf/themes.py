"""The six secondary themes of seed 004 as data: Table III's ten most frequent features per theme.

Each theme is an ordered tuple of :class:`Feature` in the table's frequency order (rank 1 first), so
"the first n features" of the paper's scalability study (n = 1, 4, 7, 10) is ``THEMES[name][:n]``.

What the table gives and we copy: body part, axis, posture ("tilted along") versus movement
("increased/decreased swing along"), and the signs (including the per-side signs "R along +X, L along -X").
What the paper only shows in a figure (Fig. 5: per-cell shape number and normalised intensity as a heat
map whose numbers did not survive in our copy) and we chose: the ``shape`` (Fig. 4 type 1-4) of each
movement feature and every ``intensity``. Intensities are amplitudes divided by the walker's height, as in
Fig. 5; the choices follow the paper's statements (movement features are stronger than posture features;
happy wrist swing along Z, tired ankle swing along Z and masculine ankle swing along Y are the strongest).
See docs/rbf.md for the reasoning.

Axes: the paper's X, Y, Z are the walker's left, up and forward (checked against the signed entries:
feminine ankles/knees/thighs move R along +X and L along -X, i.e. towards the midline; masculine ones
move outward; sad and tired heads tilt along -Y (down) and +Z (forward)). That is exactly our frame
(y up, facing +z, left = +x), so paper axis "X" is our x, "Y" our y, "Z" our z.
"""
from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

from protocol.vocabulary import THEMES as THEME_NAMES  # the six theme names; THEMES below is Table III by theme

AXES = {"X": 0, "Y": 1, "Z": 2}

# The paper's 11 body parts (Fig. 3) on the 21-joint gait skeleton. Paired parts list (left, right).
BODY_PARTS: dict[str, tuple[str, ...]] = {
    "hip": ("root",),
    "thighs": ("left_hip", "right_hip"),
    "knees": ("left_knee", "right_knee"),
    "ankles": ("left_heel", "right_heel"),
    "torso_l": ("lower_back",),
    "torso_u": ("spine",),
    "neck": ("neck",),
    "head": ("head",),
    "shoulders": ("left_shoulder", "right_shoulder"),
    "elbows": ("left_elbow", "right_elbow"),
    "wrists": ("left_hand", "right_hand"),
}
PART_LABELS = {"hip": "Hip", "thighs": "Thighs", "knees": "Knees", "ankles": "Ankles", "torso_l": "Torso L",
               "torso_u": "Torso U", "neck": "Neck", "head": "Head", "shoulders": "Shoulders",
               "elbows": "Elbows", "wrists": "Wrists"}


@dataclass(frozen=True)
class Feature:
    """One row of Table III.

    Attributes:
        rank: 1..10, the table's frequency order.
        part: key of :data:`BODY_PARTS`.
        axis: "X", "Y" or "Z" (paper axes; identical to ours, see module docstring).
        kind: "tilt" (posture, Fig. 4 type 1) or "swing" (movement, types 2-4).
        sign: tilt: +1/-1 direction along the axis for every joint of the part; swing: +1 increased,
            -1 decreased.
        side_signs: tilts given per side ("R along +X, L along -X"): {"left": s, "right": s}; overrides sign.
        source: ``table_iii`` (the experts' rows) or ``ours`` (a row we added, :data:`OURS`; ranks 11 and up).
        shape: Fig. 4 type (1 for tilts; 2, 3 or 4 for swings). Our choice where Fig. 5 is not legible.
        intensity: amplitude / walker height (dimensionless, >= 0). ``THEMES`` holds our visual choice (Fig. 5 is
            a heat map); :func:`theme_features` gives the ``extended`` ones by default (sized from real data; 0
            where real actors do not move that way).
    """

    rank: int
    part: str
    axis: str
    kind: str
    sign: int
    shape: int
    intensity: float
    side_signs: dict = field(default_factory=dict)
    source: str = "table_iii"

    def __post_init__(self):
        where = f"feature {self.rank} ({self.part})"
        if self.part not in BODY_PARTS:
            raise ValueError(f"{where}: unknown body part; expected one of {sorted(BODY_PARTS)}")
        if self.axis not in AXES:
            raise ValueError(f"{where}: axis must be X, Y or Z, got {self.axis!r}")
        if self.kind not in ("tilt", "swing"):
            raise ValueError(f"{where}: kind must be 'tilt' or 'swing', got {self.kind!r}")
        if self.kind == "tilt" and self.shape != 1:
            raise ValueError(f"{where}: a tilt (posture) feature is shape 1, got {self.shape}")
        if self.kind == "swing" and self.shape not in (2, 3, 4):
            raise ValueError(f"{where}: a swing (movement) feature is shape 2, 3 or 4, got {self.shape}")
        if self.sign not in (-1, 1):
            raise ValueError(f"{where}: sign must be +1 or -1, got {self.sign}")
        if not self.intensity >= 0:
            raise ValueError(f"{where}: intensity must be a non-negative number, got {self.intensity}")
        if self.source not in ("table_iii", "ours"):
            raise ValueError(f"{where}: source must be 'table_iii' or 'ours', got {self.source!r}")
        if self.side_signs and set(self.side_signs) != {"left", "right"}:
            raise ValueError(f"{where}: side_signs needs 'left' and 'right', got {sorted(self.side_signs)}")

    @property
    def is_posture(self) -> bool:
        return self.kind == "tilt"

    def joint_signs(self) -> list[tuple[str, int]]:
        """(joint name, sign) for each joint of the body part."""
        out = []
        for joint in BODY_PARTS[self.part]:
            side = "left" if joint.startswith("left_") else "right" if joint.startswith("right_") else None
            sign = self.side_signs[side] if (self.side_signs and side) else self.sign
            out.append((joint, int(sign)))
        return out

    def describe(self) -> str:
        """Table III wording, e.g. 'Ankles: tilted, R along +X, L along -X'."""
        label = PART_LABELS[self.part]
        if self.kind == "swing":
            return f"{label}: {'increased' if self.sign > 0 else 'decreased'} swing along {self.axis}"
        if self.side_signs:
            r = "+" if self.side_signs["right"] > 0 else "-"
            l_ = "+" if self.side_signs["left"] > 0 else "-"
            return f"{label}: tilted, R along {r}{self.axis}, L along {l_}{self.axis}"
        return f"{label}: tilted along {'+' if self.sign > 0 else '-'}{self.axis}"


def _swing(rank, part, axis, shape, intensity, sign=1):
    return Feature(rank, part, axis, "swing", sign, shape, intensity)


def _tilt(rank, part, axis, sign, intensity, right=None, left=None):
    sides = {"right": right, "left": left} if right is not None else {}
    return Feature(rank, part, axis, "tilt", sign, 1, intensity, sides)


INWARD = {"right": 1, "left": -1}  # "R along +X, L along -X": towards the midline (left = +x)
OUTWARD = {"right": -1, "left": 1}  # "R along -X, L along +X"

THEMES: dict[str, tuple[Feature, ...]] = {
    "happy": (
        _swing(1, "shoulders", "Z", 4, 0.030),
        _swing(2, "wrists", "Z", 4, 0.070),  # strongest in Fig. 5
        _swing(3, "knees", "Y", 2, 0.035),
        _swing(4, "head", "X", 4, 0.012),
        _swing(5, "wrists", "X", 4, 0.030),
        _swing(6, "hip", "X", 4, 0.015),
        _swing(7, "knees", "X", 2, 0.012),
        _tilt(8, "neck", "Y", +1, 0.010),
        _tilt(9, "head", "Y", +1, 0.012),
        _tilt(10, "head", "Z", -1, 0.015),
    ),
    "sad": (
        _tilt(1, "shoulders", "Y", -1, 0.030),
        _tilt(2, "head", "Y", -1, 0.050),
        _tilt(3, "neck", "Y", -1, 0.025),
        _swing(4, "shoulders", "Z", 4, 0.020, sign=-1),
        _swing(5, "wrists", "Y", 3, 0.015, sign=-1),
        _tilt(6, "torso_u", "Y", -1, 0.015),
        _tilt(7, "head", "Z", +1, 0.055),
        _tilt(8, "neck", "Z", +1, 0.040),
        _tilt(9, "elbows", "Y", -1, 0.015),
        _tilt(10, "hip", "Y", -1, 0.015),
    ),
    "energetic": (
        _swing(1, "knees", "Y", 2, 0.040),
        _tilt(2, "head", "Y", +1, 0.015),
        _swing(3, "elbows", "X", 4, 0.025),
        _swing(4, "elbows", "Z", 4, 0.040),
        _swing(5, "shoulders", "Y", 3, 0.015),
        _swing(6, "shoulders", "Z", 4, 0.030),
        _swing(7, "wrists", "Z", 4, 0.050),
        _swing(8, "wrists", "X", 4, 0.025),
        _swing(9, "thighs", "Z", 4, 0.012),
        _swing(10, "thighs", "Y", 2, 0.012),
    ),
    "tired": (
        _tilt(1, "shoulders", "Y", -1, 0.030),
        _tilt(2, "head", "Y", -1, 0.050),
        _swing(3, "ankles", "Z", 4, 0.070, sign=-1),  # strongest in Fig. 5
        _tilt(4, "head", "Z", +1, 0.055),
        _tilt(5, "wrists", "Y", -1, 0.020),
        _swing(6, "ankles", "Y", 2, 0.020, sign=-1),
        _tilt(7, "neck", "Y", -1, 0.020),
        _tilt(8, "neck", "Z", +1, 0.030),
        _tilt(9, "torso_l", "Z", +1, 0.015),
        _tilt(10, "torso_u", "Z", +1, 0.040),
    ),
    "feminine": (
        _swing(1, "hip", "X", 4, 0.030),
        _tilt(2, "ankles", "X", +1, 0.030, **INWARD),
        _tilt(3, "knees", "X", +1, 0.025, **INWARD),
        _swing(4, "torso_l", "X", 4, 0.020),
        _tilt(5, "thighs", "X", +1, 0.012, **INWARD),
        _swing(6, "torso_u", "X", 4, 0.020),
        _swing(7, "thighs", "Y", 2, 0.015),
        _tilt(8, "shoulders", "Y", -1, 0.012),
        _swing(9, "elbows", "X", 4, 0.025),
        _swing(10, "wrists", "X", 4, 0.030),
    ),
    "masculine": (
        _swing(1, "shoulders", "Z", 4, 0.030),
        _tilt(2, "knees", "X", +1, 0.020, **OUTWARD),
        _tilt(3, "ankles", "X", +1, 0.025, **OUTWARD),
        _tilt(4, "elbows", "X", +1, 0.030, **OUTWARD),
        _swing(5, "ankles", "Y", 2, 0.070),  # strongest in Fig. 5
        _swing(6, "knees", "Y", 2, 0.030),
        _swing(7, "head", "Z", 3, 0.015),
        _swing(8, "neck", "Z", 3, 0.012),
        # Table III lists "Shoulders: increased swing along Z" twice (ranks 1 and 9). We keep both; the
        # second is a one-bump feature so the DOF stays within the paper's M <= 3 RBFs (2 + 1).
        _swing(9, "shoulders", "Z", 2, 0.015),
        _swing(10, "elbows", "Z", 4, 0.030),
    ),
}

# Table III wording, verbatim, to check the data above against (tests compare describe() to these).
TABLE_III: dict[str, tuple[str, ...]] = {
    "happy": ("Shoulders: increased swing along Z", "Wrists: increased swing along Z",
              "Knees: increased swing along Y", "Head: increased swing along X", "Wrists: increased swing along X",
              "Hip: increased swing along X", "Knees: increased swing along X", "Neck: tilted along +Y",
              "Head: tilted along +Y", "Head: tilted along -Z"),
    "sad": ("Shoulders: tilted along -Y", "Head: tilted along -Y", "Neck: tilted along -Y",
            "Shoulders: decreased swing along Z", "Wrists: decreased swing along Y", "Torso U: tilted along -Y",
            "Head: tilted along +Z", "Neck: tilted along +Z", "Elbows: tilted along -Y", "Hip: tilted along -Y"),
    "energetic": ("Knees: increased swing along Y", "Head: tilted along +Y", "Elbows: increased swing along X",
                  "Elbows: increased swing along Z", "Shoulders: increased swing along Y",
                  "Shoulders: increased swing along Z", "Wrists: increased swing along Z",
                  "Wrists: increased swing along X", "Thighs: increased swing along Z",
                  "Thighs: increased swing along Y"),
    "tired": ("Shoulders: tilted along -Y", "Head: tilted along -Y", "Ankles: decreased swing along Z",
              "Head: tilted along +Z", "Wrists: tilted along -Y", "Ankles: decreased swing along Y",
              "Neck: tilted along -Y", "Neck: tilted along +Z", "Torso L: tilted along +Z",
              "Torso U: tilted along +Z"),
    "feminine": ("Hip: increased swing along X", "Ankles: tilted, R along +X, L along -X",
                 "Knees: tilted, R along +X, L along -X", "Torso L: increased swing along X",
                 "Thighs: tilted, R along +X, L along -X", "Torso U: increased swing along X",
                 "Thighs: increased swing along Y", "Shoulders: tilted along -Y", "Elbows: increased swing along X",
                 "Wrists: increased swing along X"),
    "masculine": ("Shoulders: increased swing along Z", "Knees: tilted, R along -X, L along +X",
                  "Ankles: tilted, R along -X, L along +X", "Elbows: tilted, R along -X, L along +X",
                  "Ankles: increased swing along Y", "Knees: increased swing along Y", "Head: increased swing along Z",
                  "Neck: increased swing along Z", "Shoulders: increased swing along Z",
                  "Elbows: increased swing along Z"),
}

def _ours(rank, part, axis, kind, sign, shape=1, intensity=0.01, sides=None):
    return Feature(rank, part, axis, kind, sign, shape, intensity, dict(sides or {}), source="ours")


#: Rows of our own (``source="ours"``), not in Table III: levers the real styled walks use and the experts' ten
#: rows lack (docs/rbf.md). Used only by the ``extended`` set and only with all of a theme's features
#: (``n_features`` = 10), so the paper's first-n study (n = 1, 4, 7, 10 of Table III) is unchanged below 10.
#: Their intensities here are placeholders; the ``extended`` file sizes them from real data.
OURS: dict[str, tuple[Feature, ...]] = {
    # each row: the real style's largest differences from normal walks that no Table III row of the theme holds
    # (Bandai Namco train takes, docs/benchmarks/rbf.md); sized by the extended set like the experts' rows.
    # Energetic 15-16, tired 14-15, feminine 13-15 and masculine 13-14 were chosen by effect size d (style minus
    # normal over the between-take spread, the same sign in both datasets; generation.rbf.row_effects, the "rows"
    # section of docs/benchmarks/rbf.md); their comments give d and the real difference in walker heights
    "happy": (_ours(11, "hip", "Y", "swing", +1, 3),                    # more bounce (sized on Bandai and BML)
              _ours(12, "wrists", "Y", "tilt", +1)),                    # hands carried higher, elbows bent
    "sad": (_ours(11, "wrists", "Z", "swing", -1, 4),                   # arms barely swing
            _ours(12, "ankles", "Z", "swing", -1, 4),                   # short steps
            _ours(13, "torso_u", "Z", "tilt", +1)),                     # chest forward
    "energetic": (_ours(11, "wrists", "Y", "tilt", +1),                 # hands carried higher
                  _ours(12, "elbows", "Y", "tilt", +1),                 # forearms raised
                  _ours(13, "torso_l", "Z", "tilt", +1),                # leaning into the walk
                  _ours(14, "knees", "Z", "swing", +1, 4),              # longer knee swing
                  _ours(15, "wrists", "Y", "swing", +1, 4),             # hands pump up and down (d +3.8, 7.7 % h)
                  _ours(16, "ankles", "Y", "swing", +1, 2)),            # feet lifted higher (d +7.7, 2.3 % h)
    "tired": (_ours(11, "shoulders", "Z", "tilt", +1),                  # shoulders rounded forward
              _ours(12, "head", "X", "swing", +1, 4),                   # head sways side to side
              _ours(13, "head", "Z", "swing", +1, 3),                   # head nods with each step
              _ours(14, "wrists", "X", "tilt", +1, sides=INWARD),       # hands nearer the midline (d -4.6, 1.3 % h)
              _ours(15, "torso_u", "Z", "swing", +1, 4)),               # chest rocks fore and aft (d +3.0, 0.7 % h)
    "feminine": (_ours(11, "torso_u", "Z", "tilt", -1),                 # upright chest
                 _ours(12, "elbows", "Z", "tilt", -1),                  # elbows kept back, close to the body
                 _ours(13, "wrists", "X", "tilt", +1, sides=OUTWARD),   # hands held out from the hips (d +11, 3.3 % h)
                 _ours(14, "shoulders", "Z", "swing", +1, 4),           # shoulder line turns more (d +11, 2.1 % h)
                 _ours(15, "head", "X", "swing", +1, 4)),               # head sways side to side (d +2.9, 0.5 % h)
    "masculine": (_ours(11, "head", "Z", "tilt", +1),                   # head forward
                  _ours(12, "knees", "Z", "swing", +1, 4),              # longer knee swing
                  _ours(13, "hip", "Y", "swing", +1, 3),                # more bounce (d +2.8, 1.1 % h)
                  _ours(14, "wrists", "Y", "tilt", +1)),                # hands higher, elbows bent (d +1.9, 1.4 % h)
}

#: Named sets of intensities: ``extended`` (the default: sized from real style-vs-normal differences of Bandai
#: Namco walks, with our rows and stride and cadence levers, :mod:`generation.rbf.extended`, stored in
#: :data:`EXTENDED_PATH`),
#: ``calibrated`` (fitted so that w = 1 reproduces real actors' style differences with factors capped at 6x the
#: visual ones, :mod:`generation.rbf.calibrate`, :data:`CALIBRATED_PATH`) and ``visual`` (our choice, sized to
#: be visible in a stick figure at w = 0.7; the numbers of ``THEMES``). The first is the default. ``pooled`` is the
#: extended method with happy and sad sized from the mean over two sources (Bandai Namco dataset 1 and the BML walks
#: of Emotion-Gait, :data:`POOLED_PATH`); the other themes as ``extended``. An option: observers read it less often as
#: the theme than ``extended`` (docs/benchmarks/rbf.md).
INTENSITY_SETS = ("extended", "calibrated", "visual", "pooled")
DEFAULT_INTENSITIES = INTENSITY_SETS[0]
CALIBRATED_PATH = Path(__file__).resolve().parents[1] / "data" / "rbf" / "calibrated_intensities.json"
EXTENDED_PATH = Path(__file__).resolve().parents[1] / "data" / "rbf" / "extended_intensities.json"
POOLED_PATH = Path(__file__).resolve().parents[1] / "data" / "rbf" / "pooled_intensities.json"
#: Intensity sets sized by :mod:`generation.rbf.extended` (our rows, stride and cadence) -> their files.
EXTENDED_SETS = {"extended": EXTENDED_PATH, "pooled": POOLED_PATH}


def all_features(theme: str) -> tuple[Feature, ...]:
    """Table III's rows of ``theme`` followed by our own (:data:`OURS`)."""
    return THEMES[theme] + OURS.get(theme, ())


@lru_cache(maxsize=4)
def _extended_file(path: str) -> dict:
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"extended RBF intensities {p} not found; build them with "
                                "`python -m generation.rbf extend`")
    data = json.loads(p.read_text(encoding="utf-8"))
    for theme in THEMES:
        entry = data.get("themes", {}).get(theme, {})
        rows = entry.get("features")
        if not rows or sorted(r["rank"] for r in rows) != [f.rank for f in all_features(theme)]:
            raise ValueError(f"{p}: theme {theme!r} needs one extended intensity per rank (Table III and ours)")
        for r in rows:
            if not (isinstance(r.get("extended"), (int, float)) and r["extended"] >= 0):
                raise ValueError(f"{p}: theme {theme!r} rank {r.get('rank')}: extended intensity must be >= 0")
        tempo = entry.get("tempo", {})
        if not all(isinstance(tempo.get(k), (int, float)) for k in ("stride_per_weight", "cadence_per_weight")):
            raise ValueError(f"{p}: theme {theme!r} needs tempo.stride_per_weight and tempo.cadence_per_weight "
                             "(numbers); rebuild with `python -m generation.rbf extend`")
    return data


def extended_intensities(path: str | Path = EXTENDED_PATH) -> dict[str, dict[int, float]]:
    """{theme: {rank: extended intensity (x height)}} from the shipped file (or ``path``); ranks 11+ are ours."""
    data = _extended_file(str(path))
    return {t: {int(r["rank"]): float(r["extended"]) for r in data["themes"][t]["features"]} for t in THEMES}


def extended_stride_cadence(theme: str, path: str | Path = EXTENDED_PATH) -> tuple[float, float]:
    """Stride and cadence change per unit weight of the ``extended`` set (levers of ours), (stride, cadence):
    the real style-vs-normal stride ratio - 1 and cadence ratio - 1, each the mean over the datasets with the
    theme (train takes, :mod:`generation.rbf.extended`). With all ten features the walk's stride is scaled by
    max(0.5, 1 + w * stride) and its cadence by max(0.5, 1 + w * cadence)
    (:func:`generation.rbf.stylise.stride_cadence_scales`)."""
    if theme not in THEMES:
        raise ValueError(f"unknown theme {theme!r}; expected one of {list(THEME_NAMES)}")
    tempo = _extended_file(str(path))["themes"][theme]["tempo"]
    return float(tempo["stride_per_weight"]), float(tempo["cadence_per_weight"])


def extended_provenance(path: str | Path = EXTENDED_PATH) -> dict:
    """{licence, citation} of the real capture the extended intensities were sized on."""
    data = _extended_file(str(path))
    return {"licence": data["licence"], "citation": data["citation"]}


def extended_sources(theme: str, path: str | Path = EXTENDED_PATH) -> dict[str, str]:
    """{source: licence} of the real capture ``theme``'s rows in ``path`` were sized on: the theme's ``sized_on``
    where the file pools sources for it, else {} (the file's own licence covers it)."""
    entry = _extended_file(str(path))["themes"][theme]
    return {s["source"]: s["licence"] for s in entry.get("sized_on", [])}


@lru_cache(maxsize=4)
def _calibrated_file(path: str) -> dict:
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"calibrated RBF intensities {p} not found; build them with "
                                "`python -m generation.rbf calibrate`")
    data = json.loads(p.read_text(encoding="utf-8"))
    for theme in THEMES:
        rows = data.get("themes", {}).get(theme, {}).get("features")
        if not rows or sorted(r["rank"] for r in rows) != list(range(1, len(THEMES[theme]) + 1)):
            raise ValueError(f"{p}: theme {theme!r} needs one calibrated intensity per Table III rank")
        for r in rows:
            if not (isinstance(r.get("calibrated"), (int, float)) and r["calibrated"] >= 0):
                raise ValueError(f"{p}: theme {theme!r} rank {r.get('rank')}: calibrated intensity must be >= 0")
    return data


def calibrated_intensities(path: str | Path = CALIBRATED_PATH) -> dict[str, dict[int, float]]:
    """{theme: {Table III rank: calibrated intensity (x height)}} from the shipped file (or ``path``)."""
    data = _calibrated_file(str(path))
    return {t: {int(r["rank"]): float(r["calibrated"]) for r in data["themes"][t]["features"]} for t in THEMES}


def calibration_provenance(path: str | Path = CALIBRATED_PATH) -> dict:
    """{licence, citation} of the real capture the calibrated intensities were fitted on."""
    data = _calibrated_file(str(path))
    return {"licence": data["licence"], "citation": data["citation"]}


def theme_features(theme: str, n_features: int | None = None,
                   intensities: str | Mapping[int, float] = DEFAULT_INTENSITIES) -> tuple[Feature, ...]:
    """The first ``n_features`` (1..10, default all) features of a theme, in Table III order.

    ``intensities``: a name of :data:`INTENSITY_SETS` (``visual`` gives ``THEMES`` unchanged; ``extended`` and
    ``pooled`` add our rows, :data:`OURS`, when all ten Table III rows are asked for), or a mapping {rank: intensity}
    overriding the visual ones (ranks not named keep theirs; ranks of our rows add those rows; used by the fits).
    """
    if theme not in THEMES:
        raise ValueError(f"unknown theme {theme!r}; expected one of {list(THEME_NAMES)}")
    feats = THEMES[theme]
    ours = ()
    if isinstance(intensities, str):
        if intensities not in INTENSITY_SETS:
            raise ValueError(f"intensities must be one of {list(INTENSITY_SETS)}, got {intensities!r}")
        if intensities == "calibrated":
            feats = _with_intensities(feats, calibrated_intensities()[theme])
        elif intensities in EXTENDED_SETS:
            by_rank = extended_intensities(EXTENDED_SETS[intensities])[theme]
            feats = _with_intensities(feats, {r: v for r, v in by_rank.items() if r <= len(feats)})
            ours = _with_intensities(OURS.get(theme, ()), {r: v for r, v in by_rank.items() if r > len(feats)})
    else:
        own = {f.rank for f in OURS.get(theme, ())}
        ours = tuple(f for f in _with_intensities(OURS.get(theme, ()), {r: v for r, v in intensities.items()
                                                                         if r in own}) if f.rank in intensities)
        feats = _with_intensities(feats, {r: v for r, v in intensities.items() if r not in own})
    if n_features is None:
        return feats + ours
    if isinstance(n_features, bool) or not isinstance(n_features, int) or not 0 <= n_features <= len(feats):
        raise ValueError(f"n_features must be an integer in 0..{len(feats)}, got {n_features!r}")
    return feats[:n_features] + (ours if n_features == len(feats) else ())


def _with_intensities(feats: tuple[Feature, ...], by_rank: Mapping[int, float]) -> tuple[Feature, ...]:
    unknown = set(by_rank) - {f.rank for f in feats}
    if unknown:
        raise ValueError(f"intensities for unknown Table III ranks {sorted(unknown)}")
    return tuple(replace(f, intensity=float(by_rank[f.rank])) if f.rank in by_rank else f for f in feats)
