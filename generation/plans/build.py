"""Write the built-in paper plans (seed000.yaml, seed003.yaml, seed004.yaml) from their specifications.

    python -m generation.plans.build            # rewrites the three files next to this module

The plans are plain YAML afterwards; researchers copy and edit them. What each reproduces:

- seed000 (ISMAR 2020, section 6): single-emotion gaits (pure and mixed emotion vectors, straight, curved
  and sharp-turn paths), emotion-transition gaits (all 12 ordered pairs of the four emotions, each
  "predominantly" one emotion as in section 6.3.2) and the source motions (the captured DeepMimic walks).
  Ten-second clips, fixed camera (section 6.3.4).
- seed003 (IEEE VR 2021, section 6): generated gestures over the 11 MPI emotion categories for narration and
  conversation sentences, and one "source" gesture per generated one (seed 003's were motion-captured; ours
  are procedural, marked synthetic) paired through ``pair`` so the study never shows both to one person.
  The generated gestures' sentences come from the gesture network's held-out test split (each entry says
  ``sentence_split: test``), so the study shows the network on inputs it was not trained on. Beside them, REAL
  source gestures: the shipped Bandai Namco ``bye`` takes in the five styles that name a gesture emotion
  (``protocol.vocabulary.CAPTURE_GESTURE_EMOTIONS``), seated on the chair (``seated: true``), for the naturalness and
  gesture-emotion sections.
- seed004 (THMS 2016, section V): the neutral input walk, 6 themes x weights (0.4, 0.7, 1.0, 1.3) x feature
  counts (1, 4, 7, 10), and the inversions at w = -0.7 with all ten features; short looping clips. The neutral base
  is averaged from real normal walks (``base: real``, the default).
- seed004_data: each theme at w = 0.7 with the experts' features and with data-driven features (``features:
  data``, fitted to real themed walks) side by side, on the same real neutral base.
"""
from __future__ import annotations

import csv
from pathlib import Path

import yaml

from generation.gesture.config import gesture_seconds
from generation.gesture.data import load_sentences, split_sentences
from generation.gesture.text import count_words
from generation.gesture.train import TrainConfig
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS, GAIT_EMOTIONS, GESTURE_EMOTIONS, GESTURE_TASKS, THEMES

from .generators.captured import CAPTURED_CLIPS

HERE = Path(__file__).resolve().parent
SENTENCES = HERE.parent / "data" / "sentences_synthetic.csv"
WEIGHTS = (0.4, 0.7, 1.0, 1.3)
FEATURE_COUNTS = (1, 4, 7, 10)
INVERSION_WEIGHT = -0.7
RENDER = {"fps": 25, "duration_s": 10}  # 25 fps (no paper states a video rate); 1280x720 mannequin, camera auto


def _predominant(emotion: str, share: float = 0.8) -> list[float]:
    """``share`` of one emotion and the rest neutral (pure neutral for neutral)."""
    vec = [0.0] * len(GAIT_EMOTIONS)
    vec[GAIT_EMOTIONS.index(emotion)] = share
    vec[GAIT_EMOTIONS.index("neutral")] += 1.0 - share
    return [round(v, 3) for v in vec]


def seed000() -> dict:
    clips = []
    # Compact paths (loops and hairpins): a fixed camera has to frame the whole 10 s walk (about 13 m),
    # and on a long straight the body would be a few dozen pixels tall for most of the clip.
    trajectories = [{"kind": "curved", "radius_m": 3.0, "angle_deg": 330, "length_m": 14},
                    {"kind": "sharp_turn", "angle_deg": 150, "length_m": 14}]
    seed = 0
    for emotion in GAIT_EMOTIONS:           # pure emotions on a straight and a curved path
        for k, traj in enumerate(trajectories):
            seed += 1
            clips.append({"id": f"single_{emotion}_{('loop', 'hairpin')[k]}", "generator": "gait_net",
                          "fallback": "procedural_walk", "origin": "generated",
                          "emotion": [1.0 if e == emotion else 0.0 for e in GAIT_EMOTIONS], "trajectory": traj,
                          "seed": seed, "sections": ["emotion_choice", "affect_likert", "naturalness"]})
    mixtures = {
        "happy_neutral": [0.6, 0.0, 0.0, 0.4], "sad_neutral": [0.0, 0.7, 0.0, 0.3],
        "angry_neutral": [0.0, 0.0, 0.6, 0.4], "happy_angry": [0.5, 0.0, 0.5, 0.0],
        "sad_angry": [0.0, 0.5, 0.5, 0.0], "happy_sad_neutral": [0.3, 0.3, 0.0, 0.4],
        "mostly_happy": [0.8, 0.0, 0.1, 0.1], "mostly_sad": [0.0, 0.8, 0.0, 0.2],
    }
    turns = [{"kind": "curved", "radius_m": 3.0, "angle_deg": -330, "length_m": 14},
             {"kind": "sharp_turn", "angle_deg": -150, "length_m": 14},
             {"kind": "curved", "radius_m": 3.5, "angle_deg": 300, "length_m": 14}]
    for k, (name, vec) in enumerate(mixtures.items()):
        seed += 1
        clips.append({"id": f"single_{name}", "generator": "gait_net", "fallback": "procedural_walk",
                      "origin": "generated", "emotion": vec, "trajectory": turns[k % len(turns)], "seed": seed,
                      "sections": ["emotion_choice", "affect_likert", "naturalness"]})
    for a in GAIT_EMOTIONS:                 # all 12 ordered transitions
        for b in GAIT_EMOTIONS:
            if a == b:
                continue
            seed += 1
            clips.append({"id": f"transition_{a}_to_{b}", "generator": "gait_net", "fallback": "procedural_walk",
                          "origin": "generated",
                          "transition": {"initial": _predominant(a), "final": _predominant(b)},
                          "trajectory": turns[seed % len(turns)], "seed": seed, "sections": ["emotion_transition"]})
    for name in CAPTURED_CLIPS:
        clips.append({"id": f"source_{name.removesuffix('.txt')}", "generator": "captured", "origin": "source",
                      "clip": name, "cycles": 8, "sections": ["naturalness"],
                      "note": "captured walk (DeepMimic, CMU/SFU mocap), no emotion label"})
    return {"name": "seed000", "description": "Seed 000 (Bhattacharya et al., ISMAR 2020) web study stimuli: "
            "single-emotion gaits, transition gaits, source motions; 10 s clips at 25 fps (the paper gives no video "
            "rate), camera auto (fitted, or following the walker on long paths).",
            "render": dict(RENDER), "clips": clips}


def _sentence_splits() -> dict[str, str]:
    """sentence_id -> "train" | "val" | "test" as the gesture network's training split them
    (``generation.gesture.data.split_sentences`` with the training seed)."""

    return split_sentences(load_sentences(SENTENCES), TrainConfig().seed)


def _sentences(per_emotion_narration: int, per_emotion_conversation: int,
               splits: tuple[str, ...] = ("test",)) -> list[dict]:
    """Per gesture emotion, up to ``per_emotion_narration`` narration and ``per_emotion_conversation`` conversation
    sentences from the given splits of the gesture network's sentence split (default the held-out test split,
    so generated gestures are never made from sentences the network was trained on). A task with too few
    sentences in those splits is topped up from the other task. Each row gets its ``split``."""
    rows = list(csv.DictReader(SENTENCES.open(encoding="utf-8")))
    split = _sentence_splits()
    out = []
    for emotion in GESTURE_EMOTIONS:
        wanted = dict(zip(GESTURE_TASKS, (per_emotion_narration, per_emotion_conversation)))
        pools = {task: [dict(r, split=split[r["sentence_id"]]) for r in rows if r["emotion"] == emotion
                        and r["task"] == task and split[r["sentence_id"]] in splits] for task in GESTURE_TASKS}
        picked = {task: pools[task][len(pools[task]) - min(n, len(pools[task])):] for task, n in wanted.items()}
        missing = sum(wanted.values()) - sum(len(p) for p in picked.values())
        for task in GESTURE_TASKS:                 # top up from the other task's remaining sentences
            spare = pools[task][:len(pools[task]) - len(picked[task])]
            take = spare[len(spare) - min(missing, len(spare)):] if missing > 0 else []
            picked[task] = take + picked[task]
            missing -= len(take)
        for task in GESTURE_TASKS:
            out.extend(picked[task])
    return out


def _gesture_seconds(sentence: str) -> float:
    return round(float(gesture_seconds(count_words(sentence))), 2)


SHIPPED_GESTURES = "generation/data/mocap/bandai-namco/Bandai-Namco-Research-Motiondataset-1/data"
REAL_SOURCE_CONTENT = "bye"


def real_source_gestures(content: str = REAL_SOURCE_CONTENT, styles=None) -> list[dict]:
    """``captured_file`` entries of the shipped real ``content`` takes (take 001) in each captured style that names a
    gesture emotion (``protocol.vocabulary.CAPTURE_GESTURE_EMOTIONS``; default all five), seated on the chair, labelled
    with that emotion, for the naturalness and gesture-emotion sections."""

    styles = tuple(CAPTURE_GESTURE_EMOTIONS) if styles is None else tuple(styles)
    return [{"id": f"real_{content}_{style}", "generator": "captured_file", "modality": "gesture", "origin": "source",
             "file": f"{SHIPPED_GESTURES}/dataset-1_{content}_{style}_001.bvh", "seated": True,
             "emotion_label": CAPTURE_GESTURE_EMOTIONS[style], "sections": ["naturalness", "gesture_emotion"],
             "note": f"REAL captured gesture (Bandai Namco Research Motion Dataset 1, {content} {style}, take 1; "
                     f"CC BY-NC 4.0), seated"} for style in styles]


def seed003(narration: int = 3, conversation: int = 2, splits: tuple[str, ...] = ("test",)) -> dict:
    """Generated gestures for sentences of the network's held-out test split (``splits``), each entry recording
    its ``sentence_split``, and one paired source gesture each."""
    clips = []
    for k, row in enumerate(_sentences(narration, conversation, splits)):
        gender = "female" if k % 2 == 0 else "male"
        handedness = "left" if k % 7 == 3 else "right"
        sid = row["sentence_id"]
        clips.append({"id": f"source_{sid}", "generator": "procedural_gesture", "origin": "source",
                      "emotion_label": row["emotion"], "gender": gender, "handedness": handedness,
                      "duration_s": _gesture_seconds(row["sentence"]), "seed": k + 1, "sections": ["naturalness"],
                      "note": "synthetic stand-in for the motion-captured MPI sequence of this sentence"})
        clips.append({"id": f"generated_{sid}", "generator": "gesture_net", "fallback": "procedural_gesture",
                      "origin": "generated", "sentence": row["sentence"], "sentence_split": row["split"],
                      "task": row["task"],
                      "emotion_label": row["emotion"], "gender": gender, "handedness": handedness, "seed": k + 1,
                      "pair": f"source_{sid}", "sections": ["gesture_emotion", "naturalness"]})
    clips.extend(real_source_gestures())
    return {"name": "seed003", "description": "Seed 003 (Bhattacharya et al., IEEE VR 2021) web study stimuli: "
            "generated gestures over the 11 MPI emotions for sentences held out from the network's training "
            "(test split), each paired with a source gesture (procedural, synthetic), and real captured source "
            "gestures (Bandai Namco 'bye' in the styles happy, sad, angry, proud, normal = joyous, sad, angry, proud, "
            "neutral; CC BY-NC 4.0, Kobayashi et al. 2023, arXiv:2306.08861) seated on the chair; seated agent on a "
            "chair, fixed camera; 25 fps video (the paper gives no video rate).",
            "render": dict(RENDER, duration_s=12), "clips": clips}


def seed004(n_cycles: int = 3) -> dict:
    clips = [{"id": "neutral_walk", "generator": "neutral_walk", "origin": "source", "n_cycles": n_cycles,
              "sections": ["neutral_validation"], "loop": True}]
    for theme in THEMES:
        for w in WEIGHTS:
            for n in FEATURE_COUNTS:
                clips.append({"id": f"{theme}_w{w}_n{n}", "generator": "rbf", "origin": "generated", "theme": theme,
                              "weight": w, "n_features": n, "n_cycles": n_cycles, "sections": ["theme_rating"],
                              "loop": True})
    for theme in THEMES:
        clips.append({"id": f"{theme}_inverted", "generator": "rbf", "origin": "generated", "theme": theme,
                      "weight": INVERSION_WEIGHT, "n_features": 10, "n_cycles": n_cycles,
                      "sections": ["theme_inversion"], "loop": True})
    return {"name": "seed004", "description": "Seed 004 (Etemad & Arya, THMS 2016) perception study stimuli: "
            "neutral input walk averaged from real normal walks (Bandai Namco, CC BY-NC 4.0, Kobayashi et al. 2023), "
            "6 themes x 4 weights x 4 feature counts, inversions at w = -0.7; short walk cycles the player loops; "
            "25 fps video (the paper gives no video rate).", "render": dict(RENDER), "qa": dict(LOOPED_CYCLE_QA),
            "clips": clips}


#: One averaged cycle looped (the paper's stimulus) has no cycle-to-cycle change of walking speed, so the real
#: corpus's lower bound on speed variability (generation/quality/realism_ranges.json) does not apply to it.
LOOPED_CYCLE_QA = {"speed_cv_min": None}


def seed004_data(n_cycles: int = 3, weight: float = 0.7) -> dict:
    """Expert-styled and data-styled walks of each theme side by side, on the real neutral base."""
    clips = [{"id": "neutral_walk", "generator": "neutral_walk", "origin": "source", "n_cycles": n_cycles,
              "sections": ["neutral_validation"], "loop": True}]
    for theme in THEMES:
        for features in ("expert", "data"):
            clips.append({"id": f"{theme}_{features}_w{weight}", "generator": "rbf", "origin": "generated",
                          "theme": theme, "weight": weight, "n_features": 10, "features": features,
                          "n_cycles": n_cycles, "sections": ["theme_rating"], "loop": True})
    return {"name": "seed004_data", "description": "Seed 004's themes with the experts' features (Table III) beside "
            "data-driven features fitted to real themed walks (Bandai Namco, CC BY-NC 4.0, Kobayashi et al. 2023), "
            f"all ten features at w = {weight}, on the neutral walk averaged from real normal walks; 25 fps video.",
            "render": dict(RENDER), "qa": dict(LOOPED_CYCLE_QA), "clips": clips}


def write_all(out_dir: Path = HERE) -> list[Path]:
    written = []
    for name, data in (("seed000", seed000()), ("seed003", seed003()), ("seed004", seed004()),
                       ("seed004_data", seed004_data())):
        path = out_dir / f"{name}.yaml"
        header = (f"# Built-in plan {name}; written by `python -m generation.plans.build` (edit a copy, or change\n"
                  f"# build.py and rerun). {len(data['clips'])} clips.\n")
        path.write_text(header + yaml.safe_dump(data, sort_keys=False, width=118, allow_unicode=True),
                        encoding="utf-8")
        written.append(path)
    return written


if __name__ == "__main__":
    for p in write_all():
        print(p)
