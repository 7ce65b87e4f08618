"""Motion file formats: BVH, DeepMimic JSON, and the shipped captured walks."""
