"""Seed 004 RBF styles: Gaussian RBF features, themes, the neutral base walk, stylisation."""
