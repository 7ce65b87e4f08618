"""Procedural (SYNTHETIC) motion and the synthetic training corpus: walks, seated gestures, emotion mappings."""
