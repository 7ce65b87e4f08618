"""The study protocol: the one definition of the vocabularies, section types, questions' answer domains and
public CSV columns that generation, studyapp and analysis share.

Plain Python (no numpy, torch or Django), so every library can import it cheaply. Everything else derives from
these names; ``tests/test_protocol.py`` fails when a second copy of a vocabulary appears anywhere in the code.
The formats are those of DESIGN.md ("Interchange formats").

NRC-VAD rows (valence, arousal, dominance in 0..1) are copied from the NRC Valence, Arousal, and Dominance
Lexicon v1:

    Saif M. Mohammad. "Obtaining Reliable Human Ratings of Valence, Arousal, and Dominance for 20,000 English
    Words." Proceedings of ACL 2018, pages 174-184. doi:10.18653/v1/P18-1017. Free for research and
    non-commercial use; cite the paper when using it.
"""
from __future__ import annotations

from .section_types.registry import NamesView, TypeMapView

# ---- vocabularies ----------------------------------------------------------------------------------------
GAIT_EMOTIONS = ("happy", "sad", "angry", "neutral")
"""Components of seed 000's gait emotion vector, in column order (clips.csv, the network's input)."""

THEMES = ("happy", "sad", "energetic", "tired", "feminine", "masculine")
"""Seed 004's style themes (Table III)."""

OPPOSITE_THEME = {"happy": "sad", "sad": "happy", "energetic": "tired", "tired": "energetic",
                  "feminine": "masculine", "masculine": "feminine"}
"""Each theme's opposite: what a negative RBF weight should look like (seed 004 section 5.3)."""

NEUTRAL_THEME = "neutral"
"""The theme of seed 004's unstyled input walk (weight 0) in clips.csv."""

CLIP_THEMES = (*THEMES, NEUTRAL_THEME)
"""Values the ``theme`` column of clips.csv may take."""

NEUTRAL_CHOICES = (NEUTRAL_THEME, *THEMES)
"""The 7-way forced choice of seed 004's neutral validation (Table I)."""

CAPTURE_GAIT_EMOTIONS = {"happy": "happy", "sad": "sad", "angry": "angry", "normal": "neutral"}
"""Style names of captured motion (the Bandai Namco Research Motion Dataset, Kobayashi et al. 2023,
arXiv:2306.08861) -> seed 000's gait emotions: dataset 1's happy, sad, angry and normal (= neutral)."""

CAPTURE_THEMES = {"happy": "happy", "sad": "sad", "active": "energetic", "tired": "tired", "exhausted": "tired",
                  "feminine": "feminine", "masculinity": "masculine", "masculine": "masculine"}
"""Style names of captured motion -> seed 004's themes: active is energetic, tired (dataset 1) and exhausted
(dataset 2) are tired, masculinity (dataset 1) and masculine (dataset 2) are masculine."""


def capture_label(style: str) -> str:
    """A captured style's label in the study vocabulary: its gait emotion (normal -> neutral), else its theme
    (active -> energetic, exhausted -> tired, masculinity -> masculine), else the style's own name."""
    return CAPTURE_GAIT_EMOTIONS.get(style) or CAPTURE_THEMES.get(style) or style


CAPTURE_GESTURE_EMOTIONS = {"happy": "joyous", "sad": "sad", "angry": "angry", "proud": "proud", "normal": "neutral"}
"""Style names of captured gestures (Bandai Namco dataset 1's bow, bye, byebye, guide, respond) -> seed 003's gesture
emotions (GESTURE_EMOTIONS), where the style names the same emotion: happy is joyous (the MPI category of happiness),
sad, angry and proud are themselves, normal (the actor's plain performance) is neutral. ``not-confident`` is not
mapped to ashamed: it names a lack of self-assurance (hesitant, withdrawn movement), not shame, the self-conscious
emotion about a wrong done, and the dataset's labels describe a performance style, not a felt emotion; it keeps its
own name. The other styles (tired, active, feminine, childish, ...) are not emotions of GESTURE_EMOTIONS."""


def capture_gesture_emotion(style: str) -> str | None:
    """The gesture emotion a captured style shows (CAPTURE_GESTURE_EMOTIONS), or None where none is honest."""
    return CAPTURE_GESTURE_EMOTIONS.get(style)


GESTURE_VAD: dict[str, tuple[float, float, float]] = {
    "afraid": (0.010, 0.775, 0.245),
    "amused": (0.942, 0.847, 0.596),
    "angry": (0.122, 0.830, 0.604),
    "ashamed": (0.156, 0.588, 0.228),
    "disgusted": (0.051, 0.773, 0.274),
    "joyous": (0.958, 0.580, 0.728),
    "neutral": (0.469, 0.184, 0.357),
    "proud": (0.906, 0.700, 0.873),
    "relieved": (0.896, 0.314, 0.391),
    "sad": (0.225, 0.333, 0.149),
    "surprised": (0.784, 0.855, 0.539),
}
"""The 11 categories of the MPI Emotional Body Expressions database (seed 003 section 6.1) -> NRC-VAD
(valence, arousal, dominance), each in 0..1."""

GESTURE_EMOTIONS = tuple(GESTURE_VAD)
"""Seed 003's gesture emotion categories, alphabetical."""

VAD_DIMENSIONS = ("valence", "arousal", "dominance")

GENDERS = ("female", "male")
"""Body builds of the skeletons and agents, in the order of the gesture network's one-hot attribute."""

HANDEDNESS = ("left", "right")

GESTURE_TASKS = ("narration", "conversation")
"""Seed 003's speaking tasks: a gesture accompanies a narration or a conversation."""

MODALITIES = ("gait", "gesture")
"""The two motion skeletons and the modality of generated and captured clips."""

OTHER_MODALITY = "other"
"""``modality`` of an imported video that is neither a walk nor a gesture (a face, a scene): shown only in sections
that take either modality (``SECTION_MODALITY`` None, i.e. naturalness)."""

CLIP_MODALITIES = (*MODALITIES, OTHER_MODALITY)
"""Values the ``modality`` column of clips.csv may take."""

IMPORTED = "imported"
ORIGINS = ("generated", "source", IMPORTED)
"""``origin`` of a clip: made by a generator, the source motion a generator started from, or a researcher's own
stimulus brought in with ``manage.py import_clips`` (a video or motion file made elsewhere)."""

# ---- sections and their answers ----------------------------------------------------------------------
SECTION_TYPES = NamesView()
"""The registered section types (protocol.section_types), in registration order: a live, read-only tuple-like view
of the registry."""

LIKERT_FEATURES = ("torso", "arms", "pace", "flow")
"""Seed 000 Table 2's broad pose affective features, each rated 0..4."""

LIKERT_LEVELS = {
    "torso": ("Torso", ("contracted, bowed", "somewhat contracted", "neither contracted nor expanded",
                        "somewhat expanded", "expanded, stretched")),
    "arms": ("Arms", ("contracted, close to the body", "somewhat contracted", "neither contracted nor expanded",
                      "somewhat expanded", "expanded, away from the body")),
    "pace": ("Gait pace", ("sustained, leisurely, slow", "somewhat sustained", "neither sustained nor hurried",
                           "somewhat hurried", "hurried, sudden, fast")),
    "flow": ("Gait flow", ("free, relaxed, uncontrolled", "somewhat free", "neither free nor bound",
                           "somewhat bound", "bound, tense, controlled")),
}
"""Seed 000 Table 2, verbatim: feature -> (label, the wording of values 0..4)."""

# How the `answer` cell of responses.csv is written for each answer kind.
GAIT_MULTI = "gait_multi"          # gait emotion labels joined by ';'
LIKERT = "likert"                  # integer 0..4
NATURALNESS = "naturalness"        # integer 1..5
GESTURE_CHOICE = "gesture_choice"  # one gesture emotion category
NEUTRAL_CHOICE = "neutral_choice"  # neutral or one of the six themes
THEME_RATING = "theme_rating"      # integer 1..7
INVERSION = "inversion"            # integer -7..7
INTENSITY = "intensity"            # integer 1..5

INTEGER_RANGES = {LIKERT: (0, 4), NATURALNESS: (1, 5), THEME_RATING: (1, 7), INVERSION: (-7, 7), INTENSITY: (1, 5)}
"""Answer kind -> (lowest, highest) integer, inclusive."""

LABEL_CHOICES = {GAIT_MULTI: GAIT_EMOTIONS, GESTURE_CHOICE: GESTURE_EMOTIONS, NEUTRAL_CHOICE: NEUTRAL_CHOICES}
"""Answer kind -> the labels it may use."""

MULTI_SELECT_KINDS = (GAIT_MULTI,)
"""Answer kinds where several labels may be chosen (joined by ';' in the protocol's order)."""

SECTION_QUESTIONS = TypeMapView(lambda t: t.question_kinds)
"""section_type -> question key -> answer kind: exactly what the study app writes and the analysis reads (a live view
of the section-type registry)."""

SECTION_MODALITY = TypeMapView(lambda t: t.modality)
"""The modality of the clips each section shows (None: either); a live view of the registry."""


NORMING_SECTION_TYPES = NamesView(lambda t: t.norming)
"""Sections a norming study rates its candidate clips in: the emotion question of each modality (gait walks,
gestures, RBF theme clips); the registered types declared ``norming``."""

NORMING_QUESTIONS = {"intensity": INTENSITY, "naturalness": NATURALNESS}
"""Questions a norming section (``Section.options["norming"]``) asks about each clip after its own: how intense the
perceived emotion is (1 "very weak" .. 5 "very strong") and the naturalness scale (1..5). Stored in responses.csv
under the section's own section_type with these question keys."""

ANSWER_QUESTIONS = TypeMapView(lambda t: {**t.question_kinds, **(NORMING_QUESTIONS if t.norming else {})})
"""section_type -> every question key responses.csv may hold for it -> answer kind: SECTION_QUESTIONS plus the
norming questions of NORMING_SECTION_TYPES."""


def section_questions(section_type: str, norming: bool = False) -> dict[str, str]:
    """The question keys (-> answer kind) one clip page of ``section_type`` asks: its own, then the norming
    questions when the section is a norming one."""
    questions = dict(SECTION_QUESTIONS[section_type])
    if norming and section_type in NORMING_SECTION_TYPES:
        questions.update(NORMING_QUESTIONS)
    return questions


def register_answer_kind(kind: str, *, scale: tuple[int, int] | None = None,
                         labels: tuple[str, ...] | None = None) -> str:
    """Add an answer kind a new section type asks: an integer ``scale`` (lowest, highest) or a set of ``labels``
    (exactly one of them); returns ``kind``. ValueError when the kind exists with another domain or the domain is
    empty."""
    if (scale is None) == (labels is None):
        raise ValueError(f"answer kind {kind!r}: give a scale or labels")
    if scale is not None and not (len(scale) == 2 and isinstance(scale[0], int) and isinstance(scale[1], int)
                                  and scale[0] < scale[1]):
        raise ValueError(f"answer kind {kind!r}: the scale must be (lowest, highest) integers, got {scale!r}")
    if labels is not None and (not labels or len(set(labels)) != len(labels)):
        raise ValueError(f"answer kind {kind!r}: give distinct labels")
    table, domain = (INTEGER_RANGES, tuple(scale)) if scale is not None else (LABEL_CHOICES, tuple(labels))
    other = INTEGER_RANGES if table is LABEL_CHOICES else LABEL_CHOICES
    if kind in other or table.get(kind, domain) != domain:
        raise ValueError(f"answer kind {kind!r} exists already with another domain")
    table[kind] = domain
    return kind


def unregister_answer_kind(kind: str) -> None:
    """Remove an answer kind (tests that register toy section types clean up with this)."""
    INTEGER_RANGES.pop(kind, None)
    LABEL_CHOICES.pop(kind, None)


def answer_values(kind: str) -> tuple[str, ...]:
    """Every value one answer of ``kind`` may take, as the strings stored in responses.csv."""
    if kind in INTEGER_RANGES:
        lo, hi = INTEGER_RANGES[kind]
        return tuple(str(v) for v in range(lo, hi + 1))
    return LABEL_CHOICES[kind]


# ---- public CSV columns (DESIGN.md) --------------------------------------------------------------------
FINAL_EMOTION_COLUMNS = tuple(f"final_{e}" for e in GAIT_EMOTIONS)

CLIP_COLUMNS = ("clip_id", "modality", "origin", *GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, "emotion_label",
                *VAD_DIMENSIONS, "theme", "weight", "n_features", "duration_s")
"""clips.csv, in order. Readers ignore extra columns after these."""

CLIP_PROVENANCE_COLUMNS = ("title", "licence", "citation")
"""Optional extra columns of clips.csv after the quality columns: a clip's title and the licence and citation of
what it was made from (imported files, captured data)."""

CLIP_BODY_COLUMNS = ("body",)
"""Optional extra column of clips.csv after the provenance columns: the human body preset the clip shows
(``generation/data/bodies/<preset>.npz``; blank for the mannequin, stick and point-light looks). The clip's record
keeps the body's parameters, licence and citation (``record["body"]``)."""
BODY_MAX_LENGTH = 60
"""The longest body preset name a clip record may carry (characters)."""


CLIP_FLOAT_COLUMNS = (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, *VAD_DIMENSIONS, "weight", "duration_s")
CLIP_INT_COLUMNS = ("n_features",)

# ---- per-clip quality record: optional extra columns of clips.csv after CLIP_COLUMNS -------------------------
QA_CHECKS = ("foot_skate", "penetration", "jerk", "bone_error", "figure_height", "observer", "realism")
"""Quality checks; a clip's ``qa_flag`` joins the names of those it failed with ';' (empty = passed)."""

QA_ADVISORY_CHECKS = ("realism",)
"""Checks that flag a clip for the researcher without keeping it out of study pools. ``realism`` compares a clip's
foot skate, toe skimming, stance knee, pelvis bounce and speed variability with the real corpus's 1st-99th
percentiles over whole takes: it also flags 10 % of held-out real takes and some real source clips cut to the render
length, so it informs (the admin's quality filter, clips.csv) rather than excludes."""

QA_REALISM_COLUMNS = ("qa_skate_cm_s", "qa_skate_ratio", "qa_toe_skim", "qa_stance_knee_deg", "qa_pelvis_bounce_cm",
                      "qa_speed_cv")
"""Realism measures of gait clips (generation/quality/realism.py): foot speed near the floor (cm/s), GMD's
foot-skating ratio, toe-skim share, stance knee flexion (degrees), pelvis bounce (cm), walking-speed variability."""

QA_COLUMNS = ("qa_foot_skate_cm_s", "qa_penetration_cm", "qa_jerk", "qa_bone_error_mm", "qa_figure_height_frac",
              "qa_observed", "qa_observed_p", "qa_flag", *QA_REALISM_COLUMNS, "qa_observer")
"""The quality columns of clips.csv, in order, after CLIP_COLUMNS (old files without them, or without the realism
columns and ``qa_observer`` that follow ``qa_flag``, still read: missing cells are blank). ``qa_observer`` names the
observer behind ``qa_observed``: ``real`` (trained on real capture), ``synthetic`` or ``synthetic-gesture``."""

QA_FLOAT_COLUMNS = ("qa_foot_skate_cm_s", "qa_penetration_cm", "qa_jerk", "qa_bone_error_mm", "qa_figure_height_frac",
                    "qa_observed_p", *QA_REALISM_COLUMNS)

QA_OBSERVERS = ("real", "real-perceived", "synthetic")
"""Which gait observer fills ``qa_observed`` (plan ``qa: {observer: ...}``, env ``QA_GAIT_OBSERVER``): ``real``, a
classifier trained on real captured walks with the actors' acted labels (the default: calibrated on both real
corpora, generation/quality/calibrated_observer.py, trained when both are built, else its fitted parameters shipped in
generation/data/observers/; without those, generation/quality/real_observer.py),
``real-perceived``, the calibrated one with the BML annotators' perceived labels, or ``synthetic``, trained on the
procedural corpus (generation/quality/observer.py)."""

QA_THRESHOLDS = {
    "foot_skate_cm_s": 10.0,         # max mean foot slide in contact (corpus walks 2.2-2.6, raw network 15-30)
    "penetration_cm": 1.0,           # max depth of a foot joint below the floor
    "jerk": 600.0,                   # max mean joint jerk, m/s^3 (walks 70-400 at 30 fps; 5 mm jitter adds ~600)
    "bone_error_mm": 1.0,            # max bone length deviation
    "figure_height_frac_walk": 0.50,    # min figure height / frame height in every frame (walks)
    "figure_height_frac_seated": 0.60,  # the same for seated gestures
    "observer_mismatch_p": 0.90,     # flag a gait whose synthetic observer names another emotion with this p
    "observer_mismatch_p_real": 0.40,  # the same for the real-capture observer (its right reads: p 0.44-0.80)
    "gesture_arousal_gap": 0.30,     # flag a gesture whose observer's arousal is this far from the intended one's
}
"""Default thresholds of the quality checks; a plan's ``qa:`` block overrides them by key (null disables one).

``gesture_arousal_gap``: the ``observer`` check of a gesture clip fails when the arousal the synthetic gesture
observer reads (generation/quality/gesture_observer.py: the NRC-VAD arousal of the 11 emotions weighted by its
probabilities) is at least this far from the NRC-VAD arousal (0..1) of the clip's intended ``emotion_label``. On
held-out generated gestures 0.30 flagged none of 363 honest clips and 93 % of clips labelled with an emotion whose
arousal differs by 0.3 or more (docs/benchmarks/motion_quality.md, "Gesture observer").

``observer_mismatch_p_real``: the real-capture gait observer (generation/quality/real_observer.py) is less sure of
itself than the synthetic one: on held-out real takes its top probability was 0.44-0.80 when right and 0.52 when
wrong (4 classes, chance 0.25), so a gait it reads as another emotion with p >= 0.40 is flagged
(docs/benchmarks/mocap.md, "Real-capture gait observer").

The ``realism`` check's bounds (``<measure>_min`` / ``<measure>_max``, e.g. ``stance_knee_deg_max``) are the real
corpus's own ranges, kept in generation/quality/realism_ranges.json; generation.quality.checks.resolve_thresholds
adds them to these, and a plan's ``qa:`` block overrides them the same way."""

RESPONSE_COLUMNS = ("participant_id", "section_type", "clip_id", "question", "answer", "response_ms")
"""responses.csv, in order: one row per answer."""

ATTENTION_CHECK = "attention_check"
"""The ``section_type`` of an attention-check answer in responses.csv (an instructed-response item placed in a
clip section). Its ``question`` is ``attention_question(key, instructed)``: the section's question key and the
answer the participant was told to give, e.g. ``perceived=sad``; it passed when the answer equals that."""

ATTENTION_COLUMNS = ("attention_passed", "attention_total")
"""participants.csv: attention checks the participant passed, and answered in all."""


def attention_question(key: str, instructed: str) -> str:
    """The ``question`` cell of an attention-check answer: ``<question key>=<instructed answer>``."""
    return f"{key}={instructed}"


def attention_passed(question: str, answer: str) -> bool:
    """Whether an attention-check answer (responses.csv ``question``, ``answer``) is the instructed one."""
    return question.partition("=")[2] == answer


PARTICIPANT_COLUMNS = ("participant_id", "gender", "age_group", "started_at", "completed_at", "status",
                       "external_id", *ATTENTION_COLUMNS, "section_order")
"""participants.csv, in order (feedback columns follow). ``section_order``: the ``order`` numbers of the sections
in the order this participant took them, joined by ';' (counterbalanced studies differ per participant)."""

ASSIGNMENT_COLUMNS = ("participant_id", "section_type", "section_order", "position", "clip_id", "options",
                      "shown_at", "answered_at")
"""assignments.csv (an extra export): which clips each participant was given, in order."""

CLIP_NORMS_COLUMNS = ("clip_id", "modality", "section_type", "question", "n_ratings", "intended", "top_label",
                      "top_share", "intended_share", "intended_ci_low", "intended_ci_high", "entropy_bits",
                      "ad_statistic", "ad_p_value", "intensity_mean", "naturalness_mean", "naturalness_n")
"""clip_norms.csv (analysis.norms), in order: one row per clip and question; then one ``share_<label>`` column per
label of the question domains present (NORMS_SHARE_PREFIX). Readers ignore columns they do not know."""
NORMS_SHARE_PREFIX = "share_"


def norms_domain(section_type: str, question: str) -> tuple[str, ...]:
    """The labels a clip's perceived shares are taken over for one (section_type, question): the choices of a label
    question, the points of a scale (theme_rating 1..7)."""
    return answer_values(SECTION_QUESTIONS[section_type][question])


VIEWING_TIME_FIELDS = ("first_play_ms", "ended_ms", "stall_ms", "startup_ms", "hidden_ms")
"""Viewing-record times in milliseconds: from the clip page's display to the clip's first playing frame and to its
first end (blank: never played / never reached its end), the total time playback waited for data after its first
frame, the start-up time (from the first request to play to the first frame: buffering before the first frame is
start-up, not a stall) and the total time the page was hidden while the clip played or was held by the hiding."""
VIEWING_COUNT_FIELDS = ("plays", "pauses", "seeks", "stalls", "hidden")
"""Viewing-record counts: plays from the start (the first play and every replay, over every display of the page,
reloads included), pauses by the participant (not those the browser makes when the page is hidden), seek attempts
(blocked or not), stalls (playback waiting for data after the first frame) and times the page was hidden (another
tab, a minimised window) while the clip was playing."""
VIEWING_FIELDS = ("first_play_ms", "ended_ms", "plays", "pauses", "seeks", "stalls", "stall_ms", "hidden",
                  "startup_ms", "hidden_ms")
"""The fields of a viewing record the browser measures, in viewing.csv's order (the first eight are the original
columns; later ones are appended, never inserted)."""
VIEWING_RECORDS = ("ok", "missing", "no_script", "implausible")
"""What the server makes of an answer's viewing record (viewing.csv ``record``): ``ok``: the player's script sent
it and it is plausible; ``missing``: the answer came without the record fields although the page ships the player
(not from the page: a script, a forged or replayed POST); ``no_script``: the page's fields came back but the
player's script never ran (a browser without JavaScript); ``implausible``: sent, but impossible for the time the
page was shown (e.g. more plays than the clip's duration fits into), so not to be trusted."""
VIEWING_SERVER_FIELDS = ("record", "page_ms", "shows")
"""Viewing-record fields the server sets: ``record`` (one of VIEWING_RECORDS), ``page_ms`` (ms from the page's first
display to the answer, measured by the server) and ``shows`` (how often the page was displayed: 1 + reloads)."""
VIEWING_COLUMNS_V1 = ("participant_id", "clip_id", "section_type", *VIEWING_FIELDS[:8])
"""The columns of the first viewing.csv version: every reader requires these; the later ones may be absent."""
VIEWING_COLUMNS = ("participant_id", "clip_id", "section_type", *VIEWING_FIELDS, *VIEWING_SERVER_FIELDS)
"""viewing.csv, in order: one row per answered clip page (practice items left out). ``record`` says what the server
made of it; with ``missing`` or ``no_script`` every browser field is blank."""

PAGE_COLUMNS = ("participant_id", "page", "section_type", "section_order", "shown_at", "continued_at", "seconds")
"""pages.csv, in order: one row per instruction or break page a participant was given (protocol.section_types.pages):
its number among the participant's pages (1-based, in the order taken), its type and section order number, when it
was first shown and when the participant continued (blank: not yet), and the seconds between the two."""
