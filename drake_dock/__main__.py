"""``python -m drake_dock``: the same command line as ``drake-dock``."""
import sys

from drake_dock.cli import main

sys.exit(main())
