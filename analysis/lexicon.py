"""Emotion vocabularies and the NRC-VAD rows used by the studies.

NRC-VAD values (valence, arousal, dominance in 0..1) for the 11 categories of the MPI Emotional Body Expressions
database plus ``neutral``, copied from the NRC Valence, Arousal, and Dominance Lexicon:

    Saif M. Mohammad. "Obtaining Reliable Human Ratings of Valence, Arousal, and Dominance for 20,000 English
    Words." Proceedings of ACL 2018. Free for research and non-commercial use.
"""

GAIT_EMOTIONS = ("happy", "sad", "angry", "neutral")
"""Components of the seed-000 gait emotion vector, in column order."""

THEMES = ("happy", "sad", "energetic", "tired", "feminine", "masculine")
"""Seed-004 style themes."""

NEUTRAL_CHOICES = ("neutral",) + THEMES
"""The 7-way forced choice of the seed-004 neutral validation (Table I)."""

LIKERT_FEATURES = ("torso", "arms", "pace", "flow")
"""Seed-000 Table 2 broad pose affective features, rated 0..4."""

VAD_DIMENSIONS = ("valence", "arousal", "dominance")

NRC_VAD = {
    "afraid": (0.010, 0.775, 0.245),
    "amused": (0.942, 0.847, 0.596),
    "angry": (0.122, 0.830, 0.604),
    "ashamed": (0.156, 0.588, 0.228),
    "disgusted": (0.051, 0.773, 0.274),
    "happy": (1.000, 0.735, 0.772),
    "joyous": (0.958, 0.580, 0.728),
    "neutral": (0.469, 0.184, 0.357),
    "proud": (0.906, 0.700, 0.873),
    "relieved": (0.896, 0.314, 0.391),
    "sad": (0.225, 0.333, 0.149),
    "surprised": (0.784, 0.855, 0.539),
}
"""word -> (valence, arousal, dominance), each in 0..1."""

GESTURE_EMOTIONS = tuple(NRC_VAD)
