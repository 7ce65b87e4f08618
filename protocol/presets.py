"""Study presets as plain data: one per paper's web study, and a demo with every section type. No Django.

``studyapp.staff.presets`` turns a preset into Study + Section rows (the researcher then edits them in the admin); the
synthetic-study simulator (``analysis.design``) reads the same sections to simulate a study of that preset. Each
section: ``section_type``, ``name`` (the researchers' name for it, never shown to participants), ``title`` and
``instructions`` (what participants see: plain words, never the researchers' terms such as "theme" or "inversion"),
``pool`` (catalogue filters, see ``protocol.pools``),
``clips_per_participant`` (0 = every clip of the pool), ``options`` (type-specific), or ``reuse`` (the index of an
earlier section of the same preset whose clips it shows again).
"""
from __future__ import annotations

from .vocabulary import NEUTRAL_THEME

# Seed 000 section 6.3.4 anchors and seed 003 Table 2 markers (1..5), verbatim. studyapp.questions marks the same
# strings for translation (a test keeps the two equal); the study pages show them in the participant's language.
NATURALNESS_ANCHORS_GAIT = {"1": "not natural at all", "3": "satisfactory", "5": "very natural"}
NATURALNESS_ANCHORS_GESTURE = {
    "1": "Very Unnatural (e.g. broken arms or legs, torso at an impossible angle)",
    "2": "Not Realistic (e.g. limbs going inside the body or through the chair)",
    "3": "Looks OK (no serious problems, but does not look very appealing)",
    "4": "Looks good (no problems and the gestures look natural)",
    "5": "Looks great! (the gestures look like they could be from a real person)",
}

CONSENT = (
    "You are invited to take part in a research study on how people perceive the body motion of animated virtual "
    "characters. You will watch short silent clips of a virtual character and answer a few questions about each. "
    "Taking part is voluntary; you may stop at any time by closing the page. We record your answers, the time you "
    "take to answer, your gender and age group; no name, e-mail or other identifying information is collected. "
    "The anonymous answers will be analysed and may be published."
)

GAIT_GENERATED = {"modality": "gait", "origin": "generated", "transition": False, "rbf": False}
GAIT_TRANSITION = {"modality": "gait", "origin": "generated", "transition": True}

PRESETS: dict[str, dict] = {
    "gait_ismar2020": {
        "title": "Emotive gaits (ISMAR 2020 study)",
        "introduction": "The study has four sections. Each clip shows a virtual character walking.",
        "feedback_questions": [
            {"key": "distracted_camera", "text": "Were you distracted by the camera during the study?",
             "kind": "yesno"},
            {"key": "comments", "text": "Any other comments (optional)?", "kind": "text"},
        ],
        "sections": [
            # seed 000 section 6.1: "report the emotion they perceived ... Users could report multiple emotions"
            {"section_type": "emotion_choice", "name": "Section 1: perceived emotion (seed 000 6.1)",
             "title": "Which emotions do you see?",
             "instructions": "Watch each walk and choose the emotion(s) you see in it. You can choose more than one: "
                             "for example, a walk that looks a little happy but mostly neutral can be marked both "
                             "happy and neutral.",
             "pool": GAIT_GENERATED, "clips_per_participant": 8},
            # seed 000 section 6.1: "report the initial and the final emotions they perceived"
            {"section_type": "emotion_transition", "name": "Section 2: emotion transitions (seed 000 6.1)",
             "title": "Emotions that change",
             "instructions": "In these walks the emotion changes during the clip. Choose the emotion(s) you see at "
                             "the start and at the end.",
             "pool": GAIT_TRANSITION, "clips_per_participant": 6},
            # seed 000 section 6.1 and Table 2: the four pose affective features on a five-point scale
            {"section_type": "affect_likert", "name": "Section 3: pose affective features (seed 000 Table 2)",
             "title": "Posture and movement",
             "instructions": "You will see the walks of the first section again. Rate the torso, the arms, the pace "
                             "and the flow of each walk.",
             "reuse": 0},
            # seed 000 section 6.3.4: "how natural and smooth they felt the animations to be"
            {"section_type": "naturalness", "name": "Naturalness, generated and source (seed 000 6.3.4)",
             "title": "How natural the walks look",
             "instructions": "Rate how natural and smooth each animation looks, from 1 (not natural at all) through "
                             "3 (satisfactory) to 5 (very natural).",
             "pool": {"modality": "gait", "transition": False, "rbf": False}, "clips_per_participant": 4,
             "options": {"anchors": NATURALNESS_ANCHORS_GAIT, "n_generated": 2, "n_source": 2}},
        ],
    },
    "gestures_ieeevr2021": {
        "title": "Emotive gestures (IEEE VR 2021 study)",
        "introduction": "The study has two sections. Each clip shows a virtual character sitting on a chair and "
                        "gesturing.",
        "feedback_questions": [
            {"key": "distracted_no_face", "text": "Were you distracted by the lack of facial expressions?",
             "kind": "yesno"},
            {"key": "unable_gestures_only", "text": "Were you unable to determine the emotions from the gestures "
                                                    "alone?", "kind": "yesno"},
        ],
        "sections": [
            {"section_type": "gesture_emotion", "name": "Section 1: perceived emotion (seed 003 6.1)",
             "title": "Which emotion do the gestures show?",
             "instructions": "Watch each clip and choose the emotion you see in the gestures.",
             "pool": {"modality": "gesture", "origin": "generated"}, "clips_per_participant": 6,
             "options": {"n_options": 4}},
            # seed 003 Table 2: the five markers, from "Very Unnatural" to "Looks great!"
            {"section_type": "naturalness", "name": "Section 2: plausibility of the gestures (seed 003 Table 2)",
             "title": "How natural the gestures look",
             "instructions": "Rate how natural the gestures in each clip look.",
             "pool": {"modality": "gesture"}, "clips_per_participant": 6,
             "options": {"anchors": NATURALNESS_ANCHORS_GESTURE, "n_generated": 3, "n_source": 3,
                         "question": "How natural do the gestures look?"}},
        ],
    },
    "rbf_thms2016": {
        "title": "Expert RBF style features (THMS 2016 study)",
        "introduction": "Each clip shows a virtual character walking. You will rate the style of each walk.",
        "feedback_questions": [],
        "sections": [
            # seed 004 section V-A: the input walk validated as neutral, forced choice among neutral and the themes
            {"section_type": "neutral_validation", "name": "Neutral validation of the input walk (seed 004 V-A)",
             "title": "Describe the walk",
             "instructions": "Choose the word that best describes the walk.",
             "pool": {"modality": "gait", "theme": NEUTRAL_THEME}, "clips_per_participant": 1},
            # seed 004 section V: "rate the amount of affect or style in the displayed sequences", seven points
            {"section_type": "theme_rating", "name": "Theme ratings, weight x number of features (seed 004 V)",
             "title": "Walking styles",
             "instructions": "Rate how much of the style named in the question you see in each walk, from 1 (not at "
                             "all) to 7 (very).",
             "pool": {"rbf": True, "weight__gt": 0}, "clips_per_participant": 0, "loop": True},
            # seed 004 section V-E: -7 the maximum opposite theme, 0 neutral, +7 the maximum original theme; the
            # question names the two styles (the opposite first), so the ends read "very sad" ... "very happy"
            {"section_type": "theme_inversion", "name": "Inversion, w = -0.7 (seed 004 V-E)",
             "title": "Walking styles: one or the other",
             "instructions": "Each walk may look like one of two opposite styles. Rate it from -7 (very much the "
                             "first style named) through 0 (neither) to +7 (very much the second).",
             "pool": {"rbf": True, "weight__lt": 0}, "clips_per_participant": 0, "loop": True},
        ],
    },
}

# The demo: every section type with a few clips each (seed 000, 003 and 004 procedures, shortened).
PRESETS["demo"] = {
    "title": "Demo study: emotive motion of virtual characters",
    "introduction": "A short demonstration with every kind of question. Each clip is a few seconds long.",
    "feedback_questions": [
        {"key": "distracted_camera", "text": "Were you distracted by the camera during the study?", "kind": "yesno"},
        {"key": "distracted_no_face", "text": "Were you distracted by the lack of facial expressions?",
         "kind": "yesno"},
        {"key": "comments", "text": "Any other comments (optional)?", "kind": "text"},
    ],
    "sections": [
        dict(PRESETS["gait_ismar2020"]["sections"][0], clips_per_participant=2),
        dict(PRESETS["gait_ismar2020"]["sections"][1], clips_per_participant=1),
        dict(PRESETS["gait_ismar2020"]["sections"][2],
             instructions="You will see the walks of the first section again. Rate the torso, the arms, the pace "
                          "and the flow of each walk."),
        dict(PRESETS["gait_ismar2020"]["sections"][3], clips_per_participant=2,
             options={"anchors": NATURALNESS_ANCHORS_GAIT, "n_generated": 1, "n_source": 1}),
        # one gesture here leaves the demo plan's other generated gestures for the naturalness mix below; the pool
        # takes every gesture meant for this section, the real captured ones included (seed 003 showed generated
        # gestures only; the demo shows that real ones can be asked about too)
        dict(PRESETS["gestures_ieeevr2021"]["sections"][0], clips_per_participant=1,
             pool={"modality": "gesture", "sections__contains": "gesture_emotion"}),
        dict(PRESETS["gestures_ieeevr2021"]["sections"][1], clips_per_participant=2,
             options=dict(PRESETS["gestures_ieeevr2021"]["sections"][1]["options"], n_generated=1, n_source=1)),
        dict(PRESETS["rbf_thms2016"]["sections"][0]),
        dict(PRESETS["rbf_thms2016"]["sections"][1], clips_per_participant=2),
        dict(PRESETS["rbf_thms2016"]["sections"][2], clips_per_participant=1),
    ],
}


for _sec in PRESETS["demo"]["sections"]:       # the demo mixes the papers' sections: drop their "Section N:" prefixes
    _sec["name"] = _sec["name"].split(": ", 1)[-1]
PRESETS["demo"]["sections"][0]["title"] = "Emotions in walks"
PRESETS["demo"]["sections"][4]["title"] = "Emotions in gestures"


# Norming: every candidate clip of a plan rated by at least K participants while each sees M clips per section (the
# cyclic balanced incomplete design of protocol.norming); the modality's emotion question, then intensity and
# naturalness (protocol.vocabulary.NORMING_QUESTIONS). Set the participant limit to the planned N before opening: the
# admin shows K, M and the N needed, and refuses to open a study whose N cannot give K.
NORMING_RATINGS_PER_CLIP = 20
_NORMING = {"norming": {"ratings_per_clip": NORMING_RATINGS_PER_CLIP}, "practice": True}
# people are the judge of the candidates: the automatic observer's flag keeps none out (other failed checks do)
_CANDIDATES = {"observer_advisory": True}
PRESETS["norming"] = {
    "title": "Norming the stimuli: how each clip is perceived",
    "introduction": "Each clip shows a virtual character walking or gesturing. For every clip, tell us which emotion "
                    "you perceive, how strong it is, and how natural the motion looks. There are no right or wrong "
                    "answers.",
    "feedback_questions": [{"key": "comments", "text": "Any other comments (optional)?", "kind": "text"}],
    "sections": [
        {"section_type": "emotion_choice", "name": "Norming: walks", "title": "Walks",
         "instructions": "Watch each walk. Choose the emotion(s) you see (more than one is allowed), how "
                         "intense it looks and how natural the motion looks.",
         "pool": {"modality": "gait", "transition": False, "rbf": False, **_CANDIDATES}, "clips_per_participant": 8,
         "options": {**_NORMING, "attention_checks": {"count": 1, "answer": "sad", "positions": "random"}}},
        {"section_type": "gesture_emotion", "name": "Norming: gestures", "title": "Gestures",
         "instructions": "Watch each clip. Choose the emotion you see in the gestures, how intense it looks "
                         "and how natural the gestures look.",
         "pool": {"modality": "gesture", **_CANDIDATES}, "clips_per_participant": 8,
         "options": {**_NORMING, "n_options": 4,
                     "attention_checks": {"count": 1, "answer": "sad", "positions": "random"}}},
        {"section_type": "theme_rating", "name": "Norming: walking styles", "title": "Walking styles",
         "instructions": "Rate the amount of the named style in each walk, how intense the style looks and how "
                         "natural the motion looks.",
         "pool": {"rbf": True, "weight__gt": 0, **_CANDIDATES}, "clips_per_participant": 8, "loop": True,
         "options": {**_NORMING, "attention_checks": {"count": 1, "answer": "1", "positions": "random"}}},
    ],
}


#: The stimulus plan (generation/plans/<name>.yaml) whose clips each preset's sections draw:
#: :func:`create_study_from_preset` adds a ``plan`` filter to every section pool, so clips of another plan in the
#: same catalogue (the demo's, another paper's) never enter a study's pools. A researcher may change the filter in
#: the admin.
PRESET_PLANS = {"gait_ismar2020": "seed000", "gestures_ieeevr2021": "seed003", "rbf_thms2016": "seed004",
                "demo": "demo", "norming": "demo"}


def preset_plan_names() -> list[str]:
    """The plans the presets draw on, sorted, each once (what ``analysis/data/planned_clips.csv`` holds)."""
    return sorted(set(PRESET_PLANS.values()))


#: The quality switch every preset pool carries: a clip flagged only by the advisory realism check stays in (it also
#: flags about 10 % of real captured takes, so it informs rather than excludes); every other failed check keeps a clip
#: out. A researcher may untick it in the admin's pool editor to leave realism-flagged clips out too.
PRESET_POOL_SWITCHES = {"keep_advisory": True}
for _preset in PRESETS.values():
    for _sec in _preset["sections"]:
        if "reuse" not in _sec:
            _sec["pool"] = {**(_sec.get("pool") or {}), **PRESET_POOL_SWITCHES}


if __name__ == "__main__":  # python -m protocol.presets: the presets' plans, for generation.plans.planned
    print(" ".join(preset_plan_names()))
