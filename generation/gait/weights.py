"""Named weights of the gait network: ``real`` (trained on real capture, the default) and ``procedural``.

- ``real``: ``gait_net_real.pt``, pretrained on the forward locomotion of the Bandai Namco Research Motion Dataset
  (datasets 1 and 2) and fine-tuned on dataset 1's happy, sad, angry and normal walks (Kobayashi et al. 2023,
  arXiv:2306.08861; licence CC BY-NC 4.0, which the weights, derived from the data, keep). Model card:
  docs/gait_real_model_card.md.
- ``procedural``: ``gait_net_default.pt``, trained on the SYNTHETIC procedural gait corpus
  (docs/benchmarks/gait.md).

Plans choose with the gait_net entry field ``weights: real | procedural``; clip metadata records the name.

A weights file says what it was trained on in a typed record, :class:`TrainingData` (``training_data``: its kind,
procedural or real, the dataset ids, a description and the corpus file), which picks the seed walks and the foot
clean-up of the walks it makes (:func:`is_real`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

WEIGHTS_DIR = Path(__file__).resolve().parent.parent / "data" / "weights"
NAMED_WEIGHTS = {"real": "gait_net_real.pt", "procedural": "gait_net_default.pt"}
"""Weights name -> file in :data:`WEIGHTS_DIR`."""
DEFAULT_WEIGHTS_NAME = "real"


def weights_path(name: str | None = None) -> Path:
    """The file of the named weights (None: :data:`DEFAULT_WEIGHTS_NAME`); ValueError for an unknown name."""
    name = DEFAULT_WEIGHTS_NAME if name is None else name
    if name not in NAMED_WEIGHTS:
        raise ValueError(f"unknown gait weights {name!r}: use one of {', '.join(NAMED_WEIGHTS)}")
    return WEIGHTS_DIR / NAMED_WEIGHTS[name]


#: What a gait network can be trained on: the synthetic procedural corpus, real capture, or rated clips (the stored
#: motions of a study's clips, generated or captured, with their perceived-emotion shares as labels).
TRAINING_KINDS = ("procedural", "real", "rated")
RATED_DATASETS = ("clip-norms",)
PROCEDURAL_DESCRIPTION = "synthetic procedural corpus"
PROCEDURAL_DATASETS = ("procedural-gait-corpus",)
#: Real-capture training by stage: (description, dataset ids of the real-capture corpus).
REAL_STAGES = {
    "pretrain": ("real capture: Bandai Namco datasets 1 and 2 forward locomotion (CC BY-NC 4.0)",
                 ("bandai-namco-1", "bandai-namco-2")),
    "finetune": ("real capture: Bandai Namco dataset 1 happy/sad/angry/normal walks (CC BY-NC 4.0)",
                 ("bandai-namco-1",)),
    "finetune-both": ("real capture: Bandai Namco dataset 1 happy/sad/angry/normal walks (CC BY-NC 4.0) + BML walks "
                      "of the training actors (research use, citation)", ("bandai-namco-1", "emotion-gait-bml")),
}


@dataclass(frozen=True)
class TrainingData:
    """What a gait network is (or was) trained on.

    Attributes:
        kind: ``procedural`` (the synthetic procedural corpus) or ``real`` (real capture).
        description: one line for people (clip metadata ``trained_on``).
        datasets: ids of the datasets (``procedural-gait-corpus``; ``bandai-namco-1``, ``bandai-namco-2``,
            ``emotion-gait-bml``; ``clip-norms``).
        corpus: the corpus file read: ``path``, ``sha256`` and, for real capture, ``stage`` and ``augment``; for
            the two corpora of ``finetune-both``, ``stage``, ``labels``, ``augment`` and one entry per corpus file
            under ``datasets`` (its path, SHA-256, licence, citation and split).
    """

    kind: str
    description: str
    datasets: tuple[str, ...] = ()
    corpus: dict | None = field(default=None, compare=False)

    def __post_init__(self):
        if self.kind not in TRAINING_KINDS:
            raise ValueError(f"training data kind must be one of {TRAINING_KINDS}, got {self.kind!r}")

    @classmethod
    def procedural(cls, corpus: dict | None = None) -> TrainingData:
        return cls("procedural", PROCEDURAL_DESCRIPTION, PROCEDURAL_DATASETS, corpus)

    @classmethod
    def rated(cls, description: str, norms: dict) -> TrainingData:
        """Rated clips; ``norms`` is the record of the clip_norms.csv they were labelled from."""
        return cls("rated", description, RATED_DATASETS, {"soft_labels": norms})

    def with_soft_labels(self, other: TrainingData) -> TrainingData:
        """This training data plus the rated clips of ``other`` (a real-capture stage beside soft labels)."""
        return TrainingData(self.kind, f"{self.description}; {other.description}", (*self.datasets, *other.datasets),
                            {**(self.corpus or {}), **(other.corpus or {})})

    @classmethod
    def real(cls, stage: str, corpus: dict | None = None, labels: str | None = None) -> TrainingData:
        """Real capture of a training stage (:data:`REAL_STAGES`); ``labels`` names the emotion labels where the
        stage offers a choice (``acted`` or ``soft`` for ``finetune-both``) and ends the description."""
        description, datasets = REAL_STAGES[stage]
        if labels is not None:
            description = f"{description}, {labels} emotion labels"
        return cls("real", description, datasets, corpus)

    def record(self) -> dict:
        """The ``training_data`` field of a weights file."""
        return {"kind": self.kind, "description": self.description, "datasets": list(self.datasets),
                "corpus": self.corpus}

    @classmethod
    def from_record(cls, record: dict) -> TrainingData:
        return cls(record["kind"], record["description"], tuple(record["datasets"]), record.get("corpus"))


def training_data_of(payload: dict) -> TrainingData:
    """The training data of a weights file's payload: its ``training_data`` record (format gait_net/3). A file of
    format gait_net/2 has only the prose ``trained_on`` and the ``corpus`` record; it is read here and nowhere else: a
    ``trained_on`` that begins "real capture" is real capture of the corpus's ``stage``, anything else the
    procedural corpus. ``python -m generation.gait.upgrade_weights FILE`` writes such a file again with its record
    (the shipped weights were, keeping their weights bit for bit)."""
    if payload.get("format") != "gait_net/2":
        return TrainingData.from_record(payload["training_data"])
    corpus = payload.get("corpus")
    if str(payload.get("trained_on", "")).startswith("real capture"):
        return TrainingData.real((corpus or {}).get("stage", "finetune"), corpus)
    return TrainingData.procedural(corpus)


def is_real(training: TrainingData) -> bool:
    """Whether a network (its ``LoadedGaitNet.training_data``) was trained on real capture: that picks its seed
    walks and its foot clean-up."""
    return training.kind == "real"
