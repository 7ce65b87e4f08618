"""Stimulus plans and the clip catalogue: the plan schema (schema), plan entry -> Motion (clipgen), clips.csv
(catalogue), and the paper plans (build.py writes seed000/seed003/seed004.yaml)."""
