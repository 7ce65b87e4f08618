"""Renderers of the benchmarks' JSON results as Markdown tables, one module per area (``TABLES``: table name ->
(the JSON key it needs, renderer)) and ``common`` for the formatting they share. ``doc_tables`` combines the areas'
``TABLES`` and writes the tables into the docs; import both from ``benchmarks``."""
