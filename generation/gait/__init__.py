"""Seed 000 affect-based autoregression network for emotive gaits: config, model, data, losses, training
and generation. ``from generation.gait import generate_gaits, load_default_model``."""
from .config import GaitDataConfig, GaitLossWeights, GaitModelConfig, GaitNetConfig, GaitTrainConfig
from .generate import emotion_transition, generate_gaits, load_default_model, load_model
from .model import GaitNet

__all__ = ["GaitDataConfig", "GaitLossWeights", "GaitModelConfig", "GaitNet", "GaitNetConfig", "GaitTrainConfig",
           "emotion_transition", "generate_gaits", "load_default_model", "load_model"]
