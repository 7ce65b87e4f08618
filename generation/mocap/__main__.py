"""``python -m generation.mocap import ...`` (see :mod:`generation.mocap.cli`)."""
import sys

from .cli import main

sys.exit(main())
