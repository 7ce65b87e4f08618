"""Django project and app for perceptual studies of emotive virtual-agent motion.

`generation/` and `analysis/` are plain libraries; this package glues them to the web.
"""
