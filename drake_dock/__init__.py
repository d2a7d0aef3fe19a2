"""drake_dock: capture-phase docking contact between two APDS-equipped spacecraft, after Zhao,
Liu and Chen (2016), on Drake.

Generic mathematics lives in `drake_dock.core` (no Drake) and `drake_dock.impact` (LZB, plain
numpy); the docking scene in `drake_dock.docking`; the Drake boundary in `drake_dock.run`.
"""
__version__ = "0.1.0"
